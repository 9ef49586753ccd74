// Recovery after a failed grasp or a drop (issue 25, closed loop): when the execution monitor
// finds the hand empty where the demonstrations held something, the executor opens the gripper,
// goes back to the last boundary that held (the start of the segment that reached for the object),
// looks at the objects again and plans the task from there, a bounded number of times.
// ROS-free: executor_node.cpp sends the motions and looks the objects up on tf.
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Core>

#include "lfd_core/dmp/sensory_signature.hpp"
#include "lfd_dmp/executor.hpp"

namespace lfd_dmp {

struct RecoveryOptions {
  bool enabled = true;
  std::size_t max_attempts = 2;  ///< retries per goal; then the alarm fails the goal
  /// Of each joint's velocity limit, at the peak of the retreat (a min-jerk move in joint space):
  /// slow enough that the arm's controller tracks it closely on the way back.
  double retreat_speed_fraction = 0.25;
  double min_retreat_duration = 1.0;  ///< s
  double release_time = 0.5;          ///< s the gripper is given to open before the arm moves
  double settle_time = 0.5;  ///< s after the retreat before the objects are looked at again
  /// s from the gripper's close command before an empty hand is a lost grasp: the fingers take
  /// time to close and load the pads (a reproduction's pads loaded up to 0.47 s after the
  /// command where the demonstrations' had already; a retry then would undo a good grasp).
  double min_hold_time = 1.0;
  /// m between the pads, beyond the closing command's opening, that the plan's closed gripper
  /// (learned from the demonstrations' fingers) keeps where the hand should hold something: the
  /// fingers stopped on an object. A plan that closes them fully (a fist that pushes or wipes)
  /// holds nothing, and a light pad there is no lost grasp.
  double min_held_opening = 0.005;
};

/// Throws std::invalid_argument naming the option out of range (fraction in (0, 1], the times
/// finite and >= 0).
void checkRecoveryOptions(const RecoveryOptions& options);

/// Whether the plan holds the gripper closed at `sample` (its last gripper event at or before it
/// closes it).
bool gripperClosedAt(const ExecutionPlan& plan, std::size_t sample);

/// Whether `alarm` (a deviation from the sensory signature, at alarm.time s into `plan`) means
/// the hand lost, or never got, what it should hold: the plan holds the gripper closed then, for
/// at least options.min_hold_time since its close command, on something (its opening at least
/// options.min_held_opening beyond `closed_opening`, the robot's closing command, m), and the
/// sensor reads less than the demonstrations did, on the same side of zero or nearly nothing (the
/// pads unloaded, the weight gone from the wrist). More than expected (a yank, a collision), or
/// the other sign (pressed where it should carry), is no lost grasp: a retry would not help.
bool lostGrasp(const lfd::Deviation& alarm, const ExecutionPlan& plan,
               const RecoveryOptions& options, double closed_opening = 0.0);

/// The segment to retry from after a grasp lost at `sample`: the last boundary that held is the
/// start of the segment that reached for the object, i.e. of the run of segments whose goal frames
/// name the object the gripper closed on (the segment where it closed, or the latest one before it
/// that names an object). Never before plan's first planned segment.
std::size_t retrySegment(const SkillLibrary& library, const ExecutionPlan& plan,
                         std::size_t sample);

/// A joint-space min-jerk move from `from` to `to` (no Cartesian segments: one segment named
/// "recovery"), at most options.retreat_speed_fraction of each joint's velocity limit, sampled
/// every `dt` s, with the TCP poses of `planner`'s chain.
ExecutionPlan retreatPlan(const TaskPlanner& planner, const Eigen::VectorXd& from,
                          const Eigen::VectorXd& to, double dt, const RecoveryOptions& options);

}  // namespace lfd_dmp
