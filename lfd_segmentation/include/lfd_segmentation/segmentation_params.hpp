// Parameters of the segmentation service and CLI (config/segmentation.yaml): which topics and
// fields become features, their roles, the resampling rate and the pipeline settings.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "lfd_core/segmentation_pipeline.hpp"
#include "lfd_core/time_series.hpp"

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
};

struct SegmentationParams {
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
  lfd::SegmentationPipelineConfig pipeline_config() const;
};

/// Parses the YAML layout of config/segmentation.yaml; missing keys keep the defaults. Throws
/// std::invalid_argument with the offending key on bad values (and for the ground-truth topic).
SegmentationParams params_from_yaml(const YAML::Node& root);
SegmentationParams load_params_file(const std::string& path);

/// The topic that must never be read by the segmenter (ground truth for evaluation only).
constexpr const char* kGroundTruthTopic = "/lfd/phase";

}  // namespace lfd_segmentation
