// The plug-in point of II-C: every way of segmenting prepared demonstrations is one
// SegmentationMethod, chosen by name from the configuration (SegmentationPipelineConfig::procedure,
// the `procedure` parameter). A new method is one class and one line in the registry
// (segmentation_method.cpp); the pipeline (segmentPrepared) only looks it up and calls it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd {

class SegmentationMethod {
 public:
  virtual ~SegmentationMethod();
  /// The name the configuration chooses it by ("zone_search", "paper", "joint").
  virtual std::string name() const = 0;
  /// II-C on prepared demos (segmentPrepared's contract: `demos` are the prepared ones).
  virtual SegmentationPipelineResult segment(const PreparedSegmentation& prepared,
                                             const std::vector<FeatureMatrix>& demos,
                                             const SegmentationPipelineConfig& config) const = 0;
};

/// Every registered method's name, in registration order.
std::vector<std::string> segmentationMethodNames();

/// The method of that name; throws std::invalid_argument naming the known ones otherwise.
std::unique_ptr<SegmentationMethod> makeSegmentationMethod(const std::string& name);

}  // namespace lfd
