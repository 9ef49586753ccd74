// Master-free tests of the MuJoCo workcell (lfd_sim): position-controlled hardware emulation,
// limits, trajectories, readings, reset, object placement and divergence recovery.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/sensor_table.hpp"
#include "lfd_sim_bridge/trajectory_interpolator.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"
#include "workcell_test_config.hpp"

namespace {

struct LogCounter {
  int warnings = 0, errors = 0;
  std::string last;
  lfd_sim::LogSink sink() {
    return [this](lfd_sim::LogLevel level, const std::string& text) {
      if (level == lfd_sim::LogLevel::kWarn) ++warnings;
      if (level == lfd_sim::LogLevel::kError) ++errors;
      last = text;
    };
  }
};

TEST(WorkcellSim, LoadsTheContractScene) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  EXPECT_DOUBLE_EQ(sim.timestep(), 0.001);
  EXPECT_TRUE(sim.hasJoint("R_ELBOW_P"));
  EXPECT_TRUE(sim.hasJoint("R_GRIPPER"));
  EXPECT_GE(sim.actuatedJoints().size(), 30u);
  const lfd_sim::WorkcellState s = sim.readState();
  ASSERT_EQ(s.object_names.size(), 2u);
  EXPECT_EQ(s.object_names[0], "stick");
  ASSERT_NE(s.sensor("/touch"), nullptr);
  EXPECT_EQ(s.sensor("/touch")->sensors,
            (std::vector<std::string>{"r_touch_left", "r_touch_right"}));
  EXPECT_NEAR(reading(s, "/imu", 0).at(0), 1.0, 1e-9);  // orientation w: pelvis fixed upright
  EXPECT_EQ(reading(s, "/wrist_ft", 0).size(), 3u);     // a force
}

// Readings are keyed by table row, in the rows' order, each sensor as the model defines it.
TEST(WorkcellSim, ReadsTheSensorsTheTableNames) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.sensors = {{"/pads", {"r_touch_right"}}, {"/spin", {"imu_gyro", "imu_quat"}}};
  lfd_sim::WorkcellSim sim(kModel, c);
  const lfd_sim::WorkcellState s = sim.readState();
  ASSERT_EQ(s.sensors.size(), 2u);
  EXPECT_EQ(s.sensors[0].name, "/pads");
  EXPECT_EQ(s.sensors[0].values.at(0).size(), 1u);
  EXPECT_EQ(s.sensors[1].values.at(0).size(), 3u);
  EXPECT_EQ(s.sensors[1].values.at(1).size(), 4u);
  EXPECT_EQ(s.sensor("/wrist_ft"), nullptr);  // not in this table: not read
}

// A row naming a sensor the model lacks is refused at start-up, naming the row and the sensor.
TEST(WorkcellSim, ATableSensorTheModelLacksIsAClearError) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.sensors.push_back({"/elbow_ft", {"r_elbow_force"}});
  try {
    lfd_sim::WorkcellSim sim(kModel, c);
    FAIL() << "a missing sensor was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/elbow_ft"), std::string::npos) << what;
    EXPECT_NE(what.find("'r_elbow_force'"), std::string::npos) << what;
    EXPECT_NE(what.find("r_wrist_force"), std::string::npos) << what;  // lists what there is
  }
}

