// DMP benchmark: accuracy figures (printed first), rollout steps/s, learning time per segment.
//   bench_dmp                      # all
//   bench_dmp --benchmark_filter=Rollout
#include "dmp_test_curves.hpp"
#include "lfd_core/dmp/dmp_generalization.hpp"
#include "lfd_core/dmp/position_dmp.hpp"
#include "lfd_core/dmp/segment_dmp.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <vector>

namespace {

constexpr double kDuration = 2.0;

Eigen::VectorXd times(int samples) {
  return Eigen::VectorXd::LinSpaced(samples, 0.0, kDuration);
}

lfd::SegmentDemo poseDemo(int samples) {
  lfd::SegmentDemo demo;
  demo.times = times(samples);
  demo.positions = lfd_test::curve3d(demo.times, kDuration);
  demo.quaternions.resize(samples, 4);
  demo.gripper.resize(samples);
  for (int i = 0; i < samples; ++i) {
    const double s = demo.times[i] / kDuration;
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(1.2 * s * s * (3 - 2 * s), Eigen::Vector3d(0.3, 0.2, 1).normalized()));
    demo.quaternions.row(i) << q.w(), q.x(), q.y(), q.z();
    demo.gripper[i] = 0.08 - 0.06 * s * s * (3 - 2 * s);
  }
  return demo;
}

void printAccuracy() {
  const Eigen::VectorXd t = times(1000);
  std::printf("DMP accuracy (1000-sample demos, N = %d basis functions, rollout at demo dt):\n",
              lfd::DmpParameters().num_basis);
  for (int d : {2, 3}) {
    const Eigen::MatrixXd demo =
        d == 2 ? lfd_test::curve2d(t, kDuration) : lfd_test::curve3d(t, kDuration);
    const lfd::PositionDmp dmp = lfd::PositionDmp::learn(t, demo);
    lfd::PositionRolloutOptions o;
    o.dt = t[1] - t[0];
    const auto traj = dmp.rollout(o);
    const double ext = lfd_test::extent(demo);
    std::printf("  %d-D reproduction RMSE: %.2e m = %.5f %% of extent (%.3f m)\n", d,
                lfd_test::rmse(traj.positions, demo),
                100 * lfd_test::rmse(traj.positions, demo) / ext, ext);
    o.duration = 1.5 * kDuration;
    const auto longer = dmp.rollout(o);
    const double final_err = (longer.positions.bottomRows(1) - demo.bottomRows(1)).norm();
    std::printf("  %d-D final error after 1.5x duration: %.2e m = %.5f %% of extent\n", d,
                final_err, 100 * final_err / ext);
  }
  std::fflush(stdout);
}

void BM_PositionRollout3d(benchmark::State& state) {
  const int steps = static_cast<int>(state.range(0));
  lfd::DmpParameters p;
  p.num_basis = static_cast<int>(state.range(1));
  const Eigen::VectorXd t = times(1000);
  const lfd::PositionDmp dmp = lfd::PositionDmp::learn(t, lfd_test::curve3d(t, kDuration), p);
  std::vector<double> out(static_cast<size_t>(3 * steps));
  const Eigen::Vector3d start(0.31, -0.2, 0.8), goal(0.6, -0.05, 0.9), v0 = Eigen::Vector3d::Zero();
  const double dt = kDuration / (steps - 1);
  for (auto _ : state) {
    dmp.rolloutInto(start.data(), goal.data(), v0.data(), kDuration, dt, steps, out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * steps);
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PositionRollout3d)->Args({1000, 50})->Args({10000, 50})->Args({1000, 100});

void BM_SegmentRunnerPoseGripper(benchmark::State& state) {
  const lfd::SegmentDmp dmp = lfd::SegmentDmp::learn(poseDemo(1000));
  lfd::SegmentRolloutOptions o;
  o.dt = 0.002;
  const int steps = 1000;
  for (auto _ : state) {
    lfd::SegmentDmpRunner runner(dmp, o);
    for (int k = 0; k < steps; ++k) runner.step(o.dt);
    benchmark::DoNotOptimize(runner.position().data());
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SegmentRunnerPoseGripper)->Unit(benchmark::kMicrosecond);

void BM_LearnPosition3d(benchmark::State& state) {
  const int samples = static_cast<int>(state.range(0));
  const Eigen::VectorXd t = times(samples);
  const Eigen::MatrixXd y = lfd_test::curve3d(t, kDuration);
  for (auto _ : state) benchmark::DoNotOptimize(lfd::PositionDmp::learn(t, y).weights().data());
}
BENCHMARK(BM_LearnPosition3d)->Arg(300)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_LearnSegmentPoseGripper(benchmark::State& state) {
  const lfd::SegmentDemo demo = poseDemo(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const lfd::SegmentDmp dmp = lfd::SegmentDmp::learn(demo);
    benchmark::DoNotOptimize(dmp.position->weights().data());
  }
}
BENCHMARK(BM_LearnSegmentPoseGripper)->Arg(300)->Arg(1000)->Unit(benchmark::kMicrosecond);

// range(0) demos; range(1) = 1: the ridge chosen by leave-one-out among executor.yaml's six
// candidates (what the executor does per segment and goal), 0: the fixed ridge.
void BM_Generalize(benchmark::State& state) {
  std::vector<lfd::SegmentDmp> dmps;
  std::vector<Eigen::VectorXd> params;
  for (int j = 0; j < state.range(0); ++j) {
    lfd::SegmentDemo demo = poseDemo(500);
    demo.positions.col(0) *= 1.0 + 0.1 * j;
    demo.positions.col(1).array() += 0.05 * (j % 2);
    dmps.push_back(lfd::SegmentDmp::learn(demo));
    params.push_back(lfd::goalParameters(dmps.back()));
  }
  lfd::GeneralizationOptions options;
  if (state.range(1)) options.slope_ridge_candidates = {1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0};
  const Eigen::VectorXd query = 0.5 * (params[1] + params[2]);
  for (auto _ : state) {
    const auto res = lfd::generalizeSegment(dmps, params, query, options);
    benchmark::DoNotOptimize(res.coefficients.data());
  }
}
BENCHMARK(BM_Generalize)->Args({5, 0})->Args({5, 1})->Args({9, 1})->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  printAccuracy();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
