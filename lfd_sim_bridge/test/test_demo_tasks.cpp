// Unit tests of the task configurations (config/tasks.yaml) and of the physical success criterion
// shared by the demonstrator and check_demo_bag.py.
#include <cstdio>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "lfd_sim_bridge/demo_tasks.hpp"

namespace demo = lfd_sim_bridge::demo;

namespace {

const std::string kTasksFile = std::string(LFD_SIM_MODEL_DIR) + "/../../config/tasks.yaml";

demo::Pose at(double x, double y, double z) {
  demo::Pose p;
  p.position = {x, y, z};
  return p;
}

std::string writeTemp(const std::string& text) {
  char name[] = "/tmp/test_demo_tasks_XXXXXX";
  const int fd = mkstemp(name);
  EXPECT_GE(fd, 0);
  close(fd);
  std::ofstream(name) << text;
  return name;
}

}  // namespace

TEST(TaskSetup, RepositoryConfigurationsCoverThePaperDatasets) {
  for (const std::string mode : {"sim", "teleop"}) {
    const demo::TaskSetup grasp = demo::loadTaskSetup(kTasksFile, "grasp", mode);
    EXPECT_EQ(grasp.object, "stick");
    EXPECT_EQ(grasp.configurations.size(), 9u) << mode;
    const demo::TaskSetup push = demo::loadTaskSetup(kTasksFile, "push", mode);
    EXPECT_EQ(push.object, "box");
    EXPECT_GE(push.configurations.size(), 6u) << mode;
    for (const auto* setup : {&grasp, &push}) {
      EXPECT_TRUE(setup->park.count("stick") && setup->park.count("box"));
      for (const demo::TaskConfiguration& c : setup->configurations) {
        // Objects start on the table top; grasp goals are lifted >= 10 cm, push targets on it.
        EXPECT_NEAR(c.object_start.position.z() - setup->table_top, setup == &grasp ? 0.015 : 0.04,
                    1e-6);
        if (setup == &grasp) EXPECT_GE(c.goal.position.z() - setup->table_top, 0.10);
        if (setup == &push) EXPECT_GT((c.goal.position - c.object_start.position).norm(), 0.05);
      }
    }
  }
  // Teleop variants stay inside a 15 x 15 cm area (object starts).
  const demo::TaskSetup teleop = demo::loadTaskSetup(kTasksFile, "grasp", "teleop");
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const auto& c : teleop.configurations) {
    lo = lo.cwiseMin(c.object_start.position.head<2>());
    hi = hi.cwiseMax(c.object_start.position.head<2>());
  }
  EXPECT_LE((hi - lo).maxCoeff(), 0.15 + 1e-9);
}

TEST(TaskSetup, ParsesPoseFormsAndReportsErrors) {
  const std::string good = writeTemp(
      "table_top: 0.7\n"
      "gripper_orientation: {grasp: [0, 0, 0, 1]}\n"
      "grasp:\n"
      "  sim:\n"
      "    - {id: 4, stick: [0.3, -0.2, 0.715, 1.5707963267948966], goal: {position: [0.3, -0.1, "
      "0.9], yaw: 0}}\n");
  const demo::TaskSetup s = demo::loadTaskSetup(good, "grasp", "sim");
  EXPECT_DOUBLE_EQ(s.table_top, 0.7);
  EXPECT_NEAR(std::abs(s.grasp_orientation.z()), 1.0, 1e-12);
  ASSERT_EQ(s.configurations.size(), 1u);
  EXPECT_EQ(s.configurations[0].index, 4);
  const Eigen::Vector3d axis =
      s.configurations[0].object_start.orientation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(axis.y(), 1.0, 1e-9);                                            // yaw pi/2
  EXPECT_THROW(demo::loadTaskSetup(good, "push", "sim"), std::runtime_error);  // no push list
  EXPECT_THROW(demo::loadTaskSetup(good, "pour", "sim"), std::runtime_error);
  EXPECT_THROW(demo::loadTaskSetup("/nonexistent/tasks.yaml", "grasp", "sim"), std::runtime_error);
  const std::string bad = writeTemp("grasp:\n  sim:\n    - {stick: [0.3, 0.2], goal: [0, 0, 1]}\n");
  try {
    demo::loadTaskSetup(bad, "grasp", "sim");
    FAIL() << "a 2-D position must be rejected";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("grasp.sim[0].stick"), std::string::npos) << e.what();
  }
  std::remove(good.c_str());
  std::remove(bad.c_str());
}

// The hand-made cases below are written for these numbers (config/evaluation.yaml's today).
const demo::SuccessCriteria kCriteria{0.03, 0.10};

TEST(Judge, GraspNeedsLiftAndGoal) {
  const demo::Pose goal = at(0.5, -0.3, 0.95);
  EXPECT_TRUE(demo::judge("grasp", at(0.51, -0.29, 0.94), goal, 0.80, kCriteria).success);
  EXPECT_FALSE(demo::judge("grasp", at(0.5, -0.3, 0.89), at(0.5, -0.3, 0.89), 0.80, kCriteria).success)
      << "at the goal but only 9 cm above the table";
  const demo::Outcome far = demo::judge("grasp", at(0.54, -0.3, 0.95), goal, 0.80, kCriteria);
  EXPECT_FALSE(far.success);
  EXPECT_NEAR(far.distance, 0.04, 1e-9);
  EXPECT_FALSE(demo::judge("grasp", at(0.5, -0.3, 0.815), goal, 0.80, kCriteria).success);  // dropped
}

TEST(Judge, PushUsesTheHorizontalDistance) {
  const demo::Pose target = at(0.5, -0.3, 0.84);
  EXPECT_TRUE(demo::judge("push", at(0.52, -0.31, 0.84), target, 0.80, kCriteria).success);
  EXPECT_FALSE(demo::judge("push", at(0.47, -0.28, 0.84), target, 0.80, kCriteria).success);
  EXPECT_THROW(demo::judge("pour", target, target, 0.8, kCriteria), std::invalid_argument);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
