// The segmentation stage on the service's workload: 9 grasp-like demonstrations of 12 s at 50 Hz,
// 14 state and 8 sensor features (make_synthetic_demos.py's layout), with the seconds of
// config/segmentation.yaml. The whole pipeline, its II-B part alone, II-C per combination on one
// shared selection, and the sensory events with fitted placement.
//   bench_segmentation [--benchmark_filter=Pipeline]
// Target: the service's 9 demos in <= 1.5 s, bag reading included (about 0.1-0.2 s of it).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace {

constexpr int kStates = 14, kSensors = 8;

lfd::FeatureMatrix demo(int n, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  lfd::FeatureMatrix m;
  for (int f = 0; f < kStates; ++f) m.names.push_back("/state/" + std::to_string(f));
  for (int f = 0; f < kSensors; ++f) m.names.push_back("/sensor/" + std::to_string(f));
  m.data.resize(n, kStates + kSensors);
  const int grasp = static_cast<int>(n * (0.4 + 0.05 * g(rng) / 3.0));
  for (int i = 0; i < n; ++i) {
    m.time.push_back(0.02 * i);
    const bool closed = i >= grasp;
    const double u = static_cast<double>(i) / n;
    for (int f = 0; f < kStates; ++f)
      m.data(i, f) = std::sin(M_PI * (closed ? u - 0.4 : u) * (1 + f % 3)) * (closed ? 0.2 : 0.3) +
                     (f == 0 ? (closed ? 0.02 : 0.08) : 0.0) + 0.003 * g(rng);
    for (int f = 0; f < kSensors; ++f)
      m.data(i, kStates + f) = (closed ? 4.0 - 0.3 * f : 0.0) + 0.05 * g(rng);
  }
  return m;
}

std::vector<lfd::FeatureMatrix> demos() {
  std::mt19937 rng(3);
  std::vector<lfd::FeatureMatrix> out;
  for (int d = 0; d < 9; ++d) out.push_back(demo(600 + 10 * d, rng));
  return out;
}

std::vector<std::string> sensors() {
  std::vector<std::string> out;
  for (int f = 0; f < kSensors; ++f) out.push_back("/sensor/" + std::to_string(f));
  return out;
}

// The YAML's event settings (seconds are converted per demo).
lfd::SegmentationPipelineConfig yamlConfig() {
  lfd::SegmentationPipelineConfig c;
  c.seconds = lfd::TimeParameters{};
  c.events.noise_floor_sigmas = 0.0;
  c.events.noise_floor_excursions = 5.0;
  c.events.placement = lfd::EventPlacement::kFit;
  c.events.zones_from_rest_edges = true;
  c.segmentation.zone_p_value_threshold = 1e-5;
  c.segmentation.rest_edge_p_value_threshold = 1e-2;
  c.threads = static_cast<int>(benchmark::CPUInfo::Get().num_cpus);
  return c;
}

void BM_Pipeline(benchmark::State& state) {
  const auto d = demos();
  const auto config = yamlConfig();
  for (auto _ : state) benchmark::DoNotOptimize(lfd::runSegmentationPipeline(d, sensors(), config));
}
BENCHMARK(BM_Pipeline)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PrepareOnly(benchmark::State& state) {
  const auto d = demos();
  const auto config = yamlConfig();
  for (auto _ : state) benchmark::DoNotOptimize(lfd::prepareSegmentation(d, sensors(), config));
}
BENCHMARK(BM_PrepareOnly)->Unit(benchmark::kMillisecond)->UseRealTime();

// II-C alone, per combination: what each further method costs once the selection is shared.
void BM_SegmentPrepared(benchmark::State& state) {
  const auto d = demos();
  auto config = yamlConfig();
  const lfd::PreparedSegmentation prepared = lfd::prepareSegmentation(d, sensors(), config);
  config.segmentation.combination = static_cast<lfd::ProfileCombination>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(lfd::segmentPrepared(prepared, d, config));
  state.SetLabel(lfd::toString(config.segmentation.combination));
}
BENCHMARK(BM_SegmentPrepared)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SensorEventsFitted(benchmark::State& state) {
  const auto d = demos();
  const auto config = lfd::inSamples(yamlConfig(), 50.0);
  const Eigen::MatrixXd s = d[0].select(sensors()).data;
  const std::vector<std::size_t> groups(kSensors, 0);
  for (auto _ : state) benchmark::DoNotOptimize(lfd::detectSensorEvents(s, config.events, groups));
}
BENCHMARK(BM_SensorEventsFitted)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
