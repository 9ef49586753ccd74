// Executor logic (ROS-free): turns a skill library and a new task situation into a checked joint
// trajectory. Paper II-D / III: every segment's DMP is generalized from the demonstrations to the
// segment's new goal, rolled out in sequence from the robot's current TCP pose (each segment starts
// where the previous one ended), converted to joint targets by the core IK (warm-started, joint
// limits, null-space posture; lfd_core's CartesianToJoints, shared with the demonstrator),
// and the gripper DMP is thresholded into open/close commands. The whole path is checked by IK
// BEFORE anything moves, so an unreachable goal is refused with the failing pose in the message.
// executor_node.cpp only adds ROS I/O and sim-time streaming.
#pragma once

#include "lfd_dmp/skill_library.hpp"

#include <lfd_core/cartesian_path.hpp>
#include <lfd_core/dmp_generalization.hpp>

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace lfd_dmp {

using TcpPose = lfd::Pose;  // position + unit quaternion, base_link

/// Which pose of the task situation a segment's goal is attached to.
enum class GoalReference { kObject, kGoal, kStart };
/// How the segment's goal orientation is chosen.
enum class OrientationRule {
  kObjectYaw,  ///< Rz(object yaw, symmetric: wrapped into (-pi/2, pi/2]) * gripper orientation
  kGoalYaw,    ///< Rz(goal yaw, same wrap) * gripper orientation
  kPushYaw,    ///< Rz(atan2 of the push direction) * gripper orientation (as the demonstrator)
  kStart,      ///< the TCP orientation at the start of the execution
  kLearned     ///< the generalized goal orientation of the demonstrations
};

/// Segment goal = reference position + offset (base_link axes) + along_push * d, where d is the
/// horizontal unit direction from the object to its goal.
struct SegmentGoalRule {
  std::string name;
  GoalReference reference = GoalReference::kGoal;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  double along_push = 0.0;
  OrientationRule orientation = OrientationRule::kLearned;
  std::string frame;  ///< SegmentTarget::frame
};

/// One rule per segment of the task's skill library, in order.
struct TaskGoalModel {
  std::string task;
  std::vector<SegmentGoalRule> segments;
};

/// The new situation, in base_link.
struct TaskSituation {
  Eigen::Vector3d object_position = Eigen::Vector3d::Zero();
  double object_yaw = 0.0;
  Eigen::Vector3d goal_position = Eigen::Vector3d::Zero();
  double goal_yaw = 0.0;
};

struct SegmentTarget {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Quaterniond> orientation;  ///< empty: the learned (generalized) goal
  /// Generalize in the heading frame of the named segment ("" = base_link): each demo's DMP is
  /// rotated about z so that that segment's start->goal direction (in xy) points along x,
  /// interpolated there, and rotated into the new heading of that segment. Why: a push stroke has
  /// the same shape in its own frame whatever its direction, while in base_link the forcing terms
  /// of pushes in different directions point different ways and their mix pushes the box sideways.
  std::string frame;
};

GoalReference parseGoalReference(const std::string& s);      ///< object | goal | start
OrientationRule parseOrientationRule(const std::string& s);  ///< object_yaw | goal_yaw | ...

/// Throws std::invalid_argument for a push-direction rule when object and goal coincide in xy.
std::vector<SegmentTarget> segmentTargets(const TaskGoalModel& model,
                                          const TaskSituation& situation, const TcpPose& start,
                                          const Eigen::Quaterniond& gripper_orientation);

/// Yaw of the horizontal direction from `from` to `to`; throws std::invalid_argument when their xy
/// distance is below `min_length` (the heading is then undefined).
double headingYaw(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double min_length);

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
  lfd::GeneralizationOptions generalization;
  double gripper_threshold_fraction = 0.5;
  double gripper_hysteresis = 0.05;
  double gripper_min_range = 0.005;
};

struct PlannedSegment {
  std::string name;
  size_t begin = 0, end = 0;  ///< samples [begin, end)
  double duration = 0.0;      ///< s
  TcpPose goal;               ///< goal pose given to the DMP
  std::vector<std::string> demos;
  bool outside_demo_range = false;
};

struct ExecutionPlan {
  std::vector<std::string> joint_names;
  double dt = 0.0;
  std::vector<double> times;            ///< s from the start
  std::vector<TcpPose> poses;           ///< planned TCP poses (base_link)
  std::vector<Eigen::VectorXd> joints;  ///< IK solution per sample
  std::vector<double> gripper;          ///< gripper DMP value per sample
  std::vector<GripperEvent> gripper_events;
  std::vector<PlannedSegment> segments;
  std::vector<std::string> warnings;
  double max_ik_position_error = 0.0;
  double max_ik_orientation_error = 0.0;
  double max_speed_ratio = 0.0;  ///< worst |dq/dt| / velocity limit
  double duration() const { return times.empty() ? 0.0 : times.back(); }
};

class TaskPlanner {
 public:
  /// `ik`: the robot's Cartesian->joint conversion (lfd::makeCartesianToJoints of robot.yaml).
  explicit TaskPlanner(const lfd::CartesianToJoints& ik);

  const lfd::KinematicChain& chain() const { return ik_.chain(); }
  TcpPose forward(const Eigen::VectorXd& q) const { return ik_.forward(q); }

  /// q_start: current joints of the chain. gripper_start: measured gripper value (recorded
  /// units), empty = the learned start. Throws std::invalid_argument on a library / target
  /// mismatch and std::runtime_error (naming segment, time and pose) when IK fails on the path.
  ExecutionPlan plan(const SkillLibrary& library, const std::vector<SegmentTarget>& targets,
                     const Eigen::VectorXd& q_start, std::optional<double> gripper_start,
                     const ExecutorOptions& options);

 private:
  lfd::CartesianToJoints ik_;
};

}  // namespace lfd_dmp
