// Reads a demonstration bag (written by the recorder) into a DemoRecording: the end-effector pose
// topic gives the time base (header stamps), the gripper opening is interpolated onto it.
#pragma once

#include "lfd_dmp/skill_learner.hpp"

#include <string>

namespace lfd_dmp {

struct DemoBagTopics {
  std::string pose = "/ee_pose";               ///< geometry_msgs/PoseStamped (base_link)
  std::string gripper = "/gripper/state";      ///< sensor_msgs/JointState
  std::string gripper_joint = "R_GRIPPER";     ///< joint whose position is the opening
};

/// Throws std::runtime_error naming the bag and topic on missing/unusable data. Poses with
/// non-increasing stamps are dropped (duplicates), NaN poses are an error.
DemoRecording readDemoBag(const std::string& path, const DemoBagTopics& topics = {});

}  // namespace lfd_dmp
