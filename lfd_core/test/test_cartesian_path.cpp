// Cartesian path -> joint path (the IK shared by the demonstrator and the executor) and the robot
// description file that configures it, on the robot model of jvrc1_description and its
// config/robot.yaml.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>

#include <gtest/gtest.h>

#include "lfd_core/kinematics/cartesian_path.hpp"
#include "lfd_core/kinematics/robot_setup.hpp"

namespace {

const std::string kRobotFile = std::string(LFD_ROBOT_DIR) + "/config/robot.yaml";
const std::string kUrdfPath = std::string(LFD_ROBOT_DIR) + "/models/jvrc1_like.urdf";

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

std::string writeTemp(const std::string& text) {
  char name[] = "/tmp/lfd_robot_XXXXXX";
  const int fd = mkstemp(name);
  EXPECT_GE(fd, 0);
  std::FILE* f = fdopen(fd, "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return name;
}

lfd::CartesianToJoints repositoryIk() {
  return lfd::makeCartesianToJoints(readFile(kUrdfPath), lfd::loadRobotSetup(kRobotFile));
}

// The robot.yaml posture: the null-space equilibrium the demonstrator starts from.
Eigen::VectorXd home(const lfd::CartesianToJoints& ik) {
  const lfd::RobotSetup setup = lfd::loadRobotSetup(kRobotFile);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(ik.chain().dof());
  for (int i = 0; i < q.size(); ++i) {
    const auto it = setup.preferred_posture.find(ik.chain().jointNames()[i]);
    if (it != setup.preferred_posture.end()) q[i] = it->second;
  }
  return q;
}

}  // namespace

TEST(RobotSetup, RepositoryFileDescribesTheWaistAndRightArm) {
  const lfd::RobotSetup s = lfd::loadRobotSetup(kRobotFile);
  EXPECT_EQ(s.name, "jvrc1");
  EXPECT_EQ(s.base_link, "base_link");
  EXPECT_EQ(s.tip_link, "r_gripper_tcp");
  EXPECT_GT(s.joint_costs.at("WAIST_R"), s.joint_costs.at("WAIST_Y"));
  EXPECT_EQ(s.gripper.joint, "R_GRIPPER");
  EXPECT_GT(s.gripper.open_opening, s.gripper.close_opening);
  EXPECT_EQ(s.gripper.opening_scale, 2.0);  // each pad moves by the joint
  EXPECT_EQ(s.initial_posture.count("R_ELBOW_P"), 1u);
  EXPECT_EQ(s.initial_posture.count("R_GRIPPER"), 1u);
  // The sensor table, rows and fields in the file's order (the order readings are taken in).
  ASSERT_EQ(s.sensors.size(), 3u);
  EXPECT_EQ(s.sensors[0].topic, "/wrist_ft");
  EXPECT_EQ(s.sensors[0].fields.front().first, "force");
  const lfd::SensorEntry* touch = lfd::findSensorOfType(s, "lfd_msgs/Touch");
  ASSERT_NE(touch, nullptr);
  EXPECT_EQ(touch->fields.at(0).second,
            (std::vector<std::string>{"r_touch_left", "r_touch_right"}));
  EXPECT_EQ(lfd::findSensorOfType(s, "no_msgs/Nothing"), nullptr);
  const lfd::CartesianToJoints ik = repositoryIk();
  EXPECT_EQ(ik.chain().dof(), 10);  // waist 3 + arm 7
}

TEST(RobotSetup, BadFilesAreClearErrors) {
  const auto expect_error = [](const std::string& text, const std::string& needle) {
    const std::string path = writeTemp(text);
    try {
      lfd::loadRobotSetup(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    std::remove(path.c_str());
  };
  expect_error("gripper: {joint: G}\n", "ik");
  expect_error("ik: {base_link: a}\n", "tip_link");
  expect_error("ik: {tip_link: t, joint_costs: {J: -1}}\n", "joint_costs.J");
  expect_error("ik: {tip_link: t, tolerance: {position: 0}}\n", "tolerance.position");
  expect_error("ik: {tip_link: t}\ngripper: {joint: G, open_opening: 0.0, close_opening: 0.05}\n",
               "open_opening");
  expect_error("ik: [1, 2\n", "cannot be read");
  expect_error("ik: {tip_link: t}\ngripper: {close_effort: 5}\n", "gripper.joint");
  expect_error("ik: {tip_link: t}\ngripper: {joint: G, opening_scale: 0}\n",
               "gripper.opening_scale");
  expect_error("ik: {tip_link: t}\ninitial_posture: {J: .nan}\n", "initial_posture.J");
  expect_error("ik: {tip_link: t}\ninitial_posture: [1]\n", "initial_posture must map");
  const std::string ik = "ik: {tip_link: t}\n";
  expect_error(ik + "sensors: {a: 1}\n", "sensors must be a list");
  expect_error(ik + "sensors: [{topic: /f, type: T, fields: {force: s}}]\n", "sensors[0].frame");
  expect_error(ik + "sensors: [{topic: /f, type: T, frame: f, fields: {}}]\n", "sensors[0].fields");
  expect_error(ik + "sensors: [{topic: /f, type: T, frame: f, fields: {values: []}}]\n",
               "sensors[0].fields.values");
  expect_error(ik + "sensors: [{topic: /f, type: T, frame: f, rate: 3, fields: {a: s}}]\n",
               "unknown key 'rate'");
  expect_error(ik + "sensors: [{topic: /f, type: T, frame: f, fields: {a: s}},\n"
                    "          {topic: /f, type: U, frame: g, fields: {b: t}}]\n",
               "topic /f appears twice");
  expect_error(ik + "sensors: [{topic: /f, type: T, frame: f, fields: {a: s}},\n"
                    "          {topic: /g, type: U, frame: g, fields: {b: [t, s]}}]\n",
               "sensor 's' is read twice (/f and /g)");
  EXPECT_THROW(lfd::loadRobotSetup("/nonexistent/robot.yaml"), std::runtime_error);
}

TEST(RobotSetup, ChainRootOffsetFromTheCartesianFrame) {
  // A chain rooted at the chest with poses still in base_link: FK must agree with the full chain.
  const std::string urdf = readFile(kUrdfPath);
  lfd::RobotSetup chest;
  chest.base_link = "chest_link";
  chest.tip_link = "r_gripper_tcp";
  chest.cartesian_frame = "base_link";
  const lfd::CartesianToJoints arm = lfd::makeCartesianToJoints(urdf, chest);
  const lfd::KinematicChain full =
      lfd::KinematicChain::fromUrdfString(urdf, "base_link", "r_gripper_tcp");
  Eigen::VectorXd q_full = Eigen::VectorXd::Zero(full.dof());
  Eigen::VectorXd q_arm = Eigen::VectorXd::Zero(arm.chain().dof());
  q_arm << -0.3, 0.1, 0.2, -1.2, 0.1, 0.2, 1.4;
  q_full.tail(7) = q_arm;  // waist at zero, as the offset assumes
  EXPECT_LT((arm.forward(q_arm).position - full.forward(q_full).translation()).norm(), 1e-12);
}

TEST(CartesianToJoints, LineIsTrackedWithinTheToleranceAndLimits) {
  lfd::CartesianToJoints ik = repositoryIk();
  const Eigen::VectorXd q0 = home(ik);
  const lfd::Pose start = ik.forward(q0);
  std::vector<lfd::TimedPose> samples;
  for (int k = 0; k <= 50; ++k) {
    lfd::Pose p = start;
    p.position += Eigen::Vector3d(0.1, -0.08, -0.05) * (k / 50.0);
    p.orientation = start.orientation * Eigen::AngleAxisd(0.3 * k / 50.0, Eigen::Vector3d::UnitZ());
    samples.push_back({0.04 * k, p});
  }
  const lfd::JointPath path = ik.convert(samples, q0);
  ASSERT_EQ(path.positions.size(), samples.size());
  for (size_t k = 0; k < samples.size(); ++k) {
    const lfd::Pose fk = ik.forward(path.positions[k]);
    EXPECT_LT((fk.position - samples[k].pose.position).norm(), 2e-3) << k;
    EXPECT_LT(fk.orientation.angularDistance(samples[k].pose.orientation), 0.03) << k;
    EXPECT_TRUE(ik.chain().withinLimits(path.positions[k], 1e-6));
  }
  EXPECT_LT(path.max_speed_ratio, 1.0);
}

TEST(CartesianToJoints, UnreachablePoseIsAClearError) {
  lfd::CartesianToJoints ik = repositoryIk();
  const Eigen::VectorXd q0 = home(ik);
  lfd::Pose far;
  far.position = {2.0, 0.0, 0.0};
  const std::vector<lfd::TimedPose> samples = {{0.0, ik.forward(q0)}, {0.1, far}};
  try {
    ik.convert(samples, q0);
    FAIL() << "a pose 2 m away must not be reachable";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("t=0.1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("position (2 0 0)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("robot jvrc1 cannot reach"), std::string::npos)
        << e.what();  // the robot file's name
  }
  EXPECT_THROW(ik.convert(samples, Eigen::VectorXd::Zero(2)), std::invalid_argument);
}

// Regression: a pose so far away that IK's error overflows (a skill library with weights of 1e300)
// made convert() read an empty joint vector (segfault in the executor).
TEST(CartesianToJoints, OverflowingOrNonFinitePoseIsAClearError) {
  lfd::CartesianToJoints ik = repositoryIk();
  const Eigen::VectorXd q0 = home(ik);
  const lfd::Pose start = ik.forward(q0);
  for (double x :
       {1e300, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    lfd::Pose far = start;
    far.position.x() = x;
    try {
      ik.convert({{0.0, start}, {0.1, far}}, q0);
      ADD_FAILURE() << "no error for x = " << x;
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("t=0.1"), std::string::npos) << what;
      EXPECT_NE(what.find("finite"), std::string::npos) << what;
    }
  }
}
