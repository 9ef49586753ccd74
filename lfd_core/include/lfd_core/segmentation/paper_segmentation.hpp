// Procedure "paper" (II-C, Fig. 8): `paper_candidates` candidates anywhere from the recursive,
// Kaiser-penalized combined profile, then the zone filter (eq. 1): those inside a zone are the
// changepoints. No anchoring, no consensus: the paper's procedure, kept to compare against.
#pragma once

#include "lfd_core/segmentation/segmentation_method.hpp"

namespace lfd {

class PaperSegmentation : public SegmentationMethod {
 public:
  std::string name() const override { return "paper"; }
  SegmentationPipelineResult segment(const PreparedSegmentation& prepared,
                                     const std::vector<FeatureMatrix>& demos,
                                     const SegmentationPipelineConfig& config) const override;
};

}  // namespace lfd
