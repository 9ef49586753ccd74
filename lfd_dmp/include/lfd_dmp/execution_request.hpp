// Checks of an execution request (ROS-free): every number against its physical meaning, every
// limit stated in config (config/executor.yaml `limits:`) and named in its refusal.
#pragma once

#include <lfd_core/kinematics/pose.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace lfd_dmp {

struct RequestLimits {
  double min_duration_scale = 0.1;  ///< below: the arm could not follow (1e-9 "succeeded" unmoved)
  double max_duration_scale = 10.0;
  double max_plan_seconds = 200.0;  ///< s of planned motion (samples, IK and memory grow with it)
  double quaternion_tolerance = 0.01;  ///< |norm - 1| normalized; refused beyond
  /// Where a scene pose may be, in the library's Cartesian frame (m).
  Eigen::Vector3d workspace_min = Eigen::Vector3d::Constant(-2.0);
  Eigen::Vector3d workspace_max = Eigen::Vector3d::Constant(2.0);
  size_t max_objects = 32;
  size_t max_name_length = 256;  ///< object names, frame ids, the library path
};

/// Throws std::invalid_argument (naming the limit key) for a bad limit set.
void checkLimits(const RequestLimits& limits);

/// The duration scale of a request: 0 means 1; otherwise finite and inside the limits.
double checkedDurationScale(double scale, const RequestLimits& limits);

/// A pose of a request: finite, its quaternion (w, x, y, z) normalized when within the tolerance
/// of unit length and refused beyond (a zero quaternion is no orientation). `what` names it.
lfd::Pose checkedPose(const Eigen::Vector3d& position, const Eigen::Vector4d& wxyz,
                      const std::string& what, const RequestLimits& limits);

/// Refuses a pose (already in the Cartesian frame) outside the workspace box.
void checkInWorkspace(const lfd::Pose& pose, const std::string& what, const RequestLimits& limits);

/// Object names: as many as poses, none empty, none repeated, within the count and length limits.
void checkObjectNames(const std::vector<std::string>& names, size_t poses,
                      const RequestLimits& limits);

/// A name or path from a request within ~limits/max_name_length (clipped in the message).
void checkNameLength(const std::string& text, const std::string& what, const RequestLimits& limits);

}  // namespace lfd_dmp