// A robot file for another robot (or with a typo) is refused before anything runs: a gripper
// joint, tip frame or posture joint the model lacks would record demos with an idle gripper.
TEST(WorkcellSim, RobotFileNamesTheModelLacksAreClearErrors) {
  const auto expect_refused = [](const lfd_sim::WorkcellConfig& c, const std::string& needle) {
    try {
      lfd_sim::WorkcellSim sim(kModel, c);
      ADD_FAILURE() << "accepted a robot file naming " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  lfd_sim::WorkcellConfig c = readyConfig();
  c.gripper_joint = "finger_joint";
  expect_refused(c, "gripper joint 'finger_joint'");
  c = readyConfig();
  c.ee_site = "tcp";
  expect_refused(c, "'tcp'");
  c = readyConfig();
  c.initial_posture["arm_joint_1"] = 0.1;
  expect_refused(c, "'arm_joint_1'");
}

// The table bound to the message types: fields in the message's order, dimensions checked.
TEST(SensorTable, BindsRowsAndRefusesWrongOnes) {
  const lfd::RobotSetup robot = lfd::loadRobotSetup(kRobotFile);
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  const auto dim = [&](const std::string& n) { return sim.sensorDimension(n); };
  const auto bindings = lfd_sim::bindSensorTable(robot.sensors);
  EXPECT_NO_THROW(lfd_sim::checkSensorDimensions(bindings, dim));
  const auto expect_error = [&](const lfd::SensorEntry& row, const std::string& needle) {
    try {
      lfd_sim::checkSensorDimensions(lfd_sim::bindSensorTable({row}), dim);
      ADD_FAILURE() << "accepted a row with " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("/x"), std::string::npos) << e.what();
    }
  };
  expect_error({"/x", "geometry_msgs/Wrench", "f", {{"force", {"r_wrist_force"}}}},
               "unknown message type");
  expect_error({"/x", "geometry_msgs/WrenchStamped", "f", {{"forces", {"r_wrist_force"}}}},
               "no field 'forces'");
  expect_error({"/x", "geometry_msgs/WrenchStamped", "f", {{"force", {"r_touch_left"}}}},
               "dimension 3; 'r_touch_left' has 1");
  expect_error({"/x", "sensor_msgs/Imu", "f", {{"angular_velocity", {"imu_gyro", "imu_accel"}}}},
               "takes one sensor, not 2");
  // Fields are read in the message's order, whatever the file's.
  const auto imu = lfd_sim::bindSensorTable(
      {{"/x",
        "sensor_msgs/Imu",
        "f",
        {{"linear_acceleration", {"imu_accel"}}, {"orientation", {"imu_quat"}}}}});
  EXPECT_EQ(imu[0].group.sensors, (std::vector<std::string>{"imu_quat", "imu_accel"}));
}

// A gain the robot file sets to zero is refused after the model is loaded: the constructor
// frees the model it already holds (the sanitized run of this test fails on a leak).
TEST(WorkcellSim, ANonPositiveGainIsAClearErrorThatFreesTheModel) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.kp["R_ELBOW_P"] = 0.0;
  try {
    lfd_sim::WorkcellSim sim(kModel, c);
    FAIL() << "a zero gain was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("R_ELBOW_P has a non-positive kp"), std::string::npos)
        << e.what();
  }
}

TEST(WorkcellSim, BadModelPathGivesMuJoCoMessage) {
  try {
    lfd_sim::WorkcellSim sim("/nonexistent/workcell.xml");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/workcell.xml"), std::string::npos);
  }
}

TEST(WorkcellSim, TracksAJointStep) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.step(300);  // settle from the initial posture
  const double start = sim.jointPosition("R_SHOULDER_Y");
  const double goal = start + 0.4;
  sim.setJointTargets({"R_SHOULDER_Y"}, {goal});
  // Rate limit 2 rad/s: the target arrives after 0.2 s; the joint must settle within 1 mrad
  // by 0.6 s and stay there (no drift, no oscillation).
  sim.step(600);
  for (int k = 0; k < 400; ++k) {
    sim.step();
    ASSERT_NEAR(sim.jointPosition("R_SHOULDER_Y"), goal, 1e-3) << "at step " << k;
  }
  // Other arm joints hold their posture under gravity (compensated) within 5 mrad.
  EXPECT_NEAR(sim.jointPosition("R_ELBOW_P"), -1.3, 5e-3);
  EXPECT_NEAR(sim.jointPosition("R_SHOULDER_P"), -0.3, 5e-3);
}

TEST(WorkcellSim, ClampsOutOfRangeTargetsAndWarnsOncePerJoint) {
  LogCounter logs;
  lfd_sim::WorkcellSim sim(kModel, readyConfig(), logs.sink());
  const lfd_sim::JointLimit lim = sim.jointLimit("R_ELBOW_P");
  ASSERT_TRUE(lim.position_limited);
  const int before = logs.warnings;
  sim.setJointTargets({"R_ELBOW_P"}, {lim.upper + 1.0});
  sim.setJointTargets({"R_ELBOW_P"}, {lim.upper + 2.0});
  EXPECT_EQ(logs.warnings, before + 1);
  EXPECT_NE(logs.last.find("R_ELBOW_P"), std::string::npos);
  sim.step(2000);
  EXPECT_DOUBLE_EQ(sim.jointTarget("R_ELBOW_P"), lim.upper);
  EXPECT_LE(sim.jointPosition("R_ELBOW_P"), lim.upper + 0.02);
  sim.setJointTargets({"R_SHOULDER_Y"}, {-100.0});  // another joint warns once too
  EXPECT_EQ(logs.warnings, before + 2);
  EXPECT_DOUBLE_EQ(sim.jointLimit("R_SHOULDER_Y").lower, -1.6);
}

