// Reads a demonstration bag (written by the recorder) into a DemoRecording: the end-effector pose
// topic gives the time base (header stamps) and the Cartesian frame (header frame_id), the gripper
// opening is interpolated onto it, and the scene of the metadata (demo_scene.hpp) is brought into
// the Cartesian frame with the bag's static transforms.
#pragma once

#include "lfd_dmp/skill_learner.hpp"

#include <Eigen/Geometry>

#include <functional>
#include <string>

namespace lfd_dmp {

struct DemoBagTopics {
  std::string pose = "/ee_pose";           ///< geometry_msgs/PoseStamped (base_link)
  std::string gripper = "/gripper/state";  ///< sensor_msgs/JointState
  /// Joint whose position is the opening; "" = the message's first joint (a gripper state
  /// names its gripper alone, whatever the robot calls it).
  std::string gripper_joint;
  std::string metadata = "/lfd/metadata";  ///< lfd_msgs/DemoMetadata (extra_json: the scene)
  std::string tf_static = "/tf_static";    ///< tf2_msgs/TFMessage
};

/// The pose of frame `source` in frame `target` from elsewhere than the bag (the live tf tree);
/// throws std::runtime_error when it has none.
using TransformLookup =
    std::function<Eigen::Isometry3d(const std::string& target, const std::string& source)>;

/// Throws std::runtime_error naming the bag and topic on missing/unusable data. Poses and gripper
/// states are put in stamp order by the shared policy (lfd_core/io/stamp_order.hpp: the first of a
/// duplicated stamp kept), and what it found is in the recording's `warnings`; NaN poses are an
/// error. The scene is brought
/// into the poses' frame with the bag's /tf_static, else with `fallback` (bags recorded before
/// /tf_static was); neither connecting the frames is an error, no scene is not.
DemoRecording readDemoBag(const std::string& path, const DemoBagTopics& topics = {},
                          const TransformLookup& fallback = nullptr);

}  // namespace lfd_dmp
