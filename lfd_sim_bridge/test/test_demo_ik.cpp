// Unit test of the demonstrator's Cartesian -> joint conversion on the real robot model: a whole
// grasp demonstration of config/tasks/grasp.yaml is planned by the task interpreter, sampled and
// solved, and forward kinematics of the joint path must reproduce the Cartesian path.
#include <fstream>
#include <iterator>
#include <random>

#include <gtest/gtest.h>

#include "lfd_core/kinematics/cartesian_path.hpp"
#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/demo_plan.hpp"

namespace demo = lfd_sim_bridge::demo;
namespace task = lfd_sim_bridge::task;

namespace {

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

}  // namespace

// Configured like the demonstrator node: the IK of the robot file, a configuration of the
// simulated grasp dataset, base_link 0.85 m above the world origin.
TEST(CartesianToJoints, GraspDemoIsTrackedByTheJointPath) {
  const std::string config = std::string(LFD_CONFIG_DIR) + "/";
  const task::Scene scene = task::loadScene(config + "scene.yaml");
  const task::TaskDefinition grasp = task::loadTask(config + "tasks/grasp.yaml", scene);
  std::ifstream urdf_file(std::string(LFD_SIM_MODEL_DIR) + "/jvrc1_like.urdf");
  const std::string urdf((std::istreambuf_iterator<char>(urdf_file)), {});
  const lfd::RobotSetup robot = lfd::loadRobotSetup(LFD_ROBOT_FILE);
  lfd::CartesianToJoints converter = lfd::makeCartesianToJoints(urdf, robot);
  const lfd::KinematicChain& chain = converter.chain();
  const Eigen::VectorXd q0 = readyPosture(chain);
  const demo::Pose start = converter.forward(q0);
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();
  world_from_base.translation() = scene.base_in_world;
  const demo::TaskInterpreter interpreter(grasp, scene, robot.gripper, demo::ToolGeometry{},
                                          demo::TeleopStyle{});
  std::mt19937 rng(1);
  const demo::DemoPlan plan = interpreter.planAll(
      interpreter.begin(grasp.configurations.at("sim").at(4), world_from_base, start, 1.0, rng));
  demo::Pose from = start;
  Eigen::VectorXd seed = q0;
  for (const demo::Phase& phase : plan.phases) {
    const auto samples = demo::samplePhase(from, phase, 0.02, 0.0);
    const lfd::JointPath path = converter.convert(samples, seed);
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

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
