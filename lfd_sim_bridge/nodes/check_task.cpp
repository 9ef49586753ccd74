// check_task: whether task files load, without ROS, as the demonstrator loads them
// (task_file.hpp). The task format's one check: lfd_tools.tasks asks it of every file it reads.
//
//   check_task --scene config/scene.yaml TASK_FILE...
//
// Prints "ok FILE" for each file that loads, the error (naming the file and the key) on stderr for
// each that does not. Exit status 0 when all load, 1 when one does not, 2 on a usage error.
#include <iostream>
#include <string>
#include <vector>

#include "lfd_sim_bridge/task_file.hpp"

namespace task = lfd_sim_bridge::task;

int main(int argc, char** argv) {
  std::string scene_file;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--scene" && i + 1 < argc) {
      scene_file = argv[++i];
    } else {
      files.push_back(arg);
    }
  }
  if (scene_file.empty() || files.empty()) {
    std::cerr << "usage: check_task --scene SCENE_FILE TASK_FILE...\n";
    return 2;
  }
  task::Scene scene;
  try {
    scene = task::loadScene(scene_file);
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  int status = 0;
  for (const std::string& file : files) {
    try {
      task::loadTask(file, scene);
      std::cout << "ok " << file << "\n";
    } catch (const std::exception& e) {
      std::cerr << e.what() << "\n";
      status = 1;
    }
  }
  return status;
}
