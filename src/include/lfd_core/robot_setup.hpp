// The robot as the learn-and-reproduce half needs it, read from one file (config/robot.yaml) by
// the demonstrator and the executor alike: the IK chain (base and tip links of the URDF), its
// motion costs, null-space posture and accepted residual, and the gripper's joint and commands.
// Nothing here knows a simulator: a real robot is described by its own robot.yaml.
#pragma once

#include <map>
#include <string>

#include "lfd_core/cartesian_path.hpp"

namespace lfd {

struct GripperSetup {
  std::string joint = "R_GRIPPER";  // joint whose position the gripper state reports
  double open_opening = 0.08;       // m between the pads when opened
  double close_opening = 0.0;       // m commanded to close (the effort limit stops it on an object)
  double close_effort = 20.0;       // N
};

struct RobotSetup {
  std::string base_link = "base_link";  // IK chain root (URDF link)
  std::string tip_link;                 // tool centre point (URDF link)
  // Frame of every Cartesian pose (end-effector topic, plans, rollouts); "" = base_link.
  std::string cartesian_frame;
  std::map<std::string, double> joint_costs;        // unlisted joints: 1
  std::map<std::string, double> preferred_posture;  // rad; unlisted joints: 0
  IkTolerance ik_tolerance;
  GripperSetup gripper;
};

// Throws std::runtime_error naming the file and the missing or invalid key.
RobotSetup loadRobotSetup(const std::string& path);

// The IK chain of `setup` on a robot model (URDF text), with the setup's costs and posture, for
// Cartesian poses in setup.cartesian_frame (the chain root's pose in it comes from the URDF at
// zero joints). Throws std::runtime_error when a link is missing.
CartesianToJoints makeCartesianToJoints(const std::string& urdf_xml, const RobotSetup& setup,
                                        IkOptions options = IkOptions());

}  // namespace lfd
