// Joint segmentation of the demonstrations of one task (procedure "joint"): one phase sequence
// for the whole set. Every demo's boundary evidence of every kind (boundary_evidence.hpp: contact,
// sensor level steps, motion after a pause, ClaSP) is carried onto one reference demo's time axis
// by multivariate DTW (demo_alignment.hpp); where the demos' combined evidence agrees, the task
// has a boundary. Each demo's boundary is then placed on its own strongest evidence near the
// agreed one. Where a demo's contact sensor was blind (dead, or repeating a cached reading:
// stale_readings.hpp), a boundary its siblings felt goes where its motion around it matches
// theirs (motion_match.hpp); a demo with no evidence near an agreed boundary is reported as
// lacking it, not forced.
#pragma once

#include <vector>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd {

/// Segments prepared demos jointly (the pipeline's kJoint). Needs clocks (config.seconds set);
/// throws std::invalid_argument otherwise or on the pipeline's own input errors.
SegmentationPipelineResult segmentJointly(const PreparedSegmentation& prepared,
                                          const std::vector<FeatureMatrix>& demos,
                                          const SegmentationPipelineConfig& config);

}  // namespace lfd
