// The steps of the per-demo methods (zone_search, paper), in the order they run:
//   beginPerDemoRun        the prepared result, each demo's sample-count settings
//   per demo:  detectDemoEvidence   sensory events and their eq. (1) zones
//              claspSettings + the method's own search setup
//              runDemoClasp         multivariate ClaSP (multivariate_segmentation.hpp)
//              validateChangepoints  the zone filter (eq. 1)
//              addChangepointTimes
//   agreeOnChangepointCount        the consensus (segmentation_consensus.hpp), zone_search only
//   finishPerDemoRun               timing, sensor warnings
// Each method calls them in sequence, so what differs between methods is visible in its own file.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd {

/// "demonstration d", the prefix of every per-demo error and warning.
std::string demoLabel(std::size_t d);

/// The sample-count settings of one demonstration: the config's own counts, or its seconds
/// converted at the demonstration's rate (0 = index-only series).
struct DemoSettings {
  SegmentationPipelineConfig config;
  double rate = 0.0;
};

/// Every demo's settings; checks its clock and that it holds 2 min_s (std::invalid_argument with
/// the demonstration named).
std::vector<DemoSettings> demoSettings(const std::vector<FeatureMatrix>& demos,
                                       const SegmentationPipelineConfig& config);

/// Runs job(d) for every demonstration (parallel_for); rethrows the first failure (by
/// demonstration index) with the demonstration named.
void forEachDemo(std::size_t count, int threads, const std::function<void(std::size_t)>& job);

/// What every demo of a per-demo method shares.
struct PerDemoRun {
  SegmentationPipelineResult result;  ///< the prepared result; `demos` sized, to be filled
  std::vector<DemoSettings> settings;
  std::vector<std::size_t> sensor_groups;  ///< sensorChannelGroups of the sensor features
  bool validate = false;                   ///< sensors validate ClaSP's changepoints
  std::chrono::steady_clock::time_point start;
};

/// Settings, the validation switch and its warning (no sensors or validation disabled).
PerDemoRun beginPerDemoRun(const PreparedSegmentation& prepared,
                           const std::vector<FeatureMatrix>& demos,
                           const SegmentationPipelineConfig& config);

/// The segmentation time and the sensor warnings; returns the result.
SegmentationPipelineResult finishPerDemoRun(const std::vector<FeatureMatrix>& demos,
                                            PerDemoRun* run);

/// One demo's sensory evidence: its events and the events its confidence zones surround.
struct DemoEvidence {
  SensorEvents events;                   ///< empty without validation
  std::vector<std::size_t> zone_events;  ///< rest edges or every event (zones_from_rest_edges)
  std::size_t num_samples = 0;
  /// The eq. (1) zones for min_s (they widen with it, so ClaSP's min_s must be known).
  std::vector<Interval> zones(std::size_t min_s) const;
};

/// Detects the demo's sensory events (once: they do not depend on min_s); none without validation.
DemoEvidence detectDemoEvidence(const FeatureMatrix& demo, const DemoSettings& settings,
                                const PerDemoRun& run);

/// ClaSP's settings for one demo before the method's own search setup (the fixed window, if any,
/// for every selected feature).
MultivariateSegmentationConfig claspSettings(const DemoSettings& settings,
                                             const SegmentationPipelineResult& prepared);

/// Multivariate ClaSP on the demo's selected features; fills clasp, min_segment_length,
/// num_samples and sample_rate, not the changepoints.
DemoSegmentationResult runDemoClasp(const FeatureMatrix& demo, const DemoSettings& settings,
                                    const SegmentationPipelineResult& prepared,
                                    const MultivariateSegmentationConfig& clasp);

/// The zone filter (eq. 1): ClaSP's changepoints inside a zone are the changepoints, the others
/// are rejected; records the zones and events. Without validation every changepoint is kept.
void validateChangepoints(const DemoEvidence& evidence, bool validate, DemoSegmentationResult* out);

/// The times of the changepoints and of the rejected ones.
void addChangepointTimes(const FeatureMatrix& demo, DemoSegmentationResult* out);

}  // namespace lfd
