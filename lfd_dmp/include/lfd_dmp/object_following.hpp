// Goals that follow a moving object (issue 25, closed loop): which objects a running plan follows,
// for how long, and when one has moved enough to plan the rest of the motion anew
// (TaskPlanner::replan). ROS-free: executor_node.cpp looks the objects up on tf.
//
// An object is followed during the first segment whose goal frames name it (object:<o>,
// heading:<o>, ...), up to until_fraction of it: near its end the robot is at the object, and
// from then on the object moves because the robot moves it (a grasped block rides in the hand, a
// pushed box slides ahead of the fist, which touches it from 72% of the approach on in the
// teleop push). Following it then would chase the robot's own motion; and a goal moved that late
// could only be reached by a jerk.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "lfd_dmp/executor.hpp"

namespace lfd_dmp {

struct FollowOptions {
  bool enabled = true;
  double check_period = 0.05;    ///< s of sim time between two looks at the objects
  double min_shift = 0.005;      ///< m an object must move before the plan follows it
  double min_turn = 0.05;        ///< rad an object must turn before the plan follows it
  double lead = 0.2;             ///< s from a look to the start of the motion planned from it
  std::size_t max_replans = 10;  ///< per goal: an object that keeps moving is followed this often
  double until_fraction = 0.6;   ///< of the segment that reaches the object (see above)
};

/// Checks the options (positive periods and lead, non-negative thresholds); throws
/// std::invalid_argument naming the bad one.
void checkFollowOptions(const FollowOptions& options);

/// Until when (s into `plan`) each object named by a segment's goal frames is followed:
/// until_fraction into the first segment whose position, orientation or motion frame names it.
std::map<std::string, double> followWindows(const SkillLibrary& library, const ExecutionPlan& plan,
                                            const FollowOptions& options);

/// An object that moved away from where the plan has it.
struct ObjectMove {
  std::string object;
  double shift = 0.0;  ///< m
  double turn = 0.0;   ///< rad
};

/// The followed objects (window not over at `elapsed` s into the plan) that moved by at least
/// min_shift or turned by at least min_turn between `planned` and `now` (objects missing from
/// `now` are skipped: not seen is not moved).
std::vector<ObjectMove> movedObjects(const lfd::Scene& planned,
                                     const std::map<std::string, lfd::Pose>& now,
                                     const std::map<std::string, double>& windows, double elapsed,
                                     const FollowOptions& options);

/// "object 'block' moved 4.2 cm and turned 3 deg", for the result's list of replans.
std::string describeMoves(const std::vector<ObjectMove>& moves);

}  // namespace lfd_dmp
