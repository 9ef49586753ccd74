// The tool orientation of a task, for lfd_dmp's executor until it stops depending on this package
// (issue 15 frees it from the simulator): read from the task files (config/tasks/<task>.yaml and
// the scene file beside their folder). The demonstrator itself uses task_file.hpp and
// demo_plan.hpp.
#pragma once

#include <string>

#include "lfd_sim_bridge/task_file.hpp"

namespace lfd_sim_bridge {
namespace demo {

struct TaskSetup {
  std::string task, mode;
  // TCP orientation (base_link) at yaw 0 of the task's poses: the scene's tool orientation.
  Eigen::Quaterniond grasp_orientation = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond push_orientation = Eigen::Quaterniond::Identity();
  double table_top = 0.0;  // world z of the table surface
};

// `tasks_dir`: the folder of task files; the scene file is <tasks_dir>/../scene.yaml. Throws
// std::runtime_error naming the file and the key.
TaskSetup loadTaskSetup(const std::string& tasks_dir, const std::string& task,
                        const std::string& mode);

}  // namespace demo
}  // namespace lfd_sim_bridge
