// Unit test of the demonstrator's Cartesian -> joint conversion on the real robot model: a whole
// grasp demonstration is planned, sampled and solved, and forward kinematics of the joint path
// must reproduce the Cartesian path.
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "lfd_sim_bridge/demo_ik.hpp"
#include "lfd_sim_bridge/demo_tasks.hpp"

namespace demo = lfd_sim_bridge::demo;

namespace {

lfd::KinematicChain rightArm() {
  return lfd::KinematicChain::fromUrdfFile(std::string(LFD_SIM_MODEL_DIR) + "/jvrc1_like.urdf",
                                           "base_link", "r_gripper_tcp");
}

// The bridge's ready posture (config/bridge.yaml).
Eigen::VectorXd readyPosture(const lfd::KinematicChain& chain) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(chain.dof());
  const std::pair<const char*, double> ready[] = {
      {"R_SHOULDER_P", -0.3}, {"R_ELBOW_P", -1.3}, {"R_WRIST_Y", 1.4}};
  for (const auto& [name, value] : ready) {
    const int i = chain.jointIndex(name);
    if (i >= 0) q[i] = value;
  }
  return q;
}

demo::Pose at(double x, double y, double z, double yaw) {
  demo::Pose p;
  p.position = {x, y, z};
  p.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return p;
}

}  // namespace

// Configured like the demonstrator node: IK costs and preferred posture from config/tasks.yaml,
// a configuration of the simulated grasp dataset moved from world to base_link.
TEST(CartesianToJoints, GraspDemoIsTrackedByTheJointPath) {
  const demo::TaskSetup setup = demo::loadTaskSetup(
      std::string(LFD_SIM_MODEL_DIR) + "/../../config/tasks.yaml", "grasp", "sim");
  const lfd::KinematicChain chain = rightArm();
  lfd::IkOptions options;
  options.joint_costs = Eigen::VectorXd::Ones(chain.dof());
  Eigen::VectorXd preferred = Eigen::VectorXd::Zero(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    const std::string& joint = chain.jointNames()[i];
    if (setup.joint_costs.count(joint)) options.joint_costs[i] = setup.joint_costs.at(joint);
    if (setup.preferred_posture.count(joint)) preferred[i] = setup.preferred_posture.at(joint);
  }
  demo::CartesianToJoints converter(chain, Eigen::Isometry3d::Identity(), options);
  converter.setPreferredPosture(preferred);
  const Eigen::VectorXd q0 = readyPosture(chain);
  const demo::Pose start = converter.forward(q0);
  const Eigen::Vector3d base_in_world(0.0, 0.0, 0.85);
  demo::TaskInstance inst{"grasp", setup.configurations.at(4).object_start,
                          setup.configurations.at(4).goal};
  inst.object_start.position -= base_in_world;
  inst.goal.position -= base_in_world;
  std::mt19937 rng(1);
  const demo::DemoPlan plan = demo::planDemo(inst, start, demo::Geometry{}, demo::Timing{},
                                             demo::Variation{}, demo::TeleopStyle{}, rng);
  demo::Pose from = start;
  Eigen::VectorXd seed = q0;
  for (const demo::Phase& phase : plan.phases) {
    const auto samples = demo::samplePhase(from, phase, 0.02, 0.0);
    const demo::JointPath path = converter.convert(samples, seed);
    ASSERT_EQ(path.positions.size(), samples.size());
    for (size_t k = 0; k < samples.size(); ++k) {
      const demo::Pose fk = converter.forward(path.positions[k]);
      EXPECT_LT((fk.position - samples[k].pose.position).norm(), 2e-3) << phase.name << " " << k;
      EXPECT_LT(fk.orientation.angularDistance(samples[k].pose.orientation), 0.03);
      EXPECT_TRUE(chain.withinLimits(path.positions[k], 1e-6));
    }
    // The joint servos can follow it (the bridge rate-limits targets beyond the URDF limits).
    EXPECT_LT(path.max_speed_ratio, 1.0) << phase.name;
    seed = path.positions.back();
    from = phase.segments.back().target;
  }
}

TEST(CartesianToJoints, UnreachablePoseIsAClearError) {
  const lfd::KinematicChain chain = rightArm();
  demo::CartesianToJoints converter(chain);
  const Eigen::VectorXd q0 = readyPosture(chain);
  std::vector<demo::TimedPose> far = {{0.0, converter.forward(q0)}, {0.1, at(2.0, 0.0, 0.0, 0.0)}};
  try {
    converter.convert(far, q0);
    FAIL() << "a pose 2 m away must not be reachable";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("t=0.1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(converter.convert(far, Eigen::VectorXd::Zero(2)), std::invalid_argument);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

// Issue 12: a pose so far away that IK's error overflows (a skill library with weights of 1e300)
// made convert() read an empty joint vector (segfault in the executor). Non-finite or overflowing
// poses must be a clear error.
TEST(CartesianToJoints, OverflowingOrNonFinitePoseIsAClearError) {
  const lfd::KinematicChain chain = rightArm();
  lfd::IkOptions options;
  demo::CartesianToJoints converter(chain, Eigen::Isometry3d::Identity(), options);
  const Eigen::VectorXd q0 = readyPosture(chain);
  const demo::Pose start = converter.forward(q0);
  for (double x : {1e300, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    demo::Pose far = start;
    far.position.x() = x;
    const std::vector<demo::TimedPose> samples = {{0.0, start}, {0.1, far}};
    try {
      converter.convert(samples, q0);
      ADD_FAILURE() << "no error for x = " << x;
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("t=0.1"), std::string::npos) << what;
      EXPECT_NE(what.find("finite"), std::string::npos) << what;
    }
  }
}
