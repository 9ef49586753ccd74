// The robot as the learn-and-reproduce half needs it, read from one file (the robot description
// package's config/robot.yaml) by the demonstrator, the executor and the bridge alike: the IK chain
// (base and tip links of the URDF), its motion costs, null-space posture and accepted residual, the
// gripper's joint and commands, and the sensor table. Nothing here knows a simulator or ROS: a real
// robot is described by its own robot.yaml, and its driver publishes what the table says.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "lfd_core/kinematics/cartesian_path.hpp"

namespace lfd {

struct GripperSetup {
  std::string joint;           // joint whose position the gripper state reports (required)
  double open_opening = 0.08;  // m between the pads when opened
  double close_opening = 0.0;  // m commanded to close (the effort limit stops it on an object)
  double close_effort = 20.0;  // N
  // Opening between the pads per unit of the joint (a joint moving each pad of two: 2).
  double opening_scale = 1.0;
};

// One row of the sensor table, the way ros_control's hardware interfaces describe a sensor: which
// device sensors (by their name in the robot's model, e.g. MJCF) make up one message of a standard
// type, published on `topic` with header.frame_id `frame`. The topic is the row's key.
struct SensorEntry {
  std::string topic;  // e.g. /wrist_ft
  std::string type;   // ROS message type, e.g. geometry_msgs/WrenchStamped
  std::string frame;  // tf frame of the readings
  // Message field -> device sensors feeding it, in the file's order (a force, or a list of pads).
  std::vector<std::pair<std::string, std::vector<std::string>>> fields;
};

struct RobotSetup {
  std::string name;  // robot.yaml `name` (its package: <name>_description); messages use it
  std::string base_link = "base_link";  // IK chain root (URDF link)
  std::string tip_link;                 // tool centre point (URDF link)
  // Frame of every Cartesian pose (end-effector topic, plans, rollouts); "" = base_link.
  std::string cartesian_frame;
  std::map<std::string, double> joint_costs;        // unlisted joints: 1
  std::map<std::string, double> preferred_posture;  // rad; unlisted joints: 0
  IkTolerance ik_tolerance;
  GripperSetup gripper;
  // The ready posture a simulated robot starts in and returns to at a reset (rad or m; unlisted
  // joints: 0). The gripper joint's entry is in joint units.
  std::map<std::string, double> initial_posture;
  std::vector<SensorEntry> sensors;  // the sensor table, in the file's order

  // The frame of every Cartesian pose: cartesian_frame, or the chain's base link.
  const std::string& poseFrame() const {
    return cartesian_frame.empty() ? base_link : cartesian_frame;
  }
};

// The row of `setup.sensors` publishing `type` (the first one), or nullptr.
const SensorEntry* findSensorOfType(const RobotSetup& setup, const std::string& type);

// Throws std::runtime_error naming the file and the missing or invalid key.
RobotSetup loadRobotSetup(const std::string& path);

// The IK chain of `setup` on a robot model (URDF text), with the setup's costs and posture, for
// Cartesian poses in setup.cartesian_frame (the chain root's pose in it comes from the URDF at
// zero joints). Throws std::runtime_error when a link is missing.
CartesianToJoints makeCartesianToJoints(const std::string& urdf_xml, const RobotSetup& setup,
                                        IkOptions options = IkOptions());

}  // namespace lfd