TEST(WorkcellSim, VelocityLimitRateLimitsTheTarget) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.velocity_limits["R_SHOULDER_Y"] = 0.5;
  lfd_sim::WorkcellSim sim(kModel, c);
  const double start = sim.jointTarget("R_SHOULDER_Y");
  sim.setJointTargets({"R_SHOULDER_Y"}, {start + 0.5});
  double max_speed = 0.0;
  for (int k = 0; k < 500; ++k) {
    sim.step();
    const lfd_sim::WorkcellState s = sim.readState();
    for (size_t j = 0; j < s.joint_names.size(); ++j) {
      if (s.joint_names[j] == "R_SHOULDER_Y")
        max_speed = std::max(max_speed, std::abs(s.joint_velocities[j]));
    }
  }
  EXPECT_NEAR(sim.jointTarget("R_SHOULDER_Y"), start + 0.25, 1e-9);  // 0.5 rad/s x 0.5 s
  EXPECT_LT(max_speed, 0.5 * 1.1);
  EXPECT_GT(max_speed, 0.5 * 0.8);  // and it really moves at about the limit
  sim.step(1000);
  EXPECT_NEAR(sim.jointPosition("R_SHOULDER_Y"), start + 0.5, 2e-3);
}

TEST(WorkcellSim, EffortLimitClampsTheTorque) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.effort_limits["R_SHOULDER_Y"] = 5.0;
  lfd_sim::WorkcellSim sim(kModel, c);
  EXPECT_DOUBLE_EQ(sim.jointLimit("R_SHOULDER_Y").effort, 5.0);
  sim.setJointTargets({"R_SHOULDER_Y"}, {sim.jointTarget("R_SHOULDER_Y") + 1.0});
  double max_force = 0.0;
  for (int k = 0; k < 300; ++k) {
    sim.step();
    max_force = std::max(max_force, std::abs(sim.actuatorForce("R_SHOULDER_Y")));
  }
  EXPECT_LE(max_force, 5.0 + 1e-9);
  EXPECT_GT(max_force, 4.99);  // saturated: kp x error is far above 5 N m
}

TEST(WorkcellSim, TrajectoryPassesWaypointsThenHolds) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.step(200);
  const double q0 = sim.jointTarget("R_SHOULDER_Y");
  lfd_sim::JointTrajectory traj;
  traj.joint_names = {"R_SHOULDER_Y"};
  traj.points = {{0.5, {q0 + 0.2}, {}}, {1.0, {q0 + 0.3}, {}}, {1.5, {q0 - 0.1}, {}}};
  const double t0 = sim.time();
  sim.setTrajectory(traj);
  EXPECT_TRUE(sim.trajectoryActive());
  EXPECT_NEAR(sim.trajectoryEndTime(), t0 + 1.5, 1e-12);
  double previous_target = q0;
  double max_jump = 0.0;
  for (int k = 1; k <= 1500; ++k) {
    sim.step();
    const double target = sim.jointTarget("R_SHOULDER_Y");
    max_jump = std::max(max_jump, std::abs(target - previous_target));
    previous_target = target;
    if (k == 500) {
      EXPECT_NEAR(target, q0 + 0.2, 1e-9);
    }
    if (k == 1000) {
      EXPECT_NEAR(target, q0 + 0.3, 1e-9);
    }
    // Shape preserving: never beyond the waypoints' range.
    ASSERT_LE(target, q0 + 0.3 + 1e-12);
    ASSERT_GE(target, q0 - 0.1 - 1e-12);
  }
  EXPECT_LT(max_jump, 2.0 * 0.001 + 1e-12);  // smooth: within the velocity limit every step
  EXPECT_FALSE(sim.trajectoryActive());
  sim.step(500);
  EXPECT_NEAR(sim.jointTarget("R_SHOULDER_Y"), q0 - 0.1, 1e-12);  // held at the last point
  EXPECT_NEAR(sim.jointPosition("R_SHOULDER_Y"), q0 - 0.1, 2e-3);
}

TEST(WorkcellSim, ResentStampedTrajectoryIsIgnoredButANewOneReplaces) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  const double q0 = sim.jointTarget("R_SHOULDER_Y");
  lfd_sim::JointTrajectory traj{{"R_SHOULDER_Y"}, {{1.0, {q0 + 0.4}, {}}}};
  const double stamp = sim.time() + 0.1;
  sim.setTrajectory(traj, stamp);
  sim.step(600);
  sim.setTrajectory(traj, stamp);  // duplicate: keeps the running one
  EXPECT_NEAR(sim.trajectoryEndTime(), stamp + 1.0, 1e-12);
  sim.step(600);
  EXPECT_NEAR(sim.jointTarget("R_SHOULDER_Y"), q0 + 0.4, 1e-12);
  sim.setTrajectory(traj, 0.0);  // unstamped: starts now, from the current target
  EXPECT_NEAR(sim.trajectoryEndTime(), sim.time() + 1.0, 1e-12);
  traj.points[0].positions[0] = q0;  // different content replaces it
  sim.setTrajectory(traj, stamp);
  sim.step(1100);
  EXPECT_NEAR(sim.jointTarget("R_SHOULDER_Y"), q0, 1e-12);
}

