// ClaSP speed on one thread: the profile (self-join k-NN + classification score profile) against
// series length, the k-NN alone, and a full segmentation (window selection + recursion), plus the
// multivariate segmentation of a 6-feature demonstration.
//   bench_clasp [--benchmark_filter=Profile]
// Target: the profile of a 20,000-sample series in <= 1 s.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "lfd_core/segmentation/clasp.hpp"
#include "lfd_core/segmentation/multivariate_segmentation.hpp"

namespace {

constexpr std::size_t kWindow = 50;

// Three regimes (sine, square, noisier sine of another period) so the profile has real structure.
Eigen::VectorXd regimes(std::size_t n, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1);
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  for (std::size_t t = 0; t < n; ++t) {
    const double phase = 2.0 * M_PI * static_cast<double>(t);
    double v;
    if (t < n / 3) {
      v = std::sin(phase / 60.0);
    } else if (t < 2 * n / 3) {
      v = std::sin(phase / 90.0) >= 0 ? 1.0 : -1.0;
    } else {
      v = std::sin(phase / 40.0) + 2.0 * noise(rng);
    }
    x[static_cast<Eigen::Index>(t)] = v + noise(rng);
  }
  return x;
}

void BM_ClaspProfile(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Eigen::VectorXd x = regimes(n);
  lfd::ClaspConfig config;
  config.window_size = kWindow;
  for (auto _ : state) {
    lfd::ClaspProfile p = lfd::computeClaspProfile(x, config);
    benchmark::DoNotOptimize(p.profile.data());
  }
  const double m = static_cast<double>(n - kWindow + 1);
  state.counters["pairs/s"] =
      benchmark::Counter(m * m / 2.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ClaspProfile)
    ->Arg(1000)
    ->Arg(5000)
    ->Arg(10000)
    ->Arg(20000)
    ->Arg(50000)
    ->Unit(benchmark::kMillisecond);

void BM_SelfJoinKnn(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Eigen::VectorXd x = regimes(n);
  for (auto _ : state) {
    lfd::KnnResult knn = lfd::selfJoinKnn(x, kWindow, 3, kWindow / 2);
    benchmark::DoNotOptimize(knn.indices.data());
  }
}
BENCHMARK(BM_SelfJoinKnn)->Arg(20000)->Unit(benchmark::kMillisecond);

void BM_ScoreProfileOnly(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const lfd::KnnResult knn = lfd::selfJoinKnn(regimes(n), kWindow, 3, kWindow / 2);
  for (auto _ : state) {
    Eigen::VectorXd p = lfd::classificationScoreProfile(knn, 5 * kWindow);
    benchmark::DoNotOptimize(p.data());
  }
}
BENCHMARK(BM_ScoreProfileOnly)->Arg(20000)->Unit(benchmark::kMillisecond);

// Full parameter-free segmentation: SuSS window, recursion, significance test.
void BM_ClaspSegmentation(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Eigen::VectorXd x = regimes(n);
  std::size_t found = 0;
  for (auto _ : state) {
    lfd::ClaspSegmentation s = lfd::claspSegment(x, lfd::ClaspConfig{});
    found = s.changepoints.size();
    benchmark::DoNotOptimize(s.first_profile.data());
  }
  state.counters["changepoints"] = static_cast<double>(found);
}
BENCHMARK(BM_ClaspSegmentation)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond);

// One demonstration of 6 selected features (2,000 samples), weighted product + Kaiser.
void BM_MultivariateSegmentation(benchmark::State& state) {
  const std::size_t n = 2000;
  Eigen::MatrixXd features(static_cast<Eigen::Index>(n), 6);
  for (Eigen::Index f = 0; f < 6; ++f) features.col(f) = regimes(n, 11 + static_cast<unsigned>(f));
  const std::vector<double> weights{1.0, 0.9, 0.8, 0.5, 0.3, 0.2};
  lfd::MultivariateSegmentationConfig config;
  for (auto _ : state) {
    lfd::MultivariateSegmentation s = lfd::segmentMultivariate(features, weights, config);
    benchmark::DoNotOptimize(s.changepoints.data());
  }
}
BENCHMARK(BM_MultivariateSegmentation)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
