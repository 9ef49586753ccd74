// Executor logic (ROS-free): turns a skill library and a new scene into a checked joint path.
// Paper II-D / III: every segment's goal is computed from the frame and offset the learner found
// in the demonstrations (lfd_core task_frames: no rule per task), its DMP is generalized from the
// demos to that goal (in the heading frame when the segment follows an object's way to the goal),
// rolled out in sequence from the robot's current TCP pose (each segment starts where the previous
// one ended), converted to joints by the core IK (lfd::CartesianToJoints, shared with the
// demonstrator), and the gripper DMP is thresholded into open/close events. Everything is checked
// BEFORE anything moves: a goal outside the demonstrated range or out of reach is refused with the
// segment, distance or failing pose in the message. executor_node.cpp only adds ROS I/O.
#pragma once

#include "lfd_dmp/skill_library.hpp"

#include <lfd_core/dmp/dmp_generalization.hpp>
#include <lfd_core/dmp/task_frames.hpp>
#include <lfd_core/kinematics/cartesian_path.hpp>

#include <Eigen/Geometry>

#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace lfd_dmp {

using TcpPose = lfd::Pose;  // position + unit quaternion, in the library's Cartesian frame

/// Generalize a segment in the frame its motion follows (learned: SegmentGoalModel::motion_frame):
/// each demo's DMP is rotated about z so that that frame's x axis (in the demo's scene) points
/// along x, interpolated there, and rotated into the frame's new yaw. Why: a push stroke has the
/// same shape in its own frame whatever its direction, while in the base frame the forcing terms
/// of pushes in different directions point different ways and their mix bends it.
struct HeadingFrame {
  std::string frame;
  double yaw = 0.0;                        ///< the new scene's heading
  std::map<std::string, double> demo_yaw;  ///< each demo's heading, by demo id
};

/// How far a segment's new goal frames lie from the demonstrated ones: the position frame's origin
/// from the convex hull of the demos' origins (and its rotation as far as it moves the learned
/// offset: angle x offset length), the orientation frame's rotation (as a rotation vector about
/// the demos' mean) from the hull of theirs. What the goal is learned relative to decides what
/// "demonstrated" means: a push along a demonstrated heading, starting where boxes started, is
/// inside even if the fist ends somewhere no demo's did.
struct DemoRange {
  std::string frame;             ///< the frame (of the segment's two) farthest outside
  double distance = 0.0;         ///< m
  double angle = 0.0;            ///< rad
  double distance_margin = 0.0;  ///< m allowed
  double angle_margin = 0.0;     ///< rad allowed
  bool outside() const { return distance > distance_margin || angle > angle_margin; }
};

struct SegmentTarget {
  std::string name;
  TcpPose goal;
  std::string frames;  ///< "<position frame> / <orientation frame>", for reports
  std::optional<HeadingFrame> heading;
  DemoRange range;
  /// m from the convex hull of the demos' goal positions, and the margin beyond which the local
  /// linear fit would extrapolate the motion's shape (the kernel average is used there instead).
  double shape_distance = 0.0, shape_margin = 0.0;
};

/// A change of the thresholded gripper state at `sample` (close = true).
struct GripperEvent {
  size_t sample = 0;
  bool close = false;
};

/// Thresholds a gripper DMP trajectory at `fraction` of its range (min + fraction * (max - min)),
/// with a hysteresis of `hysteresis` x range. The first event (sample 0) sets the initial state,
/// then one event per crossing; a range below `min_range` emits nothing (gripper left alone).
std::vector<GripperEvent> gripperEvents(const std::vector<double>& values, double fraction,
                                        double hysteresis, double min_range);

struct ExecutorOptions {
  double dt = 0.002;              ///< s between planned samples (500 Hz)
  double duration_scale = 1.0;    ///< multiplies every generalized segment duration
  bool all_segment_goals = true;  ///< generalize over all segment goals (task via-points) of a demo
  lfd::GeneralizationOptions generalization;  ///< range_margin: fraction of the demos' spread
  double min_range_margin = 0.02;    ///< m: the smallest distance margin (demos in one place)
  double min_range_angle = 0.1;      ///< rad: the smallest angle margin
  bool allow_extrapolation = false;  ///< plan goals outside the demonstrated range anyway
  lfd::FrameOptions frames;
  bool heading_frames = true;   ///< generalize segments along the frame their motion follows
  size_t max_samples = 100000;  ///< planned samples (memory and time bound of one plan)
  double gripper_threshold_fraction = 0.5;
  double gripper_hysteresis = 0.05;
  double gripper_min_range = 0.005;
  /// 1/normalized time: a goal that moves while its segment runs (TargetUpdate) is followed with
  /// the time constant tau / goal_filter (lfd::SegmentRolloutOptions::goal_filter)
  double goal_filter = 10.0;
  /// Plan from this segment on (a retry after a recovery, lfd_dmp/recovery.hpp): the earlier
  /// segments were done before; they stay in the plan, empty (no samples, 0 s), so that segment
  /// indices still match the library's and its sensory signature's.
  size_t first_segment = 0;
};

