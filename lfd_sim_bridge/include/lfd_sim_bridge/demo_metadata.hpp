// What a demonstration bag says about itself (ROS-free): the JSON of /lfd/metadata's extra_json,
// with the "scene" block every consumer relies on (the learner learns each skill's end relative to
// these objects and the goal; the judge reads the goal; the snapshot tool rebuilds the scene).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "lfd_sim_bridge/demo_plan.hpp"

namespace lfd_sim_bridge {
namespace demo {

struct DemoMetadata {
  const task::TaskDefinition* task = nullptr;
  const task::Scene* scene = nullptr;
  const task::Configuration* configuration = nullptr;
  int seed = 0;
  double speed = 1.0;
  double tremor_rms = 0.0;
  double planned_duration = 0.0;  // s, every guarded move running its course
  // Where the demonstrator aimed at each object, relative to where it is (the task's variation
  // and the teleop operator's misjudgement): world offset (m) and yaw (rad).
  std::map<std::string, std::pair<Eigen::Vector3d, double>> aim_offsets;
};

// {"task", "frame": "world", "scene": {"frame": "world", "objects": {name: pose},
//  "goal": pose, "joints": {joint: start value}}, "phases": [names], "windows": [names of the
// transition windows], "object" (the first object, "" for none), "object_start", "goal",
// "table_top", "seed", "speed", "aim", "tremor_rms", "planned_duration", "task_file"}, poses as
// {"position": [x, y, z], "orientation": [w, x, y, z]} in the world frame. Keys in this order,
// numbers with every digit (they read back exactly), strings as UTF-8 (a byte that is not UTF-8
// becomes U+FFFD: a bag's string field must be valid UTF-8 for its Python readers).
std::string metadataJson(const DemoMetadata& m);

// What metadataJson wrote, read back: the inverse of metadataJson, for tools and tests (the
// learner reads the scene block with lfd_dmp::sceneFromMetadata, the judge with Python's json).
struct MetadataRecord {
  std::string task, frame, scene_frame;
  std::vector<std::pair<std::string, Pose>> objects;  // scene.objects, in the task's order
  Pose scene_goal;
  std::vector<std::pair<std::string, double>> joints;  // scene.joints
  std::vector<std::string> phases, windows;
  std::string object;
  bool has_object_start = false;
  Pose object_start, goal;
  double table_top = 0.0;
  int seed = 0;
  double speed = 1.0;
  std::map<std::string, std::pair<Eigen::Vector3d, double>> aim;
  double tremor_rms = 0.0, planned_duration = 0.0;
  std::string task_file;
};

// Throws std::runtime_error naming what is missing or malformed.
MetadataRecord readMetadataJson(const std::string& text);

// A JSON string literal (quotes, backslashes and control characters escaped; also a valid YAML
// double-quoted scalar, as the demonstrator's result file uses it).
std::string jsonString(const std::string& s);

}  // namespace demo
}  // namespace lfd_sim_bridge
