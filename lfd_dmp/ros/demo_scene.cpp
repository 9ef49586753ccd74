#include "lfd_dmp/demo_scene.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <tf2/buffer_core.h>
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

namespace {

// tf2 drops a leading '/' of the frames it stores ("/world" is "world") but refuses one in a
// lookup: drop it there too, so that a tf1-era name finds its frame.
std::string tf2Frame(const std::string& frame) {
  return !frame.empty() && frame.front() == '/' ? frame.substr(1) : frame;
}

}  // namespace

StaticTransforms::StaticTransforms() : buffer_(std::make_unique<tf2::BufferCore>()) {}
StaticTransforms::~StaticTransforms() = default;
StaticTransforms::StaticTransforms(StaticTransforms&&) noexcept = default;
StaticTransforms& StaticTransforms::operator=(StaticTransforms&&) noexcept = default;

void StaticTransforms::add(const std::string& parent, const std::string& child,
                           const Eigen::Isometry3d& child_in_parent) {
  // Checked here: BufferCore would only log these and drop the transform.
  if (tf2Frame(parent).empty() || tf2Frame(child).empty() || tf2Frame(parent) == tf2Frame(child))
    throw std::runtime_error("static transform '" + parent + "' -> '" + child + "' is not valid");
  if (!child_in_parent.matrix().allFinite())
    throw std::runtime_error("static transform '" + parent + "' -> '" + child + "' is not finite");
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  const Eigen::Vector3d p = child_in_parent.translation();
  const Eigen::Quaterniond q(child_in_parent.rotation());
  t.transform.translation.x = p.x();
  t.transform.translation.y = p.y();
  t.transform.translation.z = p.z();
  t.transform.rotation.w = q.w();
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  if (!buffer_->setTransform(t, "bag", /*is_static=*/true))
    throw std::runtime_error("static transform '" + parent + "' -> '" + child +
                             "' is refused by tf2");
  empty_ = false;
}

Eigen::Isometry3d StaticTransforms::lookup(const std::string& target,
                                           const std::string& source) const {
  if (target == source) return Eigen::Isometry3d::Identity();
  // Static transforms hold at every time: time 0 is "the latest".
  const geometry_msgs::Transform t =
      buffer_->lookupTransform(tf2Frame(target), tf2Frame(source), ros::Time()).transform;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  out.linear() =
      Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z).toRotationMatrix();
  return out;
}

}  // namespace lfd_dmp
