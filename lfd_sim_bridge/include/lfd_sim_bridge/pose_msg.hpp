// The demonstrator's TCP and object poses as ROS messages (ROS adapters only): the suite's one
// conversion, lfd_msgs::toPoseMsg, which the executor uses too.
#pragma once

#include <lfd_msgs/pose_msg.h>

#include "lfd_sim_bridge/demo_motion.hpp"

namespace lfd_sim_bridge {

using lfd_msgs::toPoseMsg;

}  // namespace lfd_sim_bridge
