// Parameters of the segmentation service and CLI (config/segmentation.yaml): which topics and
// fields become features, their roles, the resampling rate and the pipeline settings.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "lfd_core/io/input_budget.hpp"
#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/segmentation/segmentation_pipeline.hpp"
#include "lfd_core/segmentation/time_series.hpp"

namespace lfd_segmentation {

/// kState: candidate for feature selection and ClaSP; kSensor: builds the confidence zones only;
/// kContext: read and resampled with the others (bad data is still reported) but used by neither.
enum class FeatureRole { kState, kSensor, kContext };

/// One topic of the bags: its fields become features named "<topic>/<field>".
struct TopicConfig {
  std::string topic;
  FeatureRole role = FeatureRole::kState;
  std::vector<std::string> fields;  ///< a field ending in "/*" expands to every name
  lfd::Interpolation interpolation = lfd::Interpolation::kLinear;
  /// Its fields go into each skill's sensory signature (the executor's monitor); YAML `monitor`,
  /// default: every role but state (a gripper's opening, a state, says `monitor: true`).
  bool monitor = false;
};

/// Bounds on one request (config `limits:`): whatever a client sends, a request takes bounded
/// memory and time and is refused, naming the limit's key, when it asks for more.
struct RequestLimits {
  std::size_t max_bags = 64;                   ///< bag paths (or CSV files) per request
  std::size_t max_bag_files = 128;             ///< files after splitting demos' parts (a,b.bag)
  std::uint64_t max_total_bytes = 1000000000;  ///< size of all a request's files together
  double max_demo_seconds = 120.0;             ///< time span of one demo's stamps (s)
  std::size_t max_samples_per_demo = 12000;    ///< rows after resampling (span x rate)
  std::size_t max_total_samples = 300000;      ///< rows summed over the request's demos
  std::size_t max_csv_rows = 100000;           ///< data rows of one CSV file
  double max_abs_value = 1e100;                ///< |feature value|; squares must not overflow
  std::size_t max_features = 256;              ///< feature columns of a demo (bag fields, CSV)
  /// Bytes of any string of a request (lfd_core input_budget.hpp).
  std::size_t max_request_string_bytes = lfd::kDefaultMaxRequestStringBytes;
};

struct SegmentationParams {
  RequestLimits limits;
  /// Roots the service's bag paths must lie in (config `allowed_roots`; the CLI ignores them).
  lfd::PathPolicy paths;
  double rate = 50.0;  ///< Hz of the common clock
  std::vector<TopicConfig> topics;
  double min_segment_seconds = 0.0;  ///< 0 = automatic
  double window_seconds = 0.0;       ///< 0 = automatic
  /// The other time parameters (events, ClaSP's minimum window), in seconds; its min_segment and
  /// window are taken from the two fields above.
  lfd::TimeParameters time;
  /// Everything else. The pipeline converts the seconds with each demonstration's own rate.
  lfd::SegmentationPipelineConfig pipeline;
  /// The pipeline configuration with the seconds attached (and, for callers that work in samples
  /// of the nominal clock, the sample counts filled at `rate`).
  lfd::SegmentationPipelineConfig pipelineConfig() const;
};

/// Parses the YAML layout of config/segmentation.yaml; missing keys keep the defaults. Throws
/// std::invalid_argument with the offending key on bad values (and for the ground-truth topic).
SegmentationParams paramsFromYaml(const YAML::Node& root);
SegmentationParams loadParamsFile(const std::string& path);

/// Refuses a request-level time override that is not a finite positive number of seconds within
/// limits/max_demo_seconds (NaN, inf, 1e300). `key` names the field in the message.
void checkSecondsOverride(double value, const std::string& key, const RequestLimits& limits);

/// Refuses demos the parameters cannot segment: a window as long as the demo (the answer would be
/// "0 changepoints" for a reason that is not in the data; the pipeline refuses a minimum segment
/// over half a demo itself), and demos over the sample limits.
void checkDemosFit(const SegmentationParams& params, const std::vector<lfd::FeatureMatrix>& demos,
                   const std::vector<std::string>& sources);

/// Refuses raw streams whose stamps span more than limits/max_demo_seconds (one message stamped
/// hours late would otherwise be resampled into millions of rows) or hold |values| above
/// limits/max_abs_value. Fast: one pass, before anything is allocated.
void checkStreams(const std::vector<lfd::Stream>& streams, const std::string& source,
                  const RequestLimits& limits);

/// The topic that must never be read by the segmenter (ground truth for evaluation only).
constexpr const char* kGroundTruthTopic = "/lfd/phase";

}  // namespace lfd_segmentation
