// Procedure "zone_search" (ours): the sensory zones first; each ClaSP recursion step takes its
// argmax inside them, the changepoint sits on a sensory event of its zone (anchor_to_events), the
// zone filter keeps the in-zone ones, and the demos agree on their count (consensus_count).
#pragma once

#include "lfd_core/segmentation/segmentation_method.hpp"

namespace lfd {

class ZoneSearchSegmentation : public SegmentationMethod {
 public:
  std::string name() const override { return "zone_search"; }
  SegmentationPipelineResult segment(const PreparedSegmentation& prepared,
                                     const std::vector<FeatureMatrix>& demos,
                                     const SegmentationPipelineConfig& config) const override;
};

}  // namespace lfd
