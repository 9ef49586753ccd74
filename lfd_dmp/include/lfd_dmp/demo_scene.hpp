// The scene of a demonstration as its bag records it, master-free: the `/lfd/metadata` extra_json
// (objects and goal, in a named frame) and the static transforms (`/tf_static`) that bring it into
// the robot's Cartesian frame, where the learner compares it with the end-effector poses.
//
// extra_json contract (DESIGN.md, "Robot and scene contract"), the first form found is used:
//   {"scene": {"frame": "world", "objects": {NAME: POSE, ...}, "goal": POSE, "joints": {...}}}
//   {"frame": "world", "object": NAME, "object_start": POSE, "goal": POSE}      (older bags)
// POSE = {"position": [x, y, z], "orientation": [w, x, y, z]}; "frame" defaults to "world".
#pragma once

#include <lfd_core/dmp/task_frames.hpp>

#include <Eigen/Geometry>

#include <map>
#include <memory>
#include <optional>
#include <string>

namespace tf2 {
class BufferCore;
}

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

/// A tree of static transforms (a bag's /tf_static), held by tf2's BufferCore: each child has one
/// parent, a frame name's leading '/' is dropped (tf2's convention), lookups chain through the
/// tree as tf does.
class StaticTransforms {
 public:
  StaticTransforms();
  ~StaticTransforms();
  StaticTransforms(StaticTransforms&&) noexcept;
  StaticTransforms& operator=(StaticTransforms&&) noexcept;

  /// `child_in_parent`: the child frame's pose in the parent frame (a rigid transform). Throws
  /// std::runtime_error for an empty or self-referencing pair of frames or a non-finite pose.
  void add(const std::string& parent, const std::string& child,
           const Eigen::Isometry3d& child_in_parent);
  /// The pose of `source` in `target`. Throws std::runtime_error (tf2::TransformException) when
  /// they are not connected.
  Eigen::Isometry3d lookup(const std::string& target, const std::string& source) const;
  bool empty() const { return empty_; }

 private:
  std::unique_ptr<tf2::BufferCore> buffer_;
  bool empty_ = true;
};

}  // namespace lfd_dmp
