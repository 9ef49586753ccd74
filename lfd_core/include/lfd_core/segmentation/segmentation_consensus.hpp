// Demonstrations of one task hold the same skills (SegmentationPipelineConfig::consensus_count).
// The count of validated changepoints the demos agree on is the most common one, held by at least
// 3 voting demos and by more demos than any other count (a count of 0 is no agreement: the
// changepoints the other demos found each stand on a sensory event of their own). With sensor
// validation only demos with a sensory event vote: a demo without one had no zone, so its 0 says
// nothing about the task. A demo with more changepoints keeps its most significant ones (a
// teleoperator's hesitation mid-skill is not a skill boundary); one with fewer takes ClaSP's best
// in-zone candidates that reach `fill_p_value` (the other demos' agreement is evidence too).
#pragma once

#include <vector>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd {

/// Applies the agreement to `result` (changepoints, pruned, added, their times, a warning per demo
/// changed). fill_p_value 0 = never add; without validation, or without a sensory event of its
/// own, a demo is never filled (it has no zone).
void agreeOnChangepointCount(const std::vector<FeatureMatrix>& demos, bool validated,
                             double fill_p_value, SegmentationPipelineResult* result);

}  // namespace lfd
