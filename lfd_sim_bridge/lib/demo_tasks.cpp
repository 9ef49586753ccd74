#include "lfd_sim_bridge/demo_tasks.hpp"

#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {

TaskSetup loadTaskSetup(const std::string& tasks_dir, const std::string& task,
                        const std::string& mode) {
  if (mode != "sim" && mode != "teleop")
    throw std::runtime_error("unknown mode '" + mode + "' (expected sim or teleop)");
  const task::Scene scene = task::loadScene(tasks_dir + "/../scene.yaml");
  task::loadTask(task::taskFilePath(tasks_dir, task), scene);  // the task exists and is valid
  TaskSetup setup;
  setup.task = task;
  setup.mode = mode;
  setup.grasp_orientation = setup.push_orientation = scene.tool_orientation;
  setup.table_top = scene.table_top;
  return setup;
}

}  // namespace demo
}  // namespace lfd_sim_bridge