TEST(WorkcellSim, StreamedTargetCancelsTrajectory) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  const double q0 = sim.jointTarget("R_SHOULDER_Y");
  lfd_sim::JointTrajectory traj{{"R_SHOULDER_Y"}, {{2.0, {q0 + 0.5}, {}}}};
  sim.setTrajectory(traj);
  sim.step(100);
  sim.setJointTargets({"R_SHOULDER_Y"}, {q0});
  EXPECT_EQ(sim.trajectoryEndTime(), 0.0);
  sim.step(1500);
  EXPECT_NEAR(sim.jointPosition("R_SHOULDER_Y"), q0, 2e-3);
}

TEST(WorkcellSim, RejectsBadCommandsWithoutSideEffects) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  const double q0 = sim.jointTarget("R_SHOULDER_Y");
  EXPECT_THROW(sim.setJointTargets({"NO_SUCH_JOINT"}, {0.0}), std::invalid_argument);
  EXPECT_THROW(sim.setJointTargets({"R_SHOULDER_Y"}, {std::nan("")}), std::invalid_argument);
  EXPECT_THROW(sim.setJointTargets({"R_SHOULDER_Y", "R_ELBOW_P"}, {0.1}), std::invalid_argument);
  // A bad entry anywhere rejects the whole command.
  EXPECT_THROW(sim.setJointTargets({"R_SHOULDER_Y", "BAD"}, {q0 + 0.3, 0.0}),
               std::invalid_argument);
  lfd_sim::JointTrajectory empty{{"R_SHOULDER_Y"}, {}};
  EXPECT_THROW(sim.setTrajectory(empty), std::invalid_argument);
  lfd_sim::JointTrajectory backwards{{"R_SHOULDER_Y"}, {{1.0, {0.1}, {}}, {0.5, {0.2}, {}}}};
  EXPECT_THROW(sim.setTrajectory(backwards), std::invalid_argument);
  EXPECT_THROW(sim.setGripper(std::nan(""), 10.0), std::invalid_argument);
  sim.step(100);
  EXPECT_DOUBLE_EQ(sim.jointTarget("R_SHOULDER_Y"), q0);
}

TEST(WorkcellSim, GripperOpensClosesAndRespectsMaxEffort) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.setGripper(0.08, 0.0);
  sim.step(1000);
  EXPECT_NEAR(sim.readState().gripper_opening, 0.08, 2e-3);
  sim.setGripper(0.0, 5.0);
  double max_force = 0.0;
  for (int k = 0; k < 1000; ++k) {
    sim.step();
    max_force = std::max(max_force, std::abs(sim.readState().gripper_effort));
  }
  EXPECT_LE(max_force, 5.0 + 1e-9);
  EXPECT_NEAR(sim.readState().gripper_opening, 0.0, 2e-3);
}

// Closing the fingers on the stick gives a step of pad force. With a response time the pads
// report it as a first-order rise (63 % after one time constant) that ends at the same level.
TEST(WorkcellSim, TouchPadsRespondWithTheirTimeConstant) {
  lfd_sim::WorkcellConfig raw_config = readyConfig(), pad_config = readyConfig();
  pad_config.touch_time_constant = 0.05;
  lfd_sim::WorkcellSim raw(kModel, raw_config), pad(kModel, pad_config);
  for (lfd_sim::WorkcellSim* sim : {&raw, &pad}) {
    // The stick between the open fingers, its long axis across the closing direction (TCP y).
    lfd_sim::Pose stick = sim->readState().ee_pose;
    stick.position[2] += 0.85;  // base_link -> world
    sim->setObjectPose("stick", stick);
    sim->setGripper(0.0, 20.0);
  }
  std::vector<double> raw_left, pad_left;
  for (int k = 0; k < 1500; ++k) {  // 1.5 s at 1 kHz
    raw.step();
    pad.step();
    raw_left.push_back(reading(raw.readState(), "/touch", 0).at(0));
    pad_left.push_back(reading(pad.readState(), "/touch", 0).at(0));
  }
  const auto onset =
      std::find_if(raw_left.begin(), raw_left.end(), [](double v) { return v > 1.0; });
  ASSERT_NE(onset, raw_left.end()) << "the closed fingers never touch";
  const std::size_t k0 = static_cast<std::size_t>(onset - raw_left.begin());
  ASSERT_LT(k0 + 400, raw_left.size());
  const double level = raw_left.back();
  ASSERT_GT(level, 1.0);
  EXPECT_NEAR(pad_left.back(), level, 0.02 * level);           // same force once settled
  EXPECT_LT(pad_left[k0 + 5], 0.3 * raw_left[k0 + 5]);         // 5 ms: barely started
  EXPECT_NEAR(pad_left[k0 + 50], 0.63 * level, 0.15 * level);  // one time constant
}

