// Faults injected into the workcell (sim only): a weakened grip, a locked joint, a
// frozen sensor and a moved object, each applied at its time and undone by a reset; bad faults
// are refused naming what is wrong.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <limits>
#include <string>

#include "lfd_sim_bridge/fault_schedule.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"
#include "workcell_test_config.hpp"

namespace {

// The stick between the open fingers, closed on with 20 N for 1 s: the left pad's force.
double holdStick(lfd_sim::WorkcellSim* sim) {
  lfd_sim::Pose stick = sim->readState().ee_pose;
  stick.position[2] += 0.85;  // base_link -> world
  sim->setObjectPose("stick", stick);
  sim->setGripper(0.0, 20.0);
  sim->step(1000);
  return reading(sim->readState(), "/touch", 0).at(0);
}

lfd_sim::WorkcellConfig drawerConfig() {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.objects = {"stick", "drawer", "drawer_handle"};
  return c;
}

// How far the drawer slides under a 30 N pull for 0.5 s.
double pullDrawer(lfd_sim::WorkcellSim* sim) {
  const int joint = mj_name2id(sim->model(), mjOBJ_JOINT, "drawer_slide");
  const int dof = sim->model()->jnt_dofadr[joint];
  const double before = sim->jointPosition("drawer_slide");
  sim->data()->qfrc_applied[dof] = 30.0;
  sim->step(500);
  sim->data()->qfrc_applied[dof] = 0.0;
  return std::abs(sim->jointPosition("drawer_slide") - before);
}

TEST(WorkcellFaults, AWeakenedGripLetsGoOfTheStickUntilAReset) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  const double held = holdStick(&sim);
  ASSERT_GT(held, 1.0) << "the closed fingers never squeeze the stick";
  sim.weakenGrip(0.0);
  sim.step(500);
  EXPECT_LT(reading(sim.readState(), "/touch", 0).at(0), 0.1 * held);
  EXPECT_NEAR(sim.readState().gripper_effort, 0.0, 1e-9);
  sim.reset({}, true);
  EXPECT_NEAR(holdStick(&sim), held, 0.1 * held);  // the reset gave the grip back
}

TEST(WorkcellFaults, ALockedDrawerHoldsAgainstAPullUntilAReset) {
  lfd_sim::WorkcellSim sim(kModel, drawerConfig());
  const double free_travel = pullDrawer(&sim);
  ASSERT_GT(free_travel, 0.005) << "a 30 N pull does not open the drawer";
  sim.reset();
  sim.lockJoint("drawer_slide", 1e4);
  EXPECT_LT(pullDrawer(&sim), 0.0005);
  sim.reset();
  EXPECT_NEAR(pullDrawer(&sim), free_travel, 0.2 * free_travel);
  EXPECT_THROW(sim.lockJoint("no_such_joint", 1e4), std::invalid_argument);
  EXPECT_THROW(sim.lockJoint("drawer_slide", -1.0), std::invalid_argument);
}

TEST(WorkcellFaults, AFrozenSensorRepeatsItsReadingWhileTheOthersMove) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.freezeSensor("/touch");
  const double before_gripper = sim.readState().gripper_opening;
  EXPECT_LT(holdStick(&sim), 1e-6);  // the pads still say what they said when frozen
  EXPECT_LT(sim.readState().gripper_opening, before_gripper - 0.005);  // the rest moved on
  sim.reset({}, true);
  EXPECT_GT(holdStick(&sim), 1.0);
  EXPECT_THROW(sim.freezeSensor("/elbow_ft"), std::invalid_argument);
}

TEST(FaultSchedule, AppliesEachFaultAtItsTimeInTimeOrder) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  lfd_sim::FaultSchedule schedule;
  const double t0 = sim.time();
  lfd_sim::Fault away;
  away.kind = lfd_sim::faultKind("move_object");
  away.target = "stick";
  away.pose.position = {0.5, 0.5, 0.9};
  away.at = t0 + 0.05;
  lfd_sim::Fault weak;
  weak.kind = lfd_sim::faultKind("weaken_grip");
  weak.value = 0.5;
  weak.at = t0 + 0.02;
  schedule.add(away, sim);
  schedule.add(weak, sim);
  EXPECT_TRUE(schedule.takeDue(t0 + 0.01).empty());
  const auto first = schedule.takeDue(t0 + 0.03);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].kind, lfd_sim::Fault::Kind::kWeakenGrip);
  const auto second = schedule.takeDue(t0 + 0.06);
  ASSERT_EQ(second.size(), 1u);
  lfd_sim::applyFault(second[0], &sim);
  sim.step();
  EXPECT_NEAR(sim.readState().object_poses[0].position[0], 0.5, 1e-3);
  EXPECT_EQ(schedule.size(), 0u);
  EXPECT_NE(lfd_sim::describeFault(second[0]).find("move_object stick"), std::string::npos);
}

TEST(FaultSchedule, RefusesWhatItCannotApplyNamingIt) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  lfd_sim::FaultSchedule schedule;
  const auto refused = [&](lfd_sim::Fault f, const std::string& named) {
    try {
      schedule.add(f, sim);
      ADD_FAILURE() << "accepted a fault that should name " << named;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  try {
    lfd_sim::faultKind("explode");
    ADD_FAILURE() << "an unknown kind was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lock_joint"), std::string::npos) << e.what();
  }
  lfd_sim::Fault f;
  f.kind = lfd_sim::Fault::Kind::kMoveObject;
  f.target = "anvil";
  refused(f, "anvil");
  f.kind = lfd_sim::Fault::Kind::kFreezeSensor;
  f.target = "/elbow_ft";
  refused(f, "/elbow_ft");
  f.kind = lfd_sim::Fault::Kind::kLockJoint;
  f.target = "hinge_x";
  refused(f, "hinge_x");
  f.kind = lfd_sim::Fault::Kind::kWeakenGrip;
  f.value = 1.5;
  refused(f, "[0, 1]");
  f.value = 0.5;
  f.at = std::numeric_limits<double>::quiet_NaN();
  refused(f, "finite");
  EXPECT_EQ(schedule.size(), 0u);
}

}  // namespace
