// Task configurations of the demonstrator (ROS-free): where the object starts and where it must
// end for each demonstration, read from config/tasks.yaml, and the physical success criterion
// shared by the demonstrator and the dataset checker.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "lfd_sim_bridge/demo_motion.hpp"

namespace lfd_sim_bridge {
namespace demo {

struct TaskConfiguration {
  int index = 0;
  Pose object_start;  // world frame
  Pose goal;          // world frame: grasp = stick goal (lifted), push = box target
};

struct TaskSetup {
  std::string task;    // "grasp" or "push"
  std::string mode;    // "sim" or "teleop"
  std::string object;  // "stick" or "box"
  std::vector<TaskConfiguration> configurations;
  std::map<std::string, Pose> park;  // where the objects not used by the task wait (world)
  // TCP orientation (base_link) grasping a stick lying along x / pushing along +x.
  Eigen::Quaterniond grasp_orientation = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond push_orientation = Eigen::Quaterniond::Identity();
  double table_top = 0.80;  // world z of the table surface
};

// Reads the task's configurations for the mode from a tasks.yaml file. Throws
// std::runtime_error naming the file and the missing/invalid entry.
TaskSetup loadTaskSetup(const std::string& path, const std::string& task, const std::string& mode);

// Physical success of a demonstration (the evaluation protocol): grasp = the stick ends at least
// `min_lift` above the table and within `tolerance` of its goal; push = the box ends within
// `tolerance` of its target (horizontal distance). The numbers are config/evaluation.yaml's
// `reproduction` block (the demonstrator node reads them); no defaults here, so none can differ.
struct SuccessCriteria {
  double tolerance = 0.0;  // m
  double min_lift = 0.0;   // m above the table (grasp)
};

struct Outcome {
  bool success = false;
  double distance = 0.0;  // m to the goal
  double height = 0.0;    // m of the object's centre above the table
  std::string reason;     // human-readable verdict
};

Outcome judge(const std::string& task, const Pose& object_end, const Pose& goal, double table_top,
              const SuccessCriteria& criteria);

}  // namespace demo
}  // namespace lfd_sim_bridge