TEST(WorkcellSim, EndEffectorVelocityMatchesFiniteDifference) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.setJointTargets({"R_SHOULDER_Y", "R_ELBOW_P"}, {0.5, -0.8});
  sim.step(100);  // moving at the rate limit now
  const lfd_sim::WorkcellState a = sim.readState();
  sim.step();
  const lfd_sim::WorkcellState b = sim.readState();
  sim.step();
  const lfd_sim::WorkcellState c = sim.readState();
  double speed = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double fd = (c.ee_pose.position[i] - a.ee_pose.position[i]) / (2 * sim.timestep());
    EXPECT_NEAR(b.ee_linear_velocity[i], fd, 2e-3 + 0.01 * std::abs(fd)) << "axis " << i;
    speed += fd * fd;
  }
  EXPECT_GT(std::sqrt(speed), 0.1);  // the test is meaningless if the hand does not move
  // Angular velocity: the rotation from a to c, as a rotation vector, over 2 dt.
  mjtNum qa[4], qc[4], qa_inv[4], dq[4], rv[3];
  for (int i = 0; i < 4; ++i) {
    qa[i] = a.ee_pose.orientation[i];
    qc[i] = c.ee_pose.orientation[i];
  }
  mju_negQuat(qa_inv, qa);
  mju_mulQuat(dq, qc, qa_inv);  // world-side difference (base_link axes)
  mju_quat2Vel(rv, dq, 2 * sim.timestep());
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(b.ee_angular_velocity[i], rv[i], 2e-2) << "axis " << i;
}

TEST(WorkcellSim, ResetRestoresPostureAndKeepsTimeMonotonic) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.setJointTargets({"R_SHOULDER_Y"}, {0.6});
  sim.step(500);
  const double t = sim.time();
  sim.reset();
  EXPECT_GE(sim.time(), t);
  EXPECT_DOUBLE_EQ(sim.jointPosition("R_ELBOW_P"), -1.3);
  EXPECT_DOUBLE_EQ(sim.jointPosition("R_SHOULDER_Y"), 0.0);
  EXPECT_DOUBLE_EQ(sim.jointTarget("R_SHOULDER_Y"), 0.0);
  for (double v : sim.readState().joint_velocities) EXPECT_EQ(v, 0.0);
  sim.reset({{"R_SHOULDER_Y", 0.2}});
  EXPECT_DOUBLE_EQ(sim.jointPosition("R_SHOULDER_Y"), 0.2);
  EXPECT_DOUBLE_EQ(sim.jointPosition("R_ELBOW_P"), -1.3);  // unlisted: initial posture
  EXPECT_THROW(sim.reset({{"NOPE", 0.0}}), std::invalid_argument);
  sim.step(300);
  EXPECT_NEAR(sim.jointPosition("R_SHOULDER_Y"), 0.2, 2e-3);
}

TEST(WorkcellSim, SetObjectPoseThenItRestsOnTheTable) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  lfd_sim::Pose p;
  p.position = {0.5, -0.3, 0.86};
  p.orientation = {std::cos(0.25), 0, 0, std::sin(0.25)};  // 0.5 rad about z
  sim.setObjectPose("stick", p);
  lfd_sim::WorkcellState s = sim.readState();
  EXPECT_NEAR(s.object_poses[0].position[0], 0.5, 1e-12);
  EXPECT_NEAR(s.object_poses[0].orientation[3], std::sin(0.25), 1e-12);
  sim.step(1000);
  s = sim.readState();
  EXPECT_NEAR(s.object_poses[0].position[0], 0.5, 5e-3);
  EXPECT_NEAR(s.object_poses[0].position[1], -0.3, 5e-3);
  EXPECT_NEAR(s.object_poses[0].position[2], 0.8 + 0.015, 3e-3);  // resting on the top
  EXPECT_THROW(sim.setObjectPose("table", p), std::invalid_argument);
  p.orientation = {0, 0, 0, 0};
  EXPECT_THROW(sim.setObjectPose("box", p), std::invalid_argument);
  // reset with objects returns them to the model's initial poses.
  sim.reset({}, true);
  EXPECT_NEAR(sim.readState().object_poses[0].position[0], 0.78, 1e-9);
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Regression: x = 1e11 was accepted and the bridge then reset on every physics step; a non-unit
// quaternion far from 1 was silently normalized.
TEST(WorkcellSim, ObjectPosesOutsideTheWorkspaceOrNonUnitAreRefused) {
  LogCounter logs;
  lfd_sim::WorkcellSim sim(kModel, readyConfig(), logs.sink());
  lfd_sim::Pose p;
  p.position = {1e11, 0.0, 0.9};
  EXPECT_NE(refusal([&] { sim.setObjectPose("stick", p); }).find("workspace"), std::string::npos);
  p.position = {0.5, -0.3, 0.86};
  p.orientation = {2.0, 0, 0, 0};
  EXPECT_NE(refusal([&] { sim.setObjectPose("stick", p); }).find("quaternion_tolerance"),
            std::string::npos);
  p.orientation = {1.005, 0, 0, 0};  // within the tolerance: normalized
  EXPECT_NO_THROW(sim.setObjectPose("stick", p));
  EXPECT_NEAR(sim.readState().object_poses[0].orientation[0], 1.0, 1e-12);
  p.position = {1e11, 0.0, 0.9};
  p.orientation = {1, 0, 0, 0};
  EXPECT_THROW(sim.checkObjectPose("box", p), std::invalid_argument);
  sim.step(500);
  EXPECT_EQ(sim.divergenceCount(), 0);
}

