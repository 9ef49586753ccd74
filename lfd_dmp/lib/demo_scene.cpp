#include "lfd_dmp/demo_scene.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <stdexcept>

namespace lfd_dmp {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error("metadata extra_json " + where + ": " + what);
}

Eigen::VectorXd numbers(const json& j, size_t n, const std::string& where) {
  if (!j.is_array() || j.size() != n)
    fail(where, "expected an array of " + std::to_string(n) + " numbers");
  Eigen::VectorXd v(static_cast<Eigen::Index>(n));
  for (size_t i = 0; i < n; ++i) {
    if (!j[i].is_number()) fail(where, "expected numbers");
    v[static_cast<Eigen::Index>(i)] = j[i].get<double>();
  }
  if (!v.allFinite()) fail(where, "is not finite");
  return v;
}

lfd::Pose pose(const json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("position"))
    fail(where, "expected {\"position\": [x, y, z], \"orientation\": [w, x, y, z]}");
  lfd::Pose p;
  p.position = numbers(j["position"], 3, where + ".position");
  if (j.contains("orientation")) {
    const Eigen::VectorXd q = numbers(j["orientation"], 4, where + ".orientation");
    if (q.norm() < 1e-6) fail(where + ".orientation", "has zero norm");
    p.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
  }
  return p;
}

std::string frameOf(const json& j, const std::string& where) {
  if (!j.contains("frame")) return "world";
  if (!j["frame"].is_string() || j["frame"].get<std::string>().empty())
    fail(where + ".frame", "expected a frame name");
  return j["frame"].get<std::string>();
}

}  // namespace

std::optional<SceneRecord> sceneFromMetadata(const std::string& extra_json) {
  json j;
  try {
    j = json::parse(extra_json);
  } catch (const json::parse_error& e) {
    throw std::runtime_error(std::string("metadata extra_json is not valid JSON: ") + e.what());
  }
  if (!j.is_object()) return std::nullopt;
  SceneRecord r;
  if (j.contains("scene")) {
    const json& s = j["scene"];
    if (!s.is_object() || !s.contains("objects") || !s.contains("goal"))
      fail("scene", "expected {\"frame\", \"objects\": {name: pose}, \"goal\": pose}");
    r.frame = frameOf(s, "scene");
    if (!s["objects"].is_object()) fail("scene.objects", "expected {name: pose}");
    for (const auto& [name, p] : s["objects"].items())
      r.scene.objects[name] = pose(p, "scene.objects." + name);
    r.scene.goal = pose(s["goal"], "scene.goal");
    return r;
  }
  if (!j.contains("object") || !j.contains("object_start") || !j.contains("goal"))
    return std::nullopt;
  if (!j["object"].is_string() || j["object"].get<std::string>().empty())
    fail("object", "expected the object's name");
  r.frame = frameOf(j, "");
  r.scene.objects[j["object"].get<std::string>()] = pose(j["object_start"], "object_start");
  r.scene.goal = pose(j["goal"], "goal");
  return r;
}

lfd::Scene transformScene(const lfd::Scene& scene, const Eigen::Isometry3d& frame_in_target) {
  auto move = [&](const lfd::Pose& p) { return lfd::toPose(frame_in_target * lfd::toIsometry(p)); };
  lfd::Scene out;
  for (const auto& [name, p] : scene.objects) out.objects[name] = move(p);
  out.goal = move(scene.goal);
  return out;
}

void StaticTransforms::add(const std::string& parent, const std::string& child,
                           const Eigen::Isometry3d& child_in_parent) {
  if (parent.empty() || child.empty() || parent == child)
    throw std::runtime_error("static transform '" + parent + "' -> '" + child + "' is not valid");
  if (!child_in_parent.matrix().allFinite())
    throw std::runtime_error("static transform '" + parent + "' -> '" + child + "' is not finite");
  parent_[child] = {parent, child_in_parent};
}

Eigen::Isometry3d StaticTransforms::inRoot(const std::string& frame, std::string* root) const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  std::string f = frame;
  for (size_t depth = 0; depth <= parent_.size(); ++depth) {
    const auto it = parent_.find(f);
    if (it == parent_.end()) {
      *root = f;
      return t;
    }
    t = it->second.second * t;
    f = it->second.first;
  }
  throw std::runtime_error("static transforms form a loop through '" + frame + "'");
}

Eigen::Isometry3d StaticTransforms::lookup(const std::string& target,
                                           const std::string& source) const {
  if (target == source) return Eigen::Isometry3d::Identity();
  std::string root_target, root_source;
  const Eigen::Isometry3d target_in_root = inRoot(target, &root_target);
  const Eigen::Isometry3d source_in_root = inRoot(source, &root_source);
  if (root_target != root_source)
    throw std::runtime_error("no static transform connects '" + source + "' to '" + target + "'");
  return target_in_root.inverse() * source_in_root;
}

}  // namespace lfd_dmp
