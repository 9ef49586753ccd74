// Demonstration bag -> feature matrix: every configured topic field becomes one named feature
// ("<topic>/<field>", e.g. /ee_twist/twist/linear/x), resampled onto one clock. Supported types:
// sensor_msgs/JointState (position|velocity|effort/<joint>), geometry_msgs/PoseStamped,
// TwistStamped, WrenchStamped, sensor_msgs/Imu and lfd_msgs/Touch (values/<name>). Sample times
// are the header stamps (the bag receive time when a stamp is zero).
#pragma once

#include <string>
#include <vector>

#include "lfd_core/time_series.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

namespace lfd_segmentation {

struct DemoFeatures {
  std::string source;         ///< bag path
  lfd::FeatureMatrix matrix;  ///< resampled features, times = bag times (s)
  std::vector<std::string> state_features;
  std::vector<std::string> sensor_features;
  std::vector<std::string> context_features;  ///< role context: in the matrix, used by neither
};

/// Raw (not resampled) streams of the configured fields of one bag. Throws std::runtime_error for
/// unreadable/truncated bags and std::invalid_argument for a missing topic or field, an unsupported
/// message type or the ground-truth topic.
std::vector<lfd::Stream> read_bag_streams(const std::string& path,
                                          const std::vector<TopicConfig>& topics,
                                          std::vector<FeatureRole>* roles = nullptr);

/// read_bag_streams + resampling at `rate` Hz (errors name the bag).
DemoFeatures read_bag_features(const std::string& path, const std::vector<TopicConfig>& topics,
                               double rate);

}  // namespace lfd_segmentation