// Found in review: /joint_trajectory velocities of 1.7e308 swung the elbow between its limits;
// clamped to the limit, they still made the elbow overshoot both waypoints by 0.6 rad, with
// nothing logged. A velocity beyond the joint's limit refuses the trajectory (nothing moves); one
// within it is followed through its waypoints.
TEST(WorkcellSim, TrajectoryVelocitiesBeyondTheJointLimitAreRefused) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  sim.step(200);
  const double q0 = sim.jointTarget("R_ELBOW_P");
  const double limit = sim.jointLimit("R_ELBOW_P").velocity;
  lfd_sim::JointTrajectory traj;
  traj.joint_names = {"R_ELBOW_P"};
  traj.points = {{0.5, {q0 + 0.05}, {1.7e308}}, {1.0, {q0 + 0.1}, {-1.7e308}}};
  std::string error;
  try {
    sim.setTrajectory(traj);
  } catch (const std::invalid_argument& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("trajectory point 0, joint R_ELBOW_P: velocity 1.7e+308 is beyond the "
                       "joint's limit"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("refused"), std::string::npos) << error;
  EXPECT_FALSE(sim.trajectoryActive());
  // Just over the limit is over it too.
  traj.points = {{0.5, {q0 + 0.05}, {limit * 1.01}}, {1.0, {q0 + 0.1}, {0.0}}};
  EXPECT_THROW(sim.setTrajectory(traj), std::invalid_argument);
  sim.step(1000);
  EXPECT_NEAR(sim.jointTarget("R_ELBOW_P"), q0, 1e-12);  // nothing moved

  // A normal trajectory with velocities within the limit is taken and passes its waypoints.
  traj.points = {{0.5, {q0 + 0.05}, {0.1}}, {1.0, {q0 + 0.1}, {0.0}}};
  sim.setTrajectory(traj);
  EXPECT_TRUE(sim.trajectoryActive());
  double lo = q0, hi = q0;
  for (int k = 0; k < 1500; ++k) {
    sim.step();
    lo = std::min(lo, sim.jointTarget("R_ELBOW_P"));
    hi = std::max(hi, sim.jointTarget("R_ELBOW_P"));
  }
  EXPECT_GT(lo, q0 - 0.01);
  EXPECT_LT(hi, q0 + 0.11);
  EXPECT_NEAR(sim.jointTarget("R_ELBOW_P"), q0 + 0.1, 1e-9);
}

TEST(WorkcellSim, RecoversFromDivergenceWithoutCrashing) {
  LogCounter logs;
  lfd_sim::WorkcellSim sim(kModel, readyConfig(), logs.sink());
  lfd_sim::Pose p;
  p.position = {0.45, -0.25, 0.9};
  sim.setObjectPose("box", p);
  sim.setJointTargets({"R_SHOULDER_Y"}, {0.5});
  sim.step(200);
  const double t = sim.time();
  sim.injectNaNForTest();
  sim.step();
  EXPECT_EQ(sim.divergenceCount(), 1);
  EXPECT_GE(logs.errors, 1);
  EXPECT_NEAR(sim.time(), t + sim.timestep(), 1e-12);  // time neither resets nor stalls
  const lfd_sim::WorkcellState s = sim.readState();
  for (double q : s.joint_positions) ASSERT_TRUE(std::isfinite(q));
  EXPECT_DOUBLE_EQ(sim.jointTarget("R_SHOULDER_Y"), 0.0);  // back to the initial posture
  EXPECT_NEAR(s.object_poses[1].position[0], 0.45, 1e-6);  // box back at its scene pose
  sim.step(500);                                           // and it keeps simulating normally
  EXPECT_EQ(sim.divergenceCount(), 1);
  EXPECT_NEAR(sim.jointPosition("R_ELBOW_P"), -1.3, 5e-3);
}

