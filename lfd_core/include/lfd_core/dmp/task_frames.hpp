// Segment goals learned from the demonstrations (the automatic frame selection of
// task-parameterized LfD): each demonstrated segment end is expressed in every frame the scene
// offers (the robot base, the TCP pose at the task's start, each object's start pose, the goal and
// the heading frames along each object's way to the goal); the frame in which that end varies
// least across the demos is kept, with the mean offset. A new scene then gives each segment its
// goal without a rule written by hand: an approach ends at the stick, a retreat near the start.
// Position and orientation choose their frames separately (a push ends behind the box along its
// heading, while the closed fist keeps about the same yaw in the base frame whatever the heading).
//
// A segment whose motion follows a frame's x axis (its start -> end direction stays along it in
// every demo: a push along the box's way to its goal, a wipe along the goal's stroke) is also
// flagged with that frame, so its DMPs can be generalized there (one shape along its own
// direction).
#pragma once

#include "lfd_core/kinematics/pose.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace lfd {

/// A task's scene, in the robot's Cartesian frame: the objects where they are before the task
/// starts, by name, and the task's goal.
struct Scene {
  std::map<std::string, Pose> objects;
  Pose goal;
};

/// A frame attached to a scene. Names (as stored in skill libraries):
///   base              the Cartesian frame itself
///   start             the TCP pose when the task starts
///   object:<o>        object o's pose
///   goal              the goal pose
///   heading:<o>       at object o, x along the horizontal direction from o to the goal, z up
///   goal_heading:<o>  at the goal, the same axes as heading:<o>
/// "Up" is the Cartesian frame's z axis, "horizontal" its xy plane.
struct SceneFrame {
  enum class Kind { kBase, kStart, kObject, kGoal, kHeading, kGoalHeading };
  Kind kind = Kind::kBase;
  std::string object;  ///< for kObject, kHeading, kGoalHeading

  std::string name() const;
  /// Throws std::invalid_argument for an unknown name or a missing object name.
  static SceneFrame parse(const std::string& name);
  bool operator==(const SceneFrame& o) const { return kind == o.kind && object == o.object; }
};

struct FrameOptions {
  /// m: an object closer than this to the goal (horizontally) has no heading (1 mm of noise at
  /// 2 cm already turns it by 3 degrees).
  double min_heading_length = 0.02;
};

/// Every frame of a scene: base, start, goal, then object, heading and goal_heading of each
/// object (in name order).
std::vector<SceneFrame> candidateFrames(const Scene& scene);

/// Yaw of the horizontal direction from `from` to `to`. Throws std::invalid_argument when they
/// are less than `min_length` apart horizontally or not finite.
double headingYaw(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double min_length);

/// The heading yaw of object `object` in `scene` (its horizontal direction to the goal).
double sceneHeading(const Scene& scene, const std::string& object, const FrameOptions& options);

/// The yaw of a pose's x axis about the vertical; throws std::invalid_argument when the x axis is
/// closer to vertical than to horizontal (no yaw).
double poseYaw(const Pose& pose);

/// The pose of `frame` in a scene whose task starts with the TCP at `start`. Throws
/// std::invalid_argument naming a missing object or an undefined heading.
Pose framePose(const SceneFrame& frame, const Scene& scene, const Pose& start,
               const FrameOptions& options);

/// One demonstration of a segment.
struct SegmentDemoEnds {
  Scene scene;
  Pose task_start;     ///< TCP when the demo's task started
  Pose segment_start;  ///< TCP when the segment started
  Pose segment_end;    ///< TCP when it ended
};

/// How much a segment end varies across the demos in one frame (RMS about the mean; infinite
/// when the frame is undefined in some demo, e.g. a heading of an object left at its goal).
struct FrameSpread {
  SceneFrame frame;
  double position_m = 0.0;
  double orientation_rad = 0.0;
};

/// A learned segment goal: position offset in one frame, orientation offset in another.
struct SegmentGoalModel {
  SceneFrame position_frame;
  Eigen::Vector3d position_offset = Eigen::Vector3d::Zero();
  double position_spread = 0.0;  ///< m, RMS across the demos in that frame
  SceneFrame orientation_frame;
  Eigen::Quaterniond orientation_offset = Eigen::Quaterniond::Identity();
  double orientation_spread = 0.0;  ///< rad, RMS across the demos in that frame
  /// The frame whose x axis the segment's horizontal motion follows (none: the base frame):
  /// generalize there.
  std::optional<SceneFrame> motion_frame;
  double motion_spread = 0.0;  ///< rad, RMS angle between the motion and that frame's x axis
  std::vector<FrameSpread> candidates;  ///< every frame tried, for reports
};

struct FrameSelectionOptions {
  FrameOptions frames;
  /// rad: the RMS angle between a segment's horizontal motion and a frame's x axis below which the
  /// segment follows that frame.
  double heading_tolerance = 0.25;
  /// m: a segment that moves less than this horizontally in some demo follows no frame.
  double min_motion_length = 0.02;
  /// One-sided normal quantile: a frame whose position spread is within the sampling noise of
  /// the smallest one (RMS ratio <= exp(z / sqrt(demos - 1)): 2.1 for 6 demos, 1.8 for 9) explains
  /// the demos as well, and the frame whose origin the end lies nearest wins among those. A few
  /// noisy demos cannot tell a push's box from its goal when every box stood ~11 cm from its goal;
  /// the fist ends at the box. 0 = only equal spreads tie.
  double tie_z = 1.645;
};

/// Learns a segment's goal from its demos (at least one; the frames are those of the objects
/// every demo's scene names). Frames whose spreads are equal (within 10 um or urad + 0.1%; for
/// the position, within the sampling noise of options.tie_z) are told apart by the end's mean
/// distance from their origin: the nearer one is kept (what the skill ends at).
/// Throws std::invalid_argument on no demos or non-finite poses.
SegmentGoalModel learnSegmentGoal(const std::vector<SegmentDemoEnds>& demos,
                                  const FrameSelectionOptions& options);

/// The goal of a learned segment in a new scene. Throws std::invalid_argument like framePose.
Pose segmentGoal(const SegmentGoalModel& model, const Scene& scene, const Pose& start,
                 const FrameOptions& options);

/// Mean of unit quaternions: the principal eigenvector of sum q q^T (q and -q count alike).
/// Throws std::invalid_argument on an empty list.
Eigen::Quaterniond meanQuaternion(const std::vector<Eigen::Quaterniond>& qs);

}  // namespace lfd
