// The datasets one demonstrator run records, from its private parameters: either ~datasets, a list
// of {task, mode, output_dir, configurations, tasks_dir} (generate_datasets.py: one simulation per
// worker records all of the worker's datasets), or the single dataset of ~task, ~mode, ~output_dir
// and ~configurations (demonstrate.launch task:=...). ~tasks_dir is every job's default folder.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

namespace lfd_sim_bridge {

struct DemoJob {
  std::string task;                 // a task file's name: <tasks_dir>/<task>.yaml
  std::string mode = "sim";         // sim | teleop; also the bridge's noise profile
  std::string output_dir;           // one bag per demo
  std::string tasks_dir;            // folder of the task file
  std::vector<int> configurations;  // ids from the task file; empty = all of the mode

  std::string name() const { return mode + "_" + task; }  // the dataset, <mode>_<task>
};

// Throws std::invalid_argument naming the parameter when a job is incomplete or malformed (an
// unknown key, a mode other than sim or teleop, both ~task and ~datasets, or neither).
std::vector<DemoJob> loadDemoJobs(const ros::NodeHandle& pnh);

}  // namespace lfd_sim_bridge
