// The scene of a demonstration as its bag records it, ROS-free: the `/lfd/metadata` extra_json
// (objects and goal, in a named frame) and the static transforms (`/tf_static`) that bring it into
// the robot's Cartesian frame, where the learner compares it with the end-effector poses.
//
// extra_json contract (DESIGN.md, "Robot and scene contract"), the first form found is used:
//   {"scene": {"frame": "world", "objects": {NAME: POSE, ...}, "goal": POSE, "joints": {...}}}
//   {"frame": "world", "object": NAME, "object_start": POSE, "goal": POSE}      (older bags)
// POSE = {"position": [x, y, z], "orientation": [w, x, y, z]}; "frame" defaults to "world".
#pragma once

#include <lfd_core/task_frames.hpp>

#include <Eigen/Geometry>

#include <map>
#include <optional>
#include <string>

namespace lfd_dmp {

struct SceneRecord {
  std::string frame = "world";  ///< the frame the poses are written in
  lfd::Scene scene;
};

/// The scene of a metadata extra_json; empty when it holds none. Throws std::runtime_error naming
/// the field when a scene is there but malformed (non-finite, a zero quaternion, wrong shapes).
/// Quaternions are normalized.
std::optional<SceneRecord> sceneFromMetadata(const std::string& extra_json);

/// The scene with every pose moved by `frame_in_target` (the scene frame's pose in the target).
lfd::Scene transformScene(const lfd::Scene& scene, const Eigen::Isometry3d& frame_in_target);

/// A tree of static transforms (tf2 semantics: each child has one parent).
class StaticTransforms {
 public:
  /// `child_in_parent`: the child frame's pose in the parent frame.
  void add(const std::string& parent, const std::string& child,
           const Eigen::Isometry3d& child_in_parent);
  /// The pose of `source` in `target`. Throws std::runtime_error when they are not connected.
  Eigen::Isometry3d lookup(const std::string& target, const std::string& source) const;
  bool empty() const { return parent_.empty(); }

 private:
  // The frame's pose in the root of its tree, and that root.
  Eigen::Isometry3d inRoot(const std::string& frame, std::string* root) const;
  std::map<std::string, std::pair<std::string, Eigen::Isometry3d>> parent_;
};

}  // namespace lfd_dmp