/// Segment targets that take effect `time` s into a plan (an object moved): a segment starting
/// later is generalized toward them, a segment running then moves its DMP's goal to them.
struct TargetUpdate {
  double time = 0.0;
  std::vector<SegmentTarget> targets;
};

/// A goal outside the demonstrated range when extrapolation is not allowed.
class OutsideDemoRange : public std::invalid_argument {
 public:
  OutsideDemoRange(const std::string& what, double distance, double angle)
      : std::invalid_argument(what), distance(distance), angle(angle) {}
  double distance;  ///< m, the largest DemoRange::distance of the segments
  double angle;     ///< rad, the largest DemoRange::angle
};

/// Planning stopped because the caller cancelled it.
class PlanningCancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PlannedSegment {
  std::string name;
  std::string frames;
  size_t begin = 0, end = 0;  ///< samples [begin, end)
  double duration = 0.0;      ///< s
  TcpPose goal;               ///< goal pose given to the DMP
  std::vector<std::string> demos;
  /// The ridge of its local linear fit (GeneralizationResult::slope_ridge); -1 = kernel average.
  double slope_ridge = -1.0;
};

struct ExecutionPlan {
  std::vector<std::string> joint_names;
  double dt = 0.0;
  std::vector<double> times;            ///< s from the start
  std::vector<TcpPose> poses;           ///< planned TCP poses (Cartesian frame)
  std::vector<Eigen::VectorXd> joints;  ///< IK solution per sample
  std::vector<double> gripper;          ///< gripper DMP value per sample
  std::vector<GripperEvent> gripper_events;
  std::vector<PlannedSegment> segments;
  std::vector<std::string> warnings;
  double extrapolation_distance = 0.0;  ///< m, largest DemoRange::distance of the segments
  double extrapolation_angle = 0.0;     ///< rad, largest DemoRange::angle
  bool outside_demo_range = false;
  double max_ik_position_error = 0.0;
  double max_ik_orientation_error = 0.0;
  double max_speed_ratio = 0.0;  ///< worst |dq/dt| / velocity limit
  double duration() const { return times.empty() ? 0.0 : times.back(); }
};

/// The goal of every segment of `library` in `scene` for a task starting with the TCP at `start`:
/// its learned frames and offsets, the heading frame it is generalized in, and how far it lies
/// from what was demonstrated (DemoRange; the shape distance). Throws std::invalid_argument when
/// the library has no learned goals (relearn it) or the scene lacks what a frame needs (an object,
/// a defined heading).
std::vector<SegmentTarget> segmentTargets(const SkillLibrary& library, const lfd::Scene& scene,
                                          const TcpPose& start, const ExecutorOptions& options,
                                          std::vector<std::string>* warnings);

class TaskPlanner {
 public:
  /// `ik`: the robot's Cartesian->joint conversion (lfd::makeCartesianToJoints of robot.yaml).
  explicit TaskPlanner(const lfd::CartesianToJoints& ik);

  const lfd::KinematicChain& chain() const { return ik_.chain(); }
  TcpPose forward(const Eigen::VectorXd& q) const { return ik_.forward(q); }

  /// q_start: current joints of the chain. gripper_start: measured gripper value (recorded
  /// units), empty = the learned start. `cancelled` is polled between pieces of work (throws
  /// PlanningCancelled when it returns true). Throws OutsideDemoRange (goal outside the demos'
  /// range, unless options.allow_extrapolation), std::invalid_argument on a library / target
  /// mismatch or a plan over options.max_samples, and std::runtime_error (naming segment, time
  /// and pose) when IK fails on the path.
  ExecutionPlan plan(const SkillLibrary& library, const std::vector<SegmentTarget>& targets,
                     const Eigen::VectorXd& q_start, std::optional<double> gripper_start,
                     const ExecutorOptions& options,
                     const std::function<bool()>& cancelled = nullptr);

  /// The plan of `plan(targets)` as it becomes when `updates` (increasing times) take effect:
  /// identical up to each update's time; a segment running then keeps its DMP and follows its
  /// moved goal through options.goal_filter (position, velocity and acceleration continuous);
  /// every later segment is generalized toward the updated targets. IK is solved only from the
  /// last update on: the joints before it are `current`'s (the plan the robot is following).
  /// Throws as plan() does, and std::invalid_argument on updates out of order or of the wrong
  /// size.
  ExecutionPlan replan(const SkillLibrary& library, const std::vector<SegmentTarget>& targets,
                       const std::vector<TargetUpdate>& updates, const ExecutionPlan& current,
                       const Eigen::VectorXd& q_start, std::optional<double> gripper_start,
                       const ExecutorOptions& options,
                       const std::function<bool()>& cancelled = nullptr);

 private:
  lfd::CartesianToJoints ik_;
};

}  // namespace lfd_dmp
