#include "lfd_sim_bridge/demo_tasks.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace lfd_sim_bridge {
namespace demo {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("tasks file '" + path + "': " + what);
}

// A pose written as [x, y, z], [x, y, z, yaw] or {position: [x, y, z], yaw: a} or
// {position: [...], orientation: [w, x, y, z]}.
Pose parsePose(const YAML::Node& node, const std::string& path, const std::string& where) {
  Pose p;
  auto vector3 = [&](const YAML::Node& n) {
    if (!n.IsSequence() || n.size() < 3) fail(path, where + " needs a position [x, y, z]");
    return Eigen::Vector3d(n[0].as<double>(), n[1].as<double>(), n[2].as<double>());
  };
  auto yaw = [](double a) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()));
  };
  if (node.IsSequence()) {
    p.position = vector3(node);
    if (node.size() == 4) p.orientation = yaw(node[3].as<double>());
    if (node.size() != 3 && node.size() != 4) fail(path, where + " must be [x, y, z(, yaw)]");
    return p;
  }
  if (!node.IsMap() || !node["position"]) fail(path, where + " is not a pose");
  p.position = vector3(node["position"]);
  if (node["orientation"]) {
    const YAML::Node q = node["orientation"];
    if (!q.IsSequence() || q.size() != 4) fail(path, where + ".orientation must be [w, x, y, z]");
    p.orientation = Eigen::Quaterniond(q[0].as<double>(), q[1].as<double>(), q[2].as<double>(),
                                       q[3].as<double>());
    if (p.orientation.norm() < 1e-9) fail(path, where + ".orientation is a zero quaternion");
    p.orientation.normalize();
  } else if (node["yaw"]) {
    p.orientation = yaw(node["yaw"].as<double>());
  }
  return p;
}

Eigen::Quaterniond parseQuaternion(const YAML::Node& q, const std::string& path,
                                   const std::string& where) {
  if (!q.IsSequence() || q.size() != 4) fail(path, where + " must be [w, x, y, z]");
  Eigen::Quaterniond out(q[0].as<double>(), q[1].as<double>(), q[2].as<double>(),
                         q[3].as<double>());
  if (out.norm() < 1e-9) fail(path, where + " is a zero quaternion");
  return out.normalized();
}

}  // namespace

TaskSetup loadTaskSetup(const std::string& path, const std::string& task, const std::string& mode) {
  if (task != "grasp" && task != "push")
    throw std::runtime_error("unknown task '" + task + "' (expected grasp or push)");
  if (mode != "sim" && mode != "teleop")
    throw std::runtime_error("unknown mode '" + mode + "' (expected sim or teleop)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
  TaskSetup setup;
  setup.task = task;
  setup.mode = mode;
  setup.object = task == "grasp" ? "stick" : "box";
  try {
    if (root["table_top"]) setup.table_top = root["table_top"].as<double>();
    if (const YAML::Node g = root["gripper_orientation"]) {
      if (g["grasp"])
        setup.grasp_orientation = parseQuaternion(g["grasp"], path, "gripper_orientation.grasp");
      if (g["push"])
        setup.push_orientation = parseQuaternion(g["push"], path, "gripper_orientation.push");
    }
    if (const YAML::Node park = root["park"]) {
      for (const auto& entry : park)
        setup.park[entry.first.as<std::string>()] =
            parsePose(entry.second, path, "park." + entry.first.as<std::string>());
    }
    const YAML::Node list = root[task][mode];
    if (!list || !list.IsSequence() || list.size() == 0)
      fail(path, task + "." + mode + " must be a non-empty list of configurations");
    const std::string goal_key = task == "grasp" ? "goal" : "target";
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string where = task + "." + mode + "[" + std::to_string(i) + "]";
      const YAML::Node entry = list[i];
      if (!entry[setup.object] || !entry[goal_key])
        fail(path, where + " needs '" + setup.object + "' and '" + goal_key + "'");
      TaskConfiguration c;
      c.index = entry["id"] ? entry["id"].as<int>() : static_cast<int>(i);
      c.object_start = parsePose(entry[setup.object], path, where + "." + setup.object);
      c.goal = parsePose(entry[goal_key], path, where + "." + goal_key);
      setup.configurations.push_back(c);
    }
  } catch (const YAML::Exception& e) {
    fail(path, std::string("invalid value: ") + e.what());
  }
  return setup;
}

Outcome judge(const std::string& task, const Pose& object_end, const Pose& goal, double table_top,
              const SuccessCriteria& criteria) {
  Outcome out;
  out.height = object_end.position.z() - table_top;
  std::ostringstream why;
  why.precision(3);
  if (task == "grasp") {
    out.distance = (object_end.position - goal.position).norm();
    out.success = out.height >= criteria.min_lift && out.distance <= criteria.tolerance;
    why << "stick " << out.height * 100
        << " cm above the table (need >= " << criteria.min_lift * 100 << "), " << out.distance * 100
        << " cm from the goal (need <= " << criteria.tolerance * 100 << ")";
  } else if (task == "push") {
    out.distance = (object_end.position - goal.position).head<2>().norm();
    out.success = out.distance <= criteria.tolerance;
    why << "box " << out.distance * 100
        << " cm from its target (need <= " << criteria.tolerance * 100 << ")";
  } else {
    throw std::invalid_argument("unknown task '" + task + "'");
  }
  out.reason = why.str();
  return out;
}

}  // namespace demo
}  // namespace lfd_sim_bridge
