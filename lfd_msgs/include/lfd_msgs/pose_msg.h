// The suite's one conversion of a pose to its message, shared by the ROS adapters of the
// demonstrator (lfd_sim_bridge) and of the executor (lfd_dmp), which depend on each other's
// packages no more than on this one.
#pragma once

#include <geometry_msgs/Pose.h>

namespace lfd_msgs {

/// The message of a pose with Eigen-like members `position` (x(), y(), z()) and `orientation`
/// (a quaternion: w(), x(), y(), z()), as lfd::Pose. A template, so that this message package
/// needs no C++ library of the suite.
template <typename Pose>
geometry_msgs::Pose toPoseMsg(const Pose& p) {
  geometry_msgs::Pose m;
  m.position.x = p.position.x();
  m.position.y = p.position.y();
  m.position.z = p.position.z();
  m.orientation.w = p.orientation.w();
  m.orientation.x = p.orientation.x();
  m.orientation.y = p.orientation.y();
  m.orientation.z = p.orientation.z();
  return m;
}

}  // namespace lfd_msgs
