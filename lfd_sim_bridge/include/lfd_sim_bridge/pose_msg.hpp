// Conversion of the demonstrator's / executor's TCP pose to its ROS message (ROS adapters only).
#pragma once

#include <geometry_msgs/Pose.h>

#include "lfd_sim_bridge/demo_motion.hpp"

namespace lfd_sim_bridge {

inline geometry_msgs::Pose toPoseMsg(const demo::Pose& p) {
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

}  // namespace lfd_sim_bridge
