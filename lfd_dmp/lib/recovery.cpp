#include "lfd_dmp/recovery.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace lfd_dmp {

namespace {

// The objects a segment's goal frames name (position, orientation, motion frame).
std::set<std::string> objectsOf(const SegmentSkills& segment) {
  std::set<std::string> out;
  if (!segment.goal) return out;
  const lfd::SegmentGoalModel& g = *segment.goal;
  for (const lfd::SceneFrame* f : {&g.position_frame, &g.orientation_frame})
    if (!f->object.empty()) out.insert(f->object);
  if (g.motion_frame && !g.motion_frame->object.empty()) out.insert(g.motion_frame->object);
  return out;
}

bool shareAny(const std::set<std::string>& a, const std::set<std::string>& b) {
  return std::any_of(a.begin(), a.end(), [&](const std::string& o) { return b.count(o) > 0; });
}

// The plan's first segment with samples (the earlier ones were done before it).
std::size_t firstPlanned(const ExecutionPlan& plan) {
  std::size_t s = 0;
  while (s + 1 < plan.segments.size() && plan.segments[s].end == plan.segments[s].begin) ++s;
  return s;
}

std::size_t segmentOfSample(const ExecutionPlan& plan, std::size_t sample) {
  for (std::size_t s = 0; s < plan.segments.size(); ++s)
    if (sample < plan.segments[s].end) return s;
  return plan.segments.empty() ? 0 : plan.segments.size() - 1;
}

// The latest gripper event at or before `sample`, or null.
const GripperEvent* lastEvent(const ExecutionPlan& plan, std::size_t sample) {
  const GripperEvent* last = nullptr;
  for (const GripperEvent& e : plan.gripper_events)
    if (e.sample <= sample) last = &e;
  return last;
}

// s(tau) of a min-jerk move, and its peak of ds/dtau (at tau = 0.5).
double minJerk(double tau) {
  return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
}
constexpr double kMinJerkPeak = 1.875;
// Of the expected reading: below it a reading of either sign is "nothing" (a sensor's noise
// around rest).
constexpr double kNearlyNothing = 0.25;

}  // namespace

void checkRecoveryOptions(const RecoveryOptions& o) {
  if (!(o.retreat_speed_fraction > 0.0 && o.retreat_speed_fraction <= 1.0))
    throw std::invalid_argument("recovery/retreat_speed_fraction must be in (0, 1]");
  for (const auto& [value, name] :
       {std::pair{o.min_retreat_duration, "min_retreat_duration"},
        std::pair{o.release_time, "release_time"}, std::pair{o.settle_time, "settle_time"},
        std::pair{o.min_hold_time, "min_hold_time"},
        std::pair{o.min_held_opening, "min_held_opening"}})
    if (!(value >= 0.0) || !std::isfinite(value))
      throw std::invalid_argument(std::string("recovery/") + name + " must be finite and >= 0");
}

bool gripperClosedAt(const ExecutionPlan& plan, std::size_t sample) {
  const GripperEvent* e = lastEvent(plan, sample);
  return e && e->close;
}

bool lostGrasp(const lfd::Deviation& alarm, const ExecutionPlan& plan,
               const RecoveryOptions& options, double closed_opening) {
  if (plan.times.empty() || !(plan.dt > 0.0) || !std::isfinite(alarm.time)) return false;
  const double samples = std::max(0.0, alarm.time / plan.dt);
  const std::size_t sample =
      std::min(plan.times.size() - 1, static_cast<std::size_t>(std::lround(samples)));
  const GripperEvent* closed = lastEvent(plan, sample);
  // Less on the same side of rest, or nearly nothing: an empty hand. A reading of the other sign
  // (the wrist pressed up where it carried a weight) is something else.
  const bool less = std::abs(alarm.measured) < std::abs(alarm.expected) &&
                    (alarm.measured * alarm.expected >= 0.0 ||
                     std::abs(alarm.measured) < kNearlyNothing * std::abs(alarm.expected));
  const bool holds = sample < plan.gripper.size() &&
                     plan.gripper[sample] - closed_opening >= options.min_held_opening;
  return closed && closed->close && holds &&
         alarm.time - plan.times[closed->sample] >= options.min_hold_time && less;
}

std::size_t retrySegment(const SkillLibrary& library, const ExecutionPlan& plan,
                         std::size_t sample) {
  const std::size_t first = firstPlanned(plan);
  const GripperEvent* closed = lastEvent(plan, sample);
  if (!closed || !closed->close || library.segments.size() != plan.segments.size()) return first;
  std::size_t s = segmentOfSample(plan, closed->sample);
  // The segment where it closed may be a move toward the goal (it closes at the boundary): then
  // the latest segment before it that reaches for an object.
  while (s > first && objectsOf(library.segments[s]).empty()) --s;
  const std::set<std::string> held = objectsOf(library.segments[s]);
  while (s > first && shareAny(objectsOf(library.segments[s - 1]), held)) --s;
  return std::max(s, first);
}

ExecutionPlan retreatPlan(const TaskPlanner& planner, const Eigen::VectorXd& from,
                          const Eigen::VectorXd& to, double dt, const RecoveryOptions& options) {
  checkRecoveryOptions(options);
  const Eigen::VectorXd& limits = planner.chain().velocityLimits();
  if (from.size() != limits.size() || to.size() != limits.size())
    throw std::invalid_argument("retreatPlan: joint vectors of the wrong size");
  if (!(dt > 0.0)) throw std::invalid_argument("retreatPlan: dt must be > 0");
  double duration = options.min_retreat_duration;
  for (Eigen::Index j = 0; j < limits.size(); ++j)
    if (limits[j] > 0.0)
      duration = std::max(duration, kMinJerkPeak * std::abs(to[j] - from[j]) /
                                        (options.retreat_speed_fraction * limits[j]));
  ExecutionPlan plan;
  plan.joint_names = planner.chain().jointNames();
  plan.dt = dt;
  const auto n = static_cast<std::size_t>(std::ceil(duration / dt)) + 1;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = std::min(duration, static_cast<double>(k) * dt);
    const Eigen::VectorXd q = from + minJerk(t / duration) * (to - from);
    plan.times.push_back(t);
    plan.joints.push_back(q);
    plan.poses.push_back(planner.forward(q));
    plan.gripper.push_back(0.0);
  }
  PlannedSegment s;
  s.name = "recovery";
  s.frames = "joints";
  s.end = n;
  s.duration = plan.times.back();
  s.goal = plan.poses.back();
  plan.segments.push_back(s);
  return plan;
}

}  // namespace lfd_dmp
