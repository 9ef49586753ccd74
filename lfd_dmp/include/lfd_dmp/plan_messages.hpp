// An execution plan as the ROS messages a robot driver and rviz take: one joint trajectory
// stamped with the sim time it starts, gripper commands stamped with the times they take effect,
// the planned path and segment markers.
#pragma once

#include "lfd_dmp/executor.hpp"

#include <lfd_msgs/GripperCommand.h>
#include <lfd_msgs/pose_msg.h>
#include <lfd_core/kinematics/robot_setup.hpp>

#include <geometry_msgs/Pose.h>
#include <nav_msgs/Path.h>
#include <ros/time.h>
#include <trajectory_msgs/JointTrajectory.h>
#include <visualization_msgs/MarkerArray.h>

#include <vector>

namespace lfd_dmp {

/// A TCP pose as its message: the suite's one conversion (the demonstrator's too).
using lfd_msgs::toPoseMsg;

/// The planned joints from sample `from` on, every `period` s (and the last sample), velocities
/// by central differences; header.stamp = `start` + the time of sample `from` (the plan starts at
/// `start`): the driver interpolates them on its clock from then on, and a trajectory sent while
/// another runs replaces it from its stamp (a replanned rest of the motion).
trajectory_msgs::JointTrajectory toJointTrajectory(const ExecutionPlan& plan,
                                                   const ros::Time& start, double period,
                                                   size_t from = 0);

/// Refuses a trajectory that moves a joint faster than its limit (`limits` by `joint_names`;
/// a joint without a positive finite limit is not checked): the driver refuses it whole (a
/// velocity beyond the limit made its Hermite segments overshoot), so the goal fails here, naming
/// the time, the joint, the speed and the limit. Throws std::invalid_argument.
void checkTrajectoryVelocities(const trajectory_msgs::JointTrajectory& trajectory,
                               const std::vector<std::string>& joint_names,
                               const Eigen::VectorXd& limits);

/// A trajectory of one point that holds `q` from `stamp` on (a stop).
trajectory_msgs::JointTrajectory holdTrajectory(const std::vector<std::string>& joints,
                                                const Eigen::VectorXd& q, const ros::Time& stamp);

/// The gripper command of one event (open / close), stamped with when it takes effect.
lfd_msgs::GripperCommand gripperCommand(bool close, const lfd::GripperSetup& gripper,
                                        const ros::Time& stamp);

/// The planned TCP path (every 10th sample) in `frame`.
nav_msgs::Path plannedPath(const ExecutionPlan& plan, const std::string& frame,
                           const ros::Time& stamp);

/// Spheres at each segment's start and goal, with its name.
visualization_msgs::MarkerArray segmentMarkers(const ExecutionPlan& plan, const std::string& frame,
                                               const ros::Time& stamp);

}  // namespace lfd_dmp
