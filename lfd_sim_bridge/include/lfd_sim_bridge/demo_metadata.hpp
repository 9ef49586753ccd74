// What a demonstration bag says about itself (ROS-free): the JSON of /lfd/metadata's extra_json,
// with the "scene" block every consumer relies on (the learner learns each skill's end relative to
// these objects and the goal; the judge reads the goal; the snapshot tool rebuilds the scene).
#pragma once

#include <map>
#include <string>
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
// {"position": [x, y, z], "orientation": [w, x, y, z]} in the world frame.
std::string metadataJson(const DemoMetadata& m);

// A JSON string literal (quotes, backslashes and control characters escaped).
std::string jsonString(const std::string& s);
std::string poseJson(const Pose& p);

}  // namespace demo
}  // namespace lfd_sim_bridge
