// The steps of the per-demo segmentation methods (segmentation_steps.hpp).
#include "lfd_core/segmentation/segmentation_steps.hpp"

#include <stdexcept>

#include "lfd_core/util/parallel_for.hpp"

namespace lfd {

std::string demoLabel(std::size_t d) {
  return "demonstration " + std::to_string(d);
}

namespace {

DemoSettings settingsFor(const FeatureMatrix& demo, const SegmentationPipelineConfig& config) {
  if (!config.seconds) return {config, 0.0};
  const double rate = sampleRateOf(demo);
  return {inSamples(config, rate), rate};
}

}  // namespace

std::vector<DemoSettings> demoSettings(const std::vector<FeatureMatrix>& demos,
                                       const SegmentationPipelineConfig& config) {
  std::vector<DemoSettings> settings;
  for (std::size_t d = 0; d < demos.size(); ++d) {
    try {
      settings.push_back(settingsFor(demos[d], config));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demoLabel(d) + ": " + e.what());
    }
    const std::size_t min_s = settings.back().config.segmentation.min_segment_length;
    if (min_s > 0 && static_cast<std::size_t>(demos[d].rows()) < 2 * min_s) {
      throw std::invalid_argument(demoLabel(d) + " has " + std::to_string(demos[d].rows()) +
                                  " samples, fewer than 2 * min_s = " + std::to_string(2 * min_s));
    }
  }
  return settings;
}

void forEachDemo(std::size_t count, int threads, const std::function<void(std::size_t)>& job) {
  parallelFor(count, threads, [&](std::size_t d) {
    try {
      job(d);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demoLabel(d) + ": " + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error(demoLabel(d) + ": " + e.what());
    }
  });
}

PerDemoRun beginPerDemoRun(const PreparedSegmentation& prepared,
                           const std::vector<FeatureMatrix>& demos,
                           const SegmentationPipelineConfig& config) {
  PerDemoRun run;
  run.start = std::chrono::steady_clock::now();
  run.result = prepared.base;
  const std::vector<std::string>& sensors = run.result.sensor_features;
  run.settings = demoSettings(demos, config);
  run.validate = config.validate_with_sensors && !sensors.empty();
  if (!run.validate) {
    run.result.warnings.push_back(
        sensors.empty() ? "no sensor features: ClaSP changepoints are not validated"
                        : "sensor validation disabled: ClaSP changepoints are accepted");
  }
  run.sensor_groups = sensorChannelGroups(sensors);
  run.result.demos.resize(demos.size());
  return run;
}

SegmentationPipelineResult finishPerDemoRun(const std::vector<FeatureMatrix>& demos,
                                            PerDemoRun* run) {
  run->result.segmentation_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run->start).count();
  addSensorWarnings(demos, run->validate, &run->result);
  return std::move(run->result);
}

std::vector<Interval> DemoEvidence::zones(std::size_t min_s) const {
  return confidenceZones(zone_events, min_s, num_samples);
}

DemoEvidence detectDemoEvidence(const FeatureMatrix& demo, const DemoSettings& settings,
                                const PerDemoRun& run) {
  DemoEvidence evidence;
  evidence.num_samples = static_cast<std::size_t>(demo.rows());
  if (!run.validate) return evidence;
  const SensoryEventConfig& config = settings.config.events;
  evidence.events =
      detectSensorEvents(demo.select(run.result.sensor_features).data, config, run.sensor_groups);
  evidence.zone_events =
      config.zones_from_rest_edges ? evidence.events.zone_events : evidence.events.all;
  return evidence;
}

MultivariateSegmentationConfig claspSettings(const DemoSettings& settings,
                                             const SegmentationPipelineResult& prepared) {
  MultivariateSegmentationConfig clasp = settings.config.segmentation;
  if (settings.config.window_size > 0)
    clasp.window_sizes.assign(prepared.selected_features.size(), settings.config.window_size);
  return clasp;
}

DemoSegmentationResult runDemoClasp(const FeatureMatrix& demo, const DemoSettings& settings,
                                    const SegmentationPipelineResult& prepared,
                                    const MultivariateSegmentationConfig& clasp) {
  DemoSegmentationResult out;
  out.num_samples = static_cast<std::size_t>(demo.rows());
  out.sample_rate = settings.rate;
  out.clasp = segmentMultivariate(demo.select(prepared.selected_features).data,
                                  prepared.feature_weights, clasp);
  out.min_segment_length = out.clasp.min_segment_length;
  return out;
}

void validateChangepoints(const DemoEvidence& evidence, bool validate,
                          DemoSegmentationResult* out) {
  if (!validate) {
    out->changepoints = out->clasp.changepoints;
    return;
  }
  // The zones at ClaSP's own min_s: the one it kept the changepoints apart with.
  const ChangepointValidation v =
      validateWithZones(out->clasp.changepoints, evidence.zones(out->min_segment_length));
  out->changepoints = v.accepted;
  out->rejected = v.rejected;
  out->zones = v.zones;
  out->events = evidence.events.all;
  out->event_details = evidence.events.details;
}

void addChangepointTimes(const FeatureMatrix& demo, DemoSegmentationResult* out) {
  for (std::size_t cp : out->changepoints) out->changepoint_times.push_back(demo.timeAt(cp));
  for (std::size_t cp : out->rejected) out->rejected_times.push_back(demo.timeAt(cp));
}

}  // namespace lfd
