// IK, FK and Jacobian throughput on the 7-DoF right arm (chest_link -> r_gripper_tcp) of the lfd
// humanoid. The IK case mimics DMP execution: each solve is warm-started from the previous
// solution and the target moves a few millimetres along a smooth path.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "lfd_core/inverse_kinematics.hpp"
#include "lfd_core/kinematic_chain.hpp"

namespace {

const std::string kUrdf = std::string(LFD_ROBOT_DIR) + "/models/jvrc1_like.urdf";

lfd::KinematicChain armChain(const char* base) {
  return lfd::KinematicChain::fromUrdfFile(kUrdf, base, "r_gripper_tcp");
}

// A comfortable reaching posture (elbow bent, hand in front of the body).
Eigen::VectorXd homePosture(const lfd::KinematicChain& chain) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(chain.dof());
  q[chain.jointIndex("R_SHOULDER_P")] = -0.6;
  q[chain.jointIndex("R_SHOULDER_R")] = -0.2;
  q[chain.jointIndex("R_ELBOW_P")] = -1.2;
  q[chain.jointIndex("R_WRIST_Y")] = -0.3;
  return q;
}

void BM_Forward(benchmark::State& state) {
  const auto chain = armChain("chest_link");
  Eigen::VectorXd q = homePosture(chain);
  for (auto _ : state) {
    q[0] += 1e-9;
    benchmark::DoNotOptimize(chain.forward(q));
  }
  state.counters["fk/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}

void BM_ForwardAndJacobian(benchmark::State& state) {
  const auto chain = armChain("chest_link");
  Eigen::VectorXd q = homePosture(chain);
  Eigen::Isometry3d pose;
  lfd::Matrix6Xd jac(6, chain.dof());
  for (auto _ : state) {
    q[0] += 1e-9;
    chain.forwardAndJacobian(q, pose, jac);
    benchmark::DoNotOptimize(jac.data());
  }
  state.counters["jac/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}

// Warm-started tracking of a circle of radius 5 cm sampled every 2 mm (a DMP-like stream).
void trackCircle(benchmark::State& state, const char* base) {
  const auto chain = armChain(base);
  lfd::InverseKinematics ik(chain);
  Eigen::VectorXd q = homePosture(chain);
  ik.setPreferredPosture(q);
  const Eigen::Isometry3d center = chain.forward(q);
  lfd::IkResult result;
  result.q = q;
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

void BM_IkWarmStart7Dof(benchmark::State& state) {
  trackCircle(state, "chest_link");
}
void BM_IkWarmStart10DofWithWaist(benchmark::State& state) {
  trackCircle(state, "base_link");
}

// Cold solves from the preferred posture toward random-ish reachable targets (reachability query).
void BM_IkColdReach7Dof(benchmark::State& state) {
  const auto chain = armChain("chest_link");
  lfd::InverseKinematics ik(chain);
  const Eigen::VectorXd home = homePosture(chain);
  int64_t k = 0, failures = 0;
  for (auto _ : state) {
    Eigen::VectorXd q = home;
    for (int i = 0; i < q.size(); ++i) q[i] += 0.4 * std::sin(0.7 * (++k) + i);
    chain.clampToLimits(q);
    const lfd::IkResult r = ik.reach(chain.forward(q), home);
    if (!r.converged) ++failures;
  }
  state.counters["solves/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
  state.counters["failures"] = static_cast<double>(failures);
}

}  // namespace

BENCHMARK(BM_Forward);
BENCHMARK(BM_ForwardAndJacobian);
BENCHMARK(BM_IkWarmStart7Dof);
BENCHMARK(BM_IkWarmStart10DofWithWaist);
BENCHMARK(BM_IkColdReach7Dof);
BENCHMARK_MAIN();
