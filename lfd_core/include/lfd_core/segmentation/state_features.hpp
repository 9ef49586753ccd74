// Which state features of a task move, and how the joint segmentation scales them: a joint angle,
// a position and a quaternion component have no common unit, so each is divided by its range
// over the task.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lfd_core/segmentation/time_series.hpp"

namespace lfd {

/// The state features (of `states`) that change at all in at least one demo.
std::vector<std::string> movingStates(const std::vector<FeatureMatrix>& demos,
                                      const std::vector<std::string>& states);

/// The features of `moving` that are in `selected` (II-B's selection), in `moving`'s order.
std::vector<std::string> selectedStates(const std::vector<std::string>& moving,
                                        const std::vector<std::string>& selected);

/// The features (of `names`) whose range in some demo is at least `min_range_sigmas` times their
/// measurement noise there (robust_statistics.hpp: measurementNoiseSigma). A quaternion component
/// that only jitters passes movingStates; scaled to its range, its noise would be as large as a
/// real motion.
std::vector<std::string> featuresAboveNoise(const std::vector<FeatureMatrix>& demos,
                                            const std::vector<std::string>& names,
                                            double min_range_sigmas);

/// Each demo's `names` columns, each feature minus its demo's minimum and divided by its largest
/// range over the task, so that DTW and the speed weigh a joint angle and a position alike.
std::vector<Eigen::MatrixXd> scaledStates(const std::vector<FeatureMatrix>& demos,
                                          const std::vector<std::string>& names);

}  // namespace lfd
