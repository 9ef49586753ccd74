// IK, FK and Jacobian throughput on each robot's IK chain, as its robot file describes it (the
// humanoid's waist and right arm, 10 DoF; the arm's 7 DoF), from its preferred posture. The IK
// case mimics DMP execution: each solve is warm-started from the previous solution and the target
// moves a few millimetres along a smooth path. Nothing here names a joint: the chain, its costs
// and posture are the robot file's (lfd::makeCartesianToJoints).
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "lfd_core/kinematics/inverse_kinematics.hpp"
#include "lfd_core/kinematics/kinematic_chain.hpp"
#include "lfd_core/kinematics/robot_setup.hpp"

namespace {

// A robot description package's IK chain and preferred posture.
struct Robot {
  std::string name;  // the robot file's
  lfd::KinematicChain chain;
  Eigen::VectorXd posture;
};

// The package's one URDF (models/*.urdf).
std::string urdfOf(const std::filesystem::path& dir) {
  for (const auto& entry : std::filesystem::directory_iterator(dir / "models"))
    if (entry.path().extension() == ".urdf") {
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      return text.str();
    }
  throw std::runtime_error("no URDF under " + (dir / "models").string());
}

Robot loadRobot(const std::filesystem::path& dir) {
  const lfd::RobotSetup setup = lfd::loadRobotSetup((dir / "config" / "robot.yaml").string());
  lfd::KinematicChain chain =
      lfd::KinematicChain::fromUrdfString(urdfOf(dir), setup.base_link, setup.tip_link);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    const auto it = setup.preferred_posture.find(chain.jointNames()[i]);
    if (it != setup.preferred_posture.end()) q[i] = it->second;
  }
  return {setup.name, std::move(chain), q};
}

void forward(benchmark::State& state, const Robot& robot) {
  Eigen::VectorXd q = robot.posture;
  for (auto _ : state) {
    q[0] += 1e-9;
    benchmark::DoNotOptimize(robot.chain.forward(q));
  }
  state.counters["fk/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}

void forwardAndJacobian(benchmark::State& state, const Robot& robot) {
  Eigen::VectorXd q = robot.posture;
  Eigen::Isometry3d pose;
  lfd::Matrix6Xd jac(6, robot.chain.dof());
  for (auto _ : state) {
    q[0] += 1e-9;
    robot.chain.forwardAndJacobian(q, pose, jac);
    benchmark::DoNotOptimize(jac.data());
  }
  state.counters["jac/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}

// Warm-started tracking of a circle of radius 5 cm sampled every 2 mm (a DMP-like stream).
void ikWarmStart(benchmark::State& state, const Robot& robot) {
  lfd::InverseKinematics ik(robot.chain);
  ik.setPreferredPosture(robot.posture);
  const Eigen::Isometry3d center = robot.chain.forward(robot.posture);
  lfd::IkResult result;
  result.q = robot.posture;
  double phase = 0.0;
  int64_t failures = 0, iterations = 0;
  for (auto _ : state) {
    phase += 0.04;
    Eigen::Isometry3d target = center;
    target.translation() += 0.05 * Eigen::Vector3d(std::cos(phase) - 1.0, std::sin(phase), 0.0);
    target.linear() =
        center.linear() * Eigen::AngleAxisd(0.2 * std::sin(phase), Eigen::Vector3d::UnitZ());
    if (!ik.solve(target, result.q, result)) ++failures;
    iterations += result.iterations;
  }
  state.counters["solves/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
  state.counters["failures"] = static_cast<double>(failures);
  state.counters["iter/solve"] = static_cast<double>(iterations) / state.iterations();
}

// Cold solves from the preferred posture toward random-ish reachable targets (reachability query).
void ikColdReach(benchmark::State& state, const Robot& robot) {
  lfd::InverseKinematics ik(robot.chain);
  int64_t k = 0, failures = 0;
  for (auto _ : state) {
    Eigen::VectorXd q = robot.posture;
    for (int i = 0; i < q.size(); ++i) q[i] += 0.4 * std::sin(0.7 * (++k) + i);
    robot.chain.clampToLimits(q);
    const lfd::IkResult r = ik.reach(robot.chain.forward(q), robot.posture);
    if (!r.converged) ++failures;
  }
  state.counters["solves/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
  state.counters["failures"] = static_cast<double>(failures);
}

}  // namespace

int main(int argc, char** argv) {
  static const std::vector<Robot> kRobots = {loadRobot(LFD_ROBOT_DIR),
                                             loadRobot(LFD_ARM7_ROBOT_DIR)};
  for (const Robot& robot : kRobots) {
    const std::string tag = robot.name + " (" + std::to_string(robot.chain.dof()) + " DoF)";
    const auto add = [&robot, &tag](const std::string& what,
                                    void (*run)(benchmark::State&, const Robot&)) {
      benchmark::RegisterBenchmark((what + "/" + tag).c_str(),
                                   [&robot, run](benchmark::State& state) { run(state, robot); });
    };
    add("Forward", forward);
    add("ForwardAndJacobian", forwardAndJacobian);
    add("IkWarmStart", ikWarmStart);
    add("IkColdReach", ikColdReach);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
