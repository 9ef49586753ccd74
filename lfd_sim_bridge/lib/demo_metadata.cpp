#include "lfd_sim_bridge/demo_metadata.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {
namespace {

// Ordered: the keys keep the documented order, the objects the task's.
using Json = nlohmann::ordered_json;

std::string dump(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

Json toJson(const Pose& p) {
  return {{"position", Json::array({p.position.x(), p.position.y(), p.position.z()})},
          {"orientation", Json::array({p.orientation.w(), p.orientation.x(), p.orientation.y(),
                                       p.orientation.z()})}};
}

Pose poseOf(const Json& j, const std::string& where) {
  const Json& position = j.at("position");
  const Json& orientation = j.at("orientation");
  if (position.size() != 3 || orientation.size() != 4)
    throw std::runtime_error("demo metadata: " + where +
                             " needs 3 position and 4 orientation numbers");
  Pose p;
  p.position = Eigen::Vector3d(position.at(0).get<double>(), position.at(1).get<double>(),
                               position.at(2).get<double>());
  p.orientation =
      Eigen::Quaterniond(orientation.at(0).get<double>(), orientation.at(1).get<double>(),
                         orientation.at(2).get<double>(), orientation.at(3).get<double>());
  return p;
}

Json sceneJson(const DemoMetadata& m) {
  const task::TaskDefinition& t = *m.task;
  const task::Configuration& c = *m.configuration;
  Json objects = Json::object();
  for (const std::string& name : t.objects) objects[name] = toJson(c.objects.at(name));
  Json joints = Json::object();
  for (const std::string& joint : t.joints(*m.scene)) {
    const auto q = c.joints.find(joint);
    joints[joint] = q == c.joints.end() ? 0.0 : q->second;
  }
  return {{"frame", "world"}, {"objects", objects}, {"goal", toJson(c.goal)}, {"joints", joints}};
}

}  // namespace

std::string jsonString(const std::string& s) {
  return dump(Json(s));
}

std::string metadataJson(const DemoMetadata& m) {
  if (!m.task || !m.scene || !m.configuration)
    throw std::invalid_argument("metadataJson needs the task, the scene and the configuration");
  const task::TaskDefinition& t = *m.task;
  const task::Configuration& c = *m.configuration;
  Json phases = Json::array(), windows = Json::array();
  for (const task::PhaseSpec& p : t.phases) {
    phases.push_back(p.name);
    if (p.window) windows.push_back(p.name);
  }
  const std::string object = t.objects.empty() ? "" : t.objects.front();
  Json aim = Json::object();
  for (const auto& [name, offset] : m.aim_offsets)
    aim[name] = {{"offset", Json::array({offset.first.x(), offset.first.y(), offset.first.z()})},
                 {"yaw", offset.second}};

  Json j = {{"task", t.name},   {"frame", "world"},   {"scene", sceneJson(m)},
            {"phases", phases}, {"windows", windows}, {"object", object}};
  if (!object.empty()) j["object_start"] = toJson(c.objects.at(object));
  j["goal"] = toJson(c.goal);
  j["table_top"] = m.scene->table_top;
  j["seed"] = m.seed;
  j["speed"] = m.speed;
  j["aim"] = aim;
  j["tremor_rms"] = m.tremor_rms;
  j["planned_duration"] = m.planned_duration;
  j["task_file"] = t.path;
  return dump(j);
}

MetadataRecord readMetadataJson(const std::string& text) {
  try {
    const Json j = Json::parse(text);
    MetadataRecord r;
    r.task = j.at("task").get<std::string>();
    r.frame = j.at("frame").get<std::string>();
    const Json& scene = j.at("scene");
    r.scene_frame = scene.at("frame").get<std::string>();
    for (const auto& [name, pose] : scene.at("objects").items())
      r.objects.emplace_back(name, poseOf(pose, "scene.objects." + name));
    r.scene_goal = poseOf(scene.at("goal"), "scene.goal");
    for (const auto& [name, value] : scene.at("joints").items())
      r.joints.emplace_back(name, value.get<double>());
    r.phases = j.at("phases").get<std::vector<std::string>>();
    r.windows = j.at("windows").get<std::vector<std::string>>();
    r.object = j.at("object").get<std::string>();
    r.has_object_start = j.contains("object_start");
    if (r.has_object_start) r.object_start = poseOf(j.at("object_start"), "object_start");
    r.goal = poseOf(j.at("goal"), "goal");
    r.table_top = j.at("table_top").get<double>();
    r.seed = j.at("seed").get<int>();
    r.speed = j.at("speed").get<double>();
    for (const auto& [name, aim] : j.at("aim").items()) {
      const Json& offset = aim.at("offset");
      if (offset.size() != 3)
        throw std::runtime_error("demo metadata: aim." + name + ".offset needs 3 numbers");
      r.aim[name] = {Eigen::Vector3d(offset.at(0).get<double>(), offset.at(1).get<double>(),
                                     offset.at(2).get<double>()),
                     aim.at("yaw").get<double>()};
    }
    r.tremor_rms = j.at("tremor_rms").get<double>();
    r.planned_duration = j.at("planned_duration").get<double>();
    r.task_file = j.at("task_file").get<std::string>();
    return r;
  } catch (const Json::exception& e) {
    throw std::runtime_error(std::string("demo metadata: ") + e.what());
  }
}

}  // namespace demo
}  // namespace lfd_sim_bridge