// The articulated drawer: its cabinet is placed like an object but never pushed (mocap), its
// handle is reported but cannot be placed, its slide is a scene joint that a reset closes again
// (or sets, when named) and a divergence leaves the cabinet where the scene put it.
TEST(WorkcellSim, DrawerIsPlacedReportedAndResetLikeTheOtherObjects) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.objects = {"stick", "drawer", "drawer_handle"};
  lfd_sim::WorkcellSim sim(kModel, c);
  ASSERT_TRUE(sim.hasJoint("drawer_slide"));
  lfd_sim::Pose cabinet;
  cabinet.position = {0.70, -0.30, 0.80};
  cabinet.orientation = {0.0, 0.0, 0.0, 1.0};  // turned by pi: its front faces the robot
  sim.setObjectPose("drawer", cabinet);
  lfd_sim::Pose handle = sim.readState().object_poses[2];
  EXPECT_NEAR(handle.position[0], 0.70 - 0.145, 1e-6);  // config/scene.yaml frames.handle
  EXPECT_NEAR(handle.position[2], 0.87, 1e-6);
  EXPECT_THROW(sim.setObjectPose("drawer_handle", cabinet), std::invalid_argument);
  // Pulled open by hand (its joint set), the handle moves with it; the cabinet never moves.
  sim.reset({{"drawer_slide", 0.1}});
  sim.step(200);
  const lfd_sim::WorkcellState open = sim.readState();
  EXPECT_NEAR(sim.jointPosition("drawer_slide"), 0.1, 1e-3);
  EXPECT_NEAR(open.object_poses[2].position[0], 0.70 - 0.245, 1e-3);
  EXPECT_NEAR(open.object_poses[1].position[0], 0.70, 1e-9);
  // Reported as a scene object's joint (the bridge's /objects/joint_states), every other as the
  // robot's (/joint_states, which robot_state_publisher reads against the URDF).
  const auto& names = open.joint_names;
  ASSERT_EQ(open.object_joint.size(), names.size());
  for (size_t i = 0; i < names.size(); ++i)
    EXPECT_EQ(open.object_joint[i], names[i] == "drawer_slide") << names[i];
  sim.reset();  // closed again, the cabinet where the scene put it
  EXPECT_NEAR(sim.jointPosition("drawer_slide"), 0.0, 1e-9);
  EXPECT_NEAR(sim.readState().object_poses[1].position[0], 0.70, 1e-9);
  sim.injectNaNForTest();
  sim.step();
  EXPECT_EQ(sim.divergenceCount(), 1);
  EXPECT_NEAR(sim.readState().object_poses[1].position[0], 0.70, 1e-9);
  sim.reset({}, true);  // objects back to the model's (park) poses
  EXPECT_NEAR(sim.readState().object_poses[1].position[0], 0.38, 1e-9);
}

TEST(WorkcellSim, SimTimeIsStrictlyMonotonic) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  double t = sim.time();
  for (int k = 0; k < 50; ++k) {
    sim.step();
    ASSERT_GT(sim.time(), t);
    t = sim.time();
    if (k == 10) sim.reset({}, true);
    if (k == 20) sim.injectNaNForTest();
    ASSERT_GE(sim.time(), t);
  }
  EXPECT_NEAR(sim.time(), 0.05, 1e-9);
}

TEST(WorkcellSim, NoiseIsSeededAndOnlyInReadings) {
  lfd_sim::WorkcellConfig c = readyConfig();
  c.noise.joint_position = 0.01;
  c.noise.force = 0.5;
  lfd_sim::WorkcellSim a(kModel, c), b(kModel, c);
  const lfd_sim::WorkcellState sa = a.readState(), sb = b.readState();
  EXPECT_EQ(sa.joint_positions, sb.joint_positions);  // same seed, same noise
  double diff = 0.0;
  for (size_t j = 0; j < sa.joint_names.size(); ++j) {
    diff += std::abs(sa.joint_positions[j] - a.jointPosition(sa.joint_names[j]));
  }
  EXPECT_GT(diff / sa.joint_names.size(), 0.002);  // noise of std 0.01 is there
  EXPECT_LT(diff / sa.joint_names.size(), 0.03);
}

