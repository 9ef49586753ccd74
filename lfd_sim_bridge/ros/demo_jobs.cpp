#include "lfd_sim_bridge/demo_jobs.hpp"

#include <set>
#include <stdexcept>

#include <XmlRpcValue.h>

namespace lfd_sim_bridge {
namespace {

std::string text(XmlRpc::XmlRpcValue& v, const std::string& where) {
  if (v.getType() != XmlRpc::XmlRpcValue::TypeString)
    throw std::invalid_argument(where + " must be a string");
  return static_cast<std::string>(v);
}

std::vector<int> ids(XmlRpc::XmlRpcValue& v, const std::string& where) {
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray)
    throw std::invalid_argument(where + " must be a list of configuration ids");
  std::vector<int> out;
  for (int i = 0; i < v.size(); ++i) {
    if (v[i].getType() != XmlRpc::XmlRpcValue::TypeInt)
      throw std::invalid_argument(where + "[" + std::to_string(i) + "] must be an integer");
    out.push_back(static_cast<int>(v[i]));
  }
  return out;
}

void check(const DemoJob& job, const std::string& where) {
  if (job.task.empty()) throw std::invalid_argument(where + "task is required");
  if (job.output_dir.empty()) throw std::invalid_argument(where + "output_dir is required");
  if (job.tasks_dir.empty()) throw std::invalid_argument(where + "tasks_dir is required");
  if (job.mode != "sim" && job.mode != "teleop")
    throw std::invalid_argument(where + "mode must be sim or teleop, got '" + job.mode + "'");
}

}  // namespace

std::vector<DemoJob> loadDemoJobs(const ros::NodeHandle& pnh) {
  DemoJob defaults;
  pnh.getParam("tasks_dir", defaults.tasks_dir);
  XmlRpc::XmlRpcValue list;
  const bool listed = pnh.getParam("datasets", list) &&
                      !(list.getType() == XmlRpc::XmlRpcValue::TypeArray && list.size() == 0);
  std::string task;
  pnh.getParam("task", task);
  if (listed && !task.empty())
    throw std::invalid_argument("~task and ~datasets are both set: give one of them");
  if (!listed) {  // one dataset (demonstrate.launch task:=...)
    DemoJob job = defaults;
    job.task = task;
    pnh.getParam("mode", job.mode);
    pnh.getParam("output_dir", job.output_dir);
    pnh.getParam("configurations", job.configurations);
    check(job, "~");
    return {job};
  }
  if (list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    throw std::invalid_argument("~datasets must be a list of {task, mode, output_dir, ...}");
  std::vector<DemoJob> jobs;
  std::set<std::string> names;
  for (int i = 0; i < list.size(); ++i) {
    const std::string where = "~datasets[" + std::to_string(i) + "]";
    if (list[i].getType() != XmlRpc::XmlRpcValue::TypeStruct)
      throw std::invalid_argument(where + " must be a map");
    DemoJob job = defaults;
    for (auto& [key, value] : list[i]) {
      if (key == "task") {
        job.task = text(value, where + "/" + key);
      } else if (key == "mode") {
        job.mode = text(value, where + "/" + key);
      } else if (key == "output_dir") {
        job.output_dir = text(value, where + "/" + key);
      } else if (key == "tasks_dir") {
        job.tasks_dir = text(value, where + "/" + key);
      } else if (key == "configurations") {
        job.configurations = ids(value, where + "/" + key);
      } else {
        throw std::invalid_argument(where + "/" + key + " is not a key of a dataset");
      }
    }
    check(job, where + "/");
    // Twice the same bags: the second would skip them as existing, or record them again.
    if (!names.insert(job.output_dir + "/" + job.name()).second)
      throw std::invalid_argument(where + ": " + job.name() + " in " + job.output_dir +
                                  " is listed twice");
    jobs.push_back(job);
  }
  return jobs;
}

}  // namespace lfd_sim_bridge
