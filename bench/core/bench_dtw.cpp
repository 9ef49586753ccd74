// DTW throughput (G cells/s) on the feature-relevance workload of paper II-B: every pair of 9
// demonstrations x 30 features, ~2000 samples per demonstration (lengths differ per demo).
//   bench_dtw [--benchmark_filter=...]
// "Gcells/s" counts n*m cells of every aligned pair per second of wall time.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "lfd_core/segmentation/dtw.hpp"

namespace {

constexpr int kDemos = 9;
constexpr int kFeatures = 30;

struct Workload {
  std::vector<std::vector<std::vector<double>>> series;  // [demo][feature] -> samples
  std::vector<lfd::DtwPairView> pairs;
  double cells = 0;
};

const Workload& relevanceWorkload() {
  static const Workload kW = [] {
    Workload w;
    std::mt19937 rng(42);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::uniform_real_distribution<double> phase(0.0, 1.0);
    for (int d = 0; d < kDemos; ++d) {
      const std::size_t n = 1800 + 50 * d;  // 1800 .. 2200 samples
      w.series.emplace_back();
      for (int f = 0; f < kFeatures; ++f) {
        std::vector<double> x(n);
        const double p = phase(rng);
        for (std::size_t i = 0; i < n; ++i) {
          const double t = double(i) / n;
          x[i] = 0.5 + 0.5 * std::sin(6.283 * (t * (1 + f % 3) + p)) + noise(rng);
        }
        w.series[d].push_back(std::move(x));
      }
    }
    for (int f = 0; f < kFeatures; ++f) {
      for (int i = 0; i < kDemos; ++i) {
        for (int j = i + 1; j < kDemos; ++j) {
          const auto& a = w.series[i][f];
          const auto& b = w.series[j][f];
          w.pairs.push_back({a.data(), a.size(), b.data(), b.size()});
          w.cells += double(a.size()) * double(b.size());
        }
      }
    }
    return w;
  }();
  return kW;
}

void setRate(benchmark::State& state, double cells_per_iteration) {
  state.counters["Gcells/s"] = benchmark::Counter(cells_per_iteration * 1e-9 * state.iterations(),
                                                  benchmark::Counter::kIsRate);
}

void BM_ScalarPairCost(benchmark::State& state) {
  const auto& p = relevanceWorkload().pairs.front();
  for (auto _ : state) benchmark::DoNotOptimize(lfd::dtwCost(p.a, p.n, p.b, p.m));
  setRate(state, double(p.n) * p.m);
}

void BM_ScalarPairPath(benchmark::State& state) {
  const auto& p = relevanceWorkload().pairs.front();
  for (auto _ : state) benchmark::DoNotOptimize(lfd::dtw(p.a, p.n, p.b, p.m).cost);
  setRate(state, double(p.n) * p.m);
}

void BM_BatchCostRelevance(benchmark::State& state) {
  const Workload& w = relevanceWorkload();
  for (auto _ : state) benchmark::DoNotOptimize(lfd::dtwCostBatch(w.pairs, {}, state.range(0)));
  setRate(state, w.cells);
}

void BM_BatchPathsRelevance(benchmark::State& state) {
  const Workload& w = relevanceWorkload();
  for (auto _ : state) benchmark::DoNotOptimize(lfd::dtwBatch(w.pairs, {}, state.range(0)));
  setRate(state, w.cells);
}

void BM_BatchPathsRelevanceBand(benchmark::State& state) {
  const Workload& w = relevanceWorkload();
  for (auto _ : state) {
    benchmark::DoNotOptimize(lfd::dtwBatch(w.pairs, {int(state.range(1))}, state.range(0)));
  }
  setRate(state, w.cells);  // full-matrix cells, for comparison with the unbanded run
}

}  // namespace

BENCHMARK(BM_ScalarPairCost)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ScalarPairPath)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BatchCostRelevance)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BatchPathsRelevance)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BatchPathsRelevanceBand)->Args({1, 200})->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
