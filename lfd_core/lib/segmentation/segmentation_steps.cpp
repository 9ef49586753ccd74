// The steps of the per-demo segmentation methods (segmentation_steps.hpp).
#include "lfd_core/segmentation/segmentation_steps.hpp"

#include <stdexcept>

#include "lfd_core/util/parallel_for.hpp"

namespace lfd {

std::string demo_label(std::size_t d) {
  return "demonstration " + std::to_string(d);
}

namespace {

DemoSettings settings_for(const FeatureMatrix& demo, const SegmentationPipelineConfig& config) {
  if (!config.seconds) return {config, 0.0};
  const double rate = sample_rate_of(demo);
  return {in_samples(config, rate), rate};
}

}  // namespace

std::vector<DemoSettings> demo_settings(const std::vector<FeatureMatrix>& demos,
                                        const SegmentationPipelineConfig& config) {
  std::vector<DemoSettings> settings;
  for (std::size_t d = 0; d < demos.size(); ++d) {
    try {
      settings.push_back(settings_for(demos[d], config));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demo_label(d) + ": " + e.what());
    }
    const std::size_t min_s = settings.back().config.segmentation.min_segment_length;
    if (min_s > 0 && static_cast<std::size_t>(demos[d].rows()) < 2 * min_s) {
      throw std::invalid_argument(demo_label(d) + " has " + std::to_string(demos[d].rows()) +
                                  " samples, fewer than 2 * min_s = " + std::to_string(2 * min_s));
    }
  }
  return settings;
}

void for_each_demo(std::size_t count, int threads, const std::function<void(std::size_t)>& job) {
  parallel_for(count, threads, [&](std::size_t d) {
    try {
      job(d);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demo_label(d) + ": " + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error(demo_label(d) + ": " + e.what());
    }
  });
}

PerDemoRun begin_per_demo_run(const PreparedSegmentation& prepared,
                              const std::vector<FeatureMatrix>& demos,
                              const SegmentationPipelineConfig& config) {
  PerDemoRun run;
  run.start = std::chrono::steady_clock::now();
  run.result = prepared.base;
  const std::vector<std::string>& sensors = run.result.sensor_features;
  run.settings = demo_settings(demos, config);
  run.validate = config.validate_with_sensors && !sensors.empty();
  if (!run.validate) {
    run.result.warnings.push_back(
        sensors.empty() ? "no sensor features: ClaSP changepoints are not validated"
                        : "sensor validation disabled: ClaSP changepoints are accepted");
  }
  run.sensor_groups = sensor_channel_groups(sensors);
  run.result.demos.resize(demos.size());
  return run;
}

SegmentationPipelineResult finish_per_demo_run(const std::vector<FeatureMatrix>& demos,
                                               PerDemoRun* run) {
  run->result.segmentation_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run->start).count();
  add_sensor_warnings(demos, run->validate, &run->result);
  return std::move(run->result);
}

std::vector<Interval> DemoEvidence::zones(std::size_t min_s) const {
  return confidence_zones(zone_events, min_s, num_samples);
}

DemoEvidence detect_demo_evidence(const FeatureMatrix& demo, const DemoSettings& settings,
                                  const PerDemoRun& run) {
  DemoEvidence evidence;
  evidence.num_samples = static_cast<std::size_t>(demo.rows());
  if (!run.validate) return evidence;
  const SensoryEventConfig& config = settings.config.events;
  evidence.events =
      detect_sensor_events(demo.select(run.result.sensor_features).data, config, run.sensor_groups);
  evidence.zone_events =
      config.zones_from_rest_edges ? evidence.events.zone_events : evidence.events.all;
  return evidence;
}

MultivariateSegmentationConfig clasp_settings(const DemoSettings& settings,
                                              const SegmentationPipelineResult& prepared) {
  MultivariateSegmentationConfig clasp = settings.config.segmentation;
  if (settings.config.window_size > 0)
    clasp.window_sizes.assign(prepared.selected_features.size(), settings.config.window_size);
  return clasp;
}

DemoSegmentationResult run_demo_clasp(const FeatureMatrix& demo, const DemoSettings& settings,
                                      const SegmentationPipelineResult& prepared,
                                      const MultivariateSegmentationConfig& clasp) {
  DemoSegmentationResult out;
  out.num_samples = static_cast<std::size_t>(demo.rows());
  out.sample_rate = settings.rate;
  out.clasp = segment_multivariate(demo.select(prepared.selected_features).data,
                                   prepared.feature_weights, clasp);
  out.min_segment_length = out.clasp.min_segment_length;
  return out;
}

void validate_changepoints(const DemoEvidence& evidence, bool validate,
                           DemoSegmentationResult* out) {
  if (!validate) {
    out->changepoints = out->clasp.changepoints;
    return;
  }
  // The zones at ClaSP's own min_s: the one it kept the changepoints apart with.
  const ChangepointValidation v =
      validate_with_zones(out->clasp.changepoints, evidence.zones(out->min_segment_length));
  out->changepoints = v.accepted;
  out->rejected = v.rejected;
  out->zones = v.zones;
  out->events = evidence.events.all;
  out->event_details = evidence.events.details;
}

void add_changepoint_times(const FeatureMatrix& demo, DemoSegmentationResult* out) {
  for (std::size_t cp : out->changepoints) out->changepoint_times.push_back(demo.time_at(cp));
  for (std::size_t cp : out->rejected) out->rejected_times.push_back(demo.time_at(cp));
}

}  // namespace lfd