// One simulation records datasets of different modes in turn: switching the noise restarts its
// generator, so what follows does not depend on the readings taken before.
TEST(WorkcellSim, SetNoiseSwitchesAndReseeds) {
  lfd_sim::WorkcellSim quiet(kModel, readyConfig()), noisy(kModel, readyConfig());
  lfd_sim::SensorNoise teleop;
  teleop.joint_position = 0.01;
  teleop.touch = 0.8;
  noisy.setNoise(teleop, 7);
  for (int i = 0; i < 5; ++i) noisy.readState();  // readings of "an earlier dataset"
  noisy.setNoise(teleop, 7);
  quiet.setNoise(teleop, 7);
  const lfd_sim::WorkcellState a = noisy.readState(), b = quiet.readState();
  EXPECT_EQ(a.joint_positions, b.joint_positions);
  EXPECT_EQ(a.sensor("/touch")->values, b.sensor("/touch")->values);
  EXPECT_EQ(noisy.sensorNoise().touch, 0.8);
  noisy.setNoise(lfd_sim::SensorNoise(), 7);  // back to exact readings
  const lfd_sim::WorkcellState exact = noisy.readState();
  for (size_t j = 0; j < exact.joint_names.size(); ++j)
    EXPECT_EQ(exact.joint_positions[j], noisy.jointPosition(exact.joint_names[j]));
}

TEST(WorkcellSim, UrdfLimitsOverrideVelocityAndEffort) {
  lfd_sim::WorkcellSim sim(kModel, readyConfig());
  const std::string urdf =
      "<robot name='r'><link name='a'/><link name='b'/>"
      "<joint name='R_SHOULDER_Y' type='revolute'><parent link='a'/><child link='b'/>"
      "<axis xyz='0 0 1'/><limit lower='-1.6' upper='1.6' effort='33' velocity='0.7'/></joint>"
      "</robot>";
  sim.applyUrdfLimits(urdf);
  EXPECT_DOUBLE_EQ(sim.jointLimit("R_SHOULDER_Y").velocity, 0.7);
  EXPECT_DOUBLE_EQ(sim.jointLimit("R_SHOULDER_Y").effort, 33.0);
  EXPECT_THROW(sim.applyUrdfLimits("<not a urdf"), std::invalid_argument);
}

TEST(TrajectoryInterpolator, HitsKnotsAndIsC1) {
  lfd_sim::JointTrajectory traj{
      {"a", "b"}, {{1.0, {1.0, -1.0}, {}}, {2.0, {2.0, 0.0}, {}}, {3.0, {0.0, 0.0}, {}}}};
  lfd_sim::TrajectoryInterpolator interp(traj, 10.0, {0.0, 0.0});
  std::vector<double> p, v;
  interp.sample(11.0, &p, &v);
  EXPECT_NEAR(p[0], 1.0, 1e-12);
  EXPECT_NEAR(p[1], -1.0, 1e-12);
  EXPECT_NEAR(v[1], 0.0, 1e-12);  // local minimum of b: zero slope, no overshoot
  interp.sample(9.0, &p, &v);
  EXPECT_EQ(p, std::vector<double>({0.0, 0.0}));
  interp.sample(20.0, &p, &v);
  EXPECT_EQ(p, std::vector<double>({0.0, 0.0}));
  EXPECT_EQ(v, std::vector<double>({0.0, 0.0}));
  // Velocity continuous across the knot at t = 12.
  std::vector<double> p1, v1, p2, v2;
  interp.sample(12.0 - 1e-7, &p1, &v1);
  interp.sample(12.0 + 1e-7, &p2, &v2);
  EXPECT_NEAR(v1[0], v2[0], 1e-4);
  // Numerical derivative matches the reported velocity.
  interp.sample(11.5, &p, &v);
  interp.sample(11.5 + 1e-6, &p1, &v1);
  EXPECT_NEAR((p1[0] - p[0]) / 1e-6, v[0], 1e-4);
}

TEST(TrajectoryInterpolator, ValidationNamesTheProblem) {
  auto message = [](const lfd_sim::JointTrajectory& t) {
    try {
      lfd_sim::validateTrajectory(t);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message({{}, {{1.0, {}, {}}}}).find("no joint"), std::string::npos);
  EXPECT_NE(message({{"a"}, {}}).find("no points"), std::string::npos);
  EXPECT_NE(message({{"a", "a"}, {{1.0, {0, 0}, {}}}}).find("duplicate"), std::string::npos);
  EXPECT_NE(message({{"a"}, {{1.0, {0, 0}, {}}}}).find("positions"), std::string::npos);
  EXPECT_NE(message({{"a"}, {{1.0, {INFINITY}, {}}}}).find("NaN or infinite"), std::string::npos);
  EXPECT_NE(message({{"a"}, {{1.0, {0}, {}}, {1.0, {1}, {}}}}).find("not after"),
            std::string::npos);
  EXPECT_EQ(message({{"a"}, {{0.0, {0}, {}}, {1.0, {1}, {0.5}}}}), "accepted");
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
