#include "lfd_dmp/executor.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

namespace lfd_dmp {
namespace {

// IK is solved in pieces of this many samples, so a cancel is seen within ~1 ms of work.
constexpr size_t kIkChunk = 250;

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream o;
  o.precision(3);
  o << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return o.str();
}

Eigen::Matrix3d yawMatrix(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// Per demo id: concatenated goal parameters of every segment (the task's via-points), for the demos
// present in every segment.
std::map<std::string, Eigen::VectorXd> allSegmentParameters(const SkillLibrary& lib) {
  std::map<std::string, std::vector<Eigen::VectorXd>> per_demo;
  for (const SegmentSkills& seg : lib.segments)
    for (const DemoSkill& d : seg.demos) per_demo[d.demo_id].push_back(d.parameters);
  std::map<std::string, Eigen::VectorXd> out;
  for (const auto& [id, parts] : per_demo) {
    if (parts.size() != lib.segments.size()) continue;
    Eigen::Index n = 0;
    for (const auto& p : parts) n += p.size();
    Eigen::VectorXd v(n);
    Eigen::Index k = 0;
    for (const auto& p : parts) {
      v.segment(k, p.size()) = p;
      k += p.size();
    }
    out[id] = v;
  }
  return out;
}

// The frame a segment is generalized in (its motion follows the frame's x axis): the frame's yaw
// in the new scene and in each demo's.
HeadingFrame headingFrame(const SkillLibrary& lib, const SegmentSkills& seg,
                          const lfd::Scene& scene, const TcpPose& start,
                          const lfd::FrameOptions& frames, std::vector<std::string>* warnings) {
  const lfd::SceneFrame& frame = *seg.goal->motion_frame;
  HeadingFrame h;
  h.frame = frame.name();
  h.yaw = lfd::poseYaw(lfd::framePose(frame, scene, start, frames));
  for (const DemoSkill& d : seg.demos) {
    const auto it = lib.demo_scenes.find(d.demo_id);
    if (it == lib.demo_scenes.end()) continue;
    try {
      h.demo_yaw[d.demo_id] =
          lfd::poseYaw(lfd::framePose(frame, it->second.scene, it->second.start, frames));
    } catch (const std::invalid_argument& e) {
      warnings->push_back("segment '" + seg.name + "': demo " + d.demo_id + " left out of " +
                          h.frame + ": " + e.what());
    }
  }
  if (h.demo_yaw.empty())
    throw std::invalid_argument("segment '" + seg.name + "': no demo has a defined " + h.frame +
                                " (the library's demo_scenes)");
  return h;
}

// The convex hull distance of `q` from the columns of `points` and the margin allowed: a fraction
// of their spread, at least `floor`.
std::pair<double, double> hullRange(const Eigen::MatrixXd& points, const Eigen::VectorXd& q,
                                    double fraction, double floor) {
  double diameter = 0.0;
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    for (Eigen::Index j = 0; j < i; ++j)
      diameter = std::max(diameter, (points.col(i) - points.col(j)).norm());
  return {lfd::convexHullDistance(points, q), std::max(fraction * diameter, floor)};
}

// Where the motion's shape would be extrapolated: the goal from the hull of the demos' goals.
void shapeRange(const SegmentSkills& seg, const ExecutorOptions& options, SegmentTarget* t) {
  Eigen::MatrixXd points(3, static_cast<Eigen::Index>(seg.demos.size()));
  for (size_t j = 0; j < seg.demos.size(); ++j)
    points.col(static_cast<Eigen::Index>(j)) = seg.demos[j].dmp.position->goal();
  std::tie(t->shape_distance, t->shape_margin) = hullRange(
      points, t->goal.position, options.generalization.range_margin, options.min_range_margin);
}

// How far the new pose of `frame` lies from its poses in the demos' scenes (the base frame has
// none). A position is learned as an offset in the frame: its origin counts, and its rotation as
// far as it moves that offset (angle x offset length, m). An orientation: only the rotation (rad).
DemoRange frameRange(const SkillLibrary& lib, const lfd::SceneFrame& frame, const lfd::Pose& now,
                     std::optional<double> position_offset, const ExecutorOptions& options) {
  DemoRange r;
  r.frame = frame.name();
  std::vector<lfd::Pose> demo;
  for (const auto& [id, d] : lib.demo_scenes) {
    try {
      demo.push_back(lfd::framePose(frame, d.scene, d.start, options.frames));
    } catch (const std::invalid_argument&) {  // undefined in that demo: not a demonstrated pose
    }
  }
  if (frame.kind == lfd::SceneFrame::Kind::kBase || demo.empty()) return r;
  Eigen::MatrixXd origins(3, static_cast<Eigen::Index>(demo.size())), rotations = origins;
  std::vector<Eigen::Quaterniond> qs;
  for (const lfd::Pose& p : demo) qs.push_back(p.orientation);
  const Eigen::Quaterniond mean = lfd::meanQuaternion(qs);
  // Rotation vectors about the mean: a hull in 3-D, sign-safe for spreads below half a turn.
  auto vec = [&](const Eigen::Quaterniond& q) {
    Eigen::Quaterniond d = mean.conjugate() * q;
    if (d.w() < 0.0) d.coeffs() = -d.coeffs();
    const Eigen::AngleAxisd aa(d);
    return Eigen::Vector3d(aa.angle() * aa.axis());
  };
  for (size_t j = 0; j < demo.size(); ++j) {
    origins.col(static_cast<Eigen::Index>(j)) = demo[j].position;
    rotations.col(static_cast<Eigen::Index>(j)) = vec(demo[j].orientation);
  }
  const auto& g = options.generalization;
  std::tie(r.angle, r.angle_margin) =
      hullRange(rotations, vec(now.orientation), g.range_margin, options.min_range_angle);
  if (!position_offset) return r;
  std::tie(r.distance, r.distance_margin) =
      hullRange(origins, now.position, g.range_margin, options.min_range_margin);
  r.distance = std::max(r.distance, r.angle * *position_offset);
  r.angle = 0.0;  // counted through the offset it moves
  return r;
}

// The frame (of the two) farther outside its demonstrated range, relative to its margins.
DemoRange worse(const DemoRange& a, const DemoRange& b) {
  auto ratio = [](const DemoRange& r) {
    return std::max(r.distance / std::max(r.distance_margin, 1e-12),
                    r.angle / std::max(r.angle_margin, 1e-12));
  };
  return ratio(b) > ratio(a) ? b : a;
}

void checkLibrary(const SkillLibrary& library) {
  if (library.segments.empty()) throw std::invalid_argument("the skill library has no segments");
  if (library.generalization_parameters != "goal_position")
    throw std::invalid_argument("unsupported generalization_parameters '" +
                                library.generalization_parameters + "' (need goal_position)");
  for (const SegmentSkills& seg : library.segments) {
    if (!seg.goal)
      throw std::invalid_argument(
          "segment '" + seg.name +
          "' of the skill library has no learned goal (learned without the demos' scenes): "
          "relearn it from bags whose metadata holds the scene");
    if (seg.demos.empty())
      throw std::invalid_argument("segment '" + seg.name + "' has no demonstration");
    for (const DemoSkill& d : seg.demos)
      if (!d.dmp.position || d.dmp.position->dims() != 3)
        throw std::invalid_argument("segment '" + seg.name + "' has no 3-D position DMP");
  }
}

// Refuses a goal outside the demonstrated range unless extrapolation is allowed.
// `first`: the segments before it are not planned (ExecutorOptions::first_segment).
void checkRange(const std::vector<SegmentTarget>& all, size_t first, bool allow,
                ExecutionPlan* plan) {
  const SegmentTarget* worst = nullptr;
  const std::vector<SegmentTarget> targets(
      all.begin() + static_cast<long>(std::min(first, all.size())), all.end());
  for (const SegmentTarget& t : targets) {
    plan->extrapolation_distance = std::max(plan->extrapolation_distance, t.range.distance);
    plan->extrapolation_angle = std::max(plan->extrapolation_angle, t.range.angle);
    if (t.range.outside() && !worst) worst = &t;
  }
  if (!worst) return;
  plan->outside_demo_range = true;
  const DemoRange& r = worst->range;
  std::ostringstream m;
  m.precision(3);
  m << "segment '" << worst->name << "': its frame " << r.frame << " lies " << r.distance
    << " m and " << r.angle << " rad from where the demonstrations had it (allowed "
    << r.distance_margin << " m, " << r.angle_margin
    << " rad: ~generalization/range_margin x their spread, at least "
    << "~min_range_margin, ~min_range_angle)";
  if (!allow)
    throw OutsideDemoRange(m.str() +
                               "; outside the demonstrated range (set allow_extrapolation "
                               "to run it anyway)",
                           plan->extrapolation_distance, plan->extrapolation_angle);
  plan->warnings.push_back(m.str() + "; run anyway (allow_extrapolation)");
}

// Samples of one generalized segment appended to the plan (each later segment starts where the
// previous ended: its duplicate first sample is skipped).
void appendRollout(const lfd::SegmentTrajectory& traj, bool first, double t_offset,
                   const Eigen::Quaterniond& hold, std::optional<double> gripper,
                   ExecutionPlan* plan) {
  for (Eigen::Index k = first ? 0 : 1; k < traj.times.size(); ++k) {
    TcpPose p;
    p.position = traj.positions.row(k).transpose();
    p.orientation = traj.quaternions.cols() == 4
                        ? Eigen::Quaterniond(traj.quaternions(k, 0), traj.quaternions(k, 1),
                                             traj.quaternions(k, 2), traj.quaternions(k, 3))
                              .normalized()
                        : hold;
    plan->times.push_back(t_offset + traj.times[k]);
    plan->poses.push_back(p);
    plan->gripper.push_back(traj.gripper.size() ? traj.gripper[k] : gripper.value_or(0.0));
  }
}

void checkPlanRequest(const SkillLibrary& library, const std::vector<SegmentTarget>& targets,
                      const Eigen::VectorXd& q_start, Eigen::Index dof,
                      const ExecutorOptions& options) {
  if (library.segments.empty()) throw std::invalid_argument("the skill library has no segments");
  if (targets.size() != library.segments.size()) {
    std::ostringstream m;
    m << "the skill library '" << library.task << "' has " << library.segments.size()
      << " segments but " << targets.size() << " segment goals were given";
    throw std::invalid_argument(m.str());
  }
  if (q_start.size() != dof)
    throw std::invalid_argument("start joint vector has " + std::to_string(q_start.size()) +
                                " values, the IK chain has " + std::to_string(dof));
  if (!(options.dt > 0.0) || !(options.duration_scale > 0.0) ||
      !std::isfinite(options.duration_scale))
    throw std::invalid_argument("dt and duration_scale must be finite and > 0");
  if (options.first_segment >= library.segments.size())
    throw std::invalid_argument("first_segment " + std::to_string(options.first_segment) +
                                " is past the library's " +
                                std::to_string(library.segments.size()) + " segments");
}

// What each segment generalizes over: its own goal, or every segment's goal together
// (options.all_segment_goals), with the demos' parameters to match.
struct GoalQuery {
  std::map<std::string, Eigen::VectorXd> all_params;
  bool use_all = false;
  Eigen::VectorXd all_query;
};

GoalQuery goalQuery(const SkillLibrary& library, const std::vector<SegmentTarget>& targets,
                    bool all_segment_goals) {
  GoalQuery g;
  g.all_params = allSegmentParameters(library);
  g.use_all = all_segment_goals && !g.all_params.empty();
  if (g.use_all) {
    g.all_query.resize(3 * static_cast<Eigen::Index>(targets.size()));
    for (size_t s = 0; s < targets.size(); ++s)
      g.all_query.segment<3>(3 * s) = targets[s].goal.position;
  }
  return g;
}

// One segment's DMP for its target, mixed from the demos that can serve it (records which in
// `planned`).
lfd::GeneralizationResult generalizeForTarget(const SegmentSkills& seg, const SegmentTarget& target,
                                              const GoalQuery& goals,
                                              const ExecutorOptions& options,
                                              PlannedSegment& planned, ExecutionPlan& plan) {
  std::vector<lfd::SegmentDmp> dmps;
  std::vector<Eigen::VectorXd> params;
  const HeadingFrame* heading = target.heading ? &*target.heading : nullptr;
  for (const DemoSkill& d : seg.demos) {
    if (heading && !heading->demo_yaw.count(d.demo_id)) continue;
    if (goals.use_all) {
      const auto it = goals.all_params.find(d.demo_id);
      if (it == goals.all_params.end()) continue;
      params.push_back(it->second);
    } else {
      params.push_back(d.parameters);
    }
    dmps.push_back(heading ? d.dmp.rotated(yawMatrix(-heading->demo_yaw.at(d.demo_id))) : d.dmp);
    planned.demos.push_back(d.demo_id);
  }
  if (dmps.empty())
    throw std::invalid_argument("segment '" + seg.name + "' has no usable demonstration");
  const Eigen::VectorXd query =
      goals.use_all ? goals.all_query : Eigen::VectorXd(target.goal.position);
  // Beyond the demos' goals the local linear fit would extrapolate the motion's shape (a teleop
  // approach to a side demonstrated once swept through the box); the kernel average is a convex
  // mix of demonstrated shapes, only its end moves to the new goal.
  lfd::GeneralizationOptions gen_options = options.generalization;
  if (target.shape_distance > target.shape_margin) {
    gen_options.local_linear = false;
    plan.warnings.push_back("segment '" + seg.name +
                            "': its goal lies beyond the demos' goals: "
                            "generalized by the kernel average");
  }
  // The demos' sub-motions come at the same phases (the learner aligned their timing), so
  // their mix keeps them: a wipe's three strokes stay three full strokes.
  lfd::GeneralizationResult gen = lfd::generalizeSegment(dmps, params, query, gen_options);
  if (heading) gen.dmp = gen.dmp.rotated(yawMatrix(heading->yaw));
  if (gen_options.local_linear) planned.slope_ridge = gen.slope_ridge;
  return gen;
}

// Where the previous segment left the tool: the next one starts there.
struct RolloutState {
  Eigen::Vector3d position;
  Eigen::Quaterniond orientation;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  std::optional<double> gripper;
  double t_offset = 0.0;
  double samples = 0.0;
};

lfd::SegmentRolloutOptions rolloutOptions(const lfd::SegmentDmp& dmp, const SegmentTarget& target,
                                          const ExecutorOptions& options, RolloutState& state) {
  lfd::SegmentRolloutOptions ro;
  ro.dt = options.dt;
  ro.tau = dmp.tau * options.duration_scale;
  // Refuse before allocating: the rollout, IK and trajectory all grow with the samples.
  state.samples += *ro.tau / options.dt;
  if (!(state.samples <= static_cast<double>(options.max_samples))) {
    std::ostringstream m;
    m << "the plan would have over " << options.max_samples << " samples ("
      << state.t_offset + *ro.tau << " s at dt " << options.dt
      << " s): over the limit (~limits/max_plan_seconds; duration_scale " << options.duration_scale
      << ")";
    throw std::invalid_argument(m.str());
  }
  ro.start_position = Eigen::VectorXd(state.position);
  ro.goal_position = Eigen::VectorXd(target.goal.position);
  ro.start_velocity = Eigen::VectorXd(state.velocity);
  if (dmp.orientation) {
    ro.start_orientation = state.orientation;
    ro.start_angular_velocity = Eigen::Vector3d::Zero();
    ro.goal_orientation = target.goal.orientation;
  }
  if (dmp.gripper && state.gripper) ro.start_gripper = *state.gripper;
  return ro;
}

// Reachability of the WHOLE path before anything moves, in pieces (a cancel is seen between):
// from sample `from` on (the joints before it are the plan's already, `seed` the last of them or
// the start).
void solveIk(lfd::CartesianToJoints& ik, const Eigen::VectorXd& seed_joints, size_t from,
             const std::function<void(const std::string&)>& poll, ExecutionPlan& plan) {
  Eigen::VectorXd seed = seed_joints;
  plan.joints.resize(from);
  plan.joints.reserve(plan.poses.size());
  for (const PlannedSegment& ps : plan.segments) {
    for (size_t a = std::max(ps.begin, from); a < ps.end; a += kIkChunk) {
      poll("IK of segment " + ps.name);
      std::vector<lfd::TimedPose> samples;
      for (size_t k = a; k < std::min(ps.end, a + kIkChunk); ++k)
        samples.push_back({plan.times[k], plan.poses[k]});
      lfd::JointPath path;
      try {
        path = ik.convert(samples, seed);
      } catch (const std::exception& e) {
        throw std::runtime_error("unreachable in segment '" + ps.name + "' (goal " +
                                 vec(ps.goal.position) + "): " + e.what());
      }
      plan.max_ik_position_error = std::max(plan.max_ik_position_error, path.max_position_error);
      plan.max_ik_orientation_error =
          std::max(plan.max_ik_orientation_error, path.max_orientation_error);
      plan.max_speed_ratio = std::max(plan.max_speed_ratio, path.max_speed_ratio);
      for (Eigen::VectorXd& q : path.positions) plan.joints.push_back(std::move(q));
      seed = plan.joints.back();
    }
  }
}

// Which targets are in force at `t` s into the plan: 1 + the last update at or before it, 0 for
// the plan's own targets (the index into a list of every target set, those first).
size_t targetSetAt(const std::vector<TargetUpdate>& updates, double t) {
  size_t in_force = 0;
  for (size_t u = 0; u < updates.size(); ++u)
    if (updates[u].time <= t) in_force = u + 1;
  return in_force;
}

// The goal switches of a segment running from `begin` for `duration` s: the updates that fall
// inside it, at their times into it.
std::vector<lfd::GoalSwitch> switchesDuring(const std::vector<TargetUpdate>& updates, size_t s,
                                            double begin, double duration, bool orientation) {
  std::vector<lfd::GoalSwitch> out;
  for (const TargetUpdate& u : updates) {
    if (u.time <= begin || u.time >= begin + duration) continue;
    lfd::GoalSwitch g;
    g.time = u.time - begin;
    g.goal.position = Eigen::VectorXd(u.targets[s].goal.position);
    if (orientation) g.goal.orientation = u.targets[s].goal.orientation;
    out.push_back(g);
  }
  return out;
}

void checkUpdates(const std::vector<TargetUpdate>& updates, size_t segments) {
  double previous = 0.0;
  for (const TargetUpdate& u : updates) {
    if (!(u.time > previous) || !std::isfinite(u.time))
      throw std::invalid_argument("target updates must come at increasing times after 0 s");
    if (u.targets.size() != segments)
      throw std::invalid_argument("a target update has " + std::to_string(u.targets.size()) +
                                  " segment goals, the library " + std::to_string(segments));
    previous = u.time;
  }
}

}  // namespace

std::vector<GripperEvent> gripperEvents(const std::vector<double>& values, double fraction,
                                        double hysteresis, double min_range) {
  std::vector<GripperEvent> events;
  if (values.empty()) return events;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  const double range = *hi - *lo;
  if (!(range >= min_range) || !std::isfinite(range)) return events;
  const double threshold = *lo + fraction * range;
  const double band = hysteresis * range;
  bool closed = values.front() < threshold;
  events.push_back({0, closed});  // establish the initial state (e.g. open before approaching)
  for (size_t i = 1; i < values.size(); ++i) {
    if (!closed && values[i] < threshold - band) {
      closed = true;
      events.push_back({i, true});
    } else if (closed && values[i] > threshold + band) {
      closed = false;
      events.push_back({i, false});
    }
  }
  return events;
}

std::vector<SegmentTarget> segmentTargets(const SkillLibrary& library, const lfd::Scene& scene,
                                          const TcpPose& start, const ExecutorOptions& options,
                                          std::vector<std::string>* warnings) {
  checkLibrary(library);
  std::vector<SegmentTarget> targets;
  for (const SegmentSkills& seg : library.segments) {
    const lfd::SegmentGoalModel& g = *seg.goal;
    SegmentTarget t;
    t.name = seg.name;
    t.frames = g.position_frame.name() + " / " + g.orientation_frame.name();
    try {
      t.goal = lfd::segmentGoal(g, scene, start, options.frames);
      if (options.heading_frames && g.motion_frame) {
        t.heading = headingFrame(library, seg, scene, start, options.frames, warnings);
        t.frames += " (along " + g.motion_frame->name() + ")";
      }
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("segment '" + seg.name + "' (goal frames " + t.frames +
                                  "): " + e.what());
    }
    t.range = worse(frameRange(library, g.position_frame,
                               lfd::framePose(g.position_frame, scene, start, options.frames),
                               g.position_offset.norm(), options),
                    frameRange(library, g.orientation_frame,
                               lfd::framePose(g.orientation_frame, scene, start, options.frames),
                               std::nullopt, options));
    shapeRange(seg, options, &t);
    targets.push_back(t);
  }
  return targets;
}

TaskPlanner::TaskPlanner(const lfd::CartesianToJoints& ik) : ik_(ik) {}

ExecutionPlan TaskPlanner::plan(const SkillLibrary& library,
                                const std::vector<SegmentTarget>& targets,
                                const Eigen::VectorXd& q_start, std::optional<double> gripper_start,
                                const ExecutorOptions& options,
                                const std::function<bool()>& cancelled) {
  return replan(library, targets, {}, ExecutionPlan(), q_start, gripper_start, options, cancelled);
}

ExecutionPlan TaskPlanner::replan(const SkillLibrary& library,
                                  const std::vector<SegmentTarget>& targets,
                                  const std::vector<TargetUpdate>& updates,
                                  const ExecutionPlan& current, const Eigen::VectorXd& q_start,
                                  std::optional<double> gripper_start,
                                  const ExecutorOptions& options,
                                  const std::function<bool()>& cancelled) {
  const auto poll = [&](const std::string& where) {
    if (cancelled && cancelled())
      throw PlanningCancelled("cancelled while planning (" + where + ")");
  };
  checkPlanRequest(library, targets, q_start, chain().dof(), options);
  checkUpdates(updates, library.segments.size());
  ExecutionPlan plan;
  const size_t first = options.first_segment;
  checkRange(targets, first, options.allow_extrapolation, &plan);
  for (const TargetUpdate& u : updates)
    checkRange(u.targets, first, options.allow_extrapolation, &plan);
  plan.joint_names = chain().jointNames();
  plan.dt = options.dt;
  const TcpPose start = forward(q_start);
  RolloutState state{start.position, start.orientation};
  state.gripper = gripper_start;
  // Every target set, the plan's own first, and what each generalizes over (once per set).
  std::vector<const std::vector<SegmentTarget>*> sets{&targets};
  for (const TargetUpdate& u : updates) sets.push_back(&u.targets);
  std::vector<GoalQuery> queries;
  for (const auto* set : sets)
    queries.push_back(goalQuery(library, *set, options.all_segment_goals));
  for (size_t s = 0; s < library.segments.size(); ++s) {
    poll("segment " + library.segments[s].name);
    // A segment is generalized toward the targets in force when it starts; an update while it
    // runs moves its DMP's goal (the goal filter keeps the motion smooth).
    const size_t in_force = targetSetAt(updates, state.t_offset);
    const SegmentTarget& target = (*sets[in_force])[s];
    PlannedSegment planned;
    planned.name = library.segments[s].name;
    planned.frames = target.frames;
    if (s < first) {  // done before this plan: kept empty, indices as the library's
      planned.goal = target.goal;
      plan.segments.push_back(planned);
      continue;
    }
    const lfd::GeneralizationResult gen =
        generalizeForTarget(library.segments[s], target, queries[in_force], options, planned, plan);
    lfd::SegmentRolloutOptions ro = rolloutOptions(gen.dmp, target, options, state);
    ro.goal_filter = options.goal_filter;
    ro.goal_switches =
        switchesDuring(updates, s, state.t_offset, *ro.tau, gen.dmp.orientation.has_value());
    const lfd::SegmentTrajectory traj = gen.dmp.rollout(ro);
    planned.begin = plan.times.size();
    planned.goal = ro.goal_switches.empty()
                       ? target.goal
                       : (*sets[targetSetAt(updates, state.t_offset + *ro.tau)])[s].goal;
    appendRollout(traj, plan.times.empty(), state.t_offset, state.orientation, state.gripper,
                  &plan);
    planned.end = plan.times.size();
    // as sampled: the durations sum to the plan's
    planned.duration = plan.times.back() - state.t_offset;
    state.t_offset = plan.times.back();
    state.position = plan.poses.back().position;
    state.orientation = plan.poses.back().orientation;
    state.velocity = traj.velocities.row(traj.velocities.rows() - 1).transpose();
    if (traj.gripper.size()) state.gripper = traj.gripper[traj.gripper.size() - 1];
    plan.segments.push_back(planned);
  }
  // What the robot did before the last update stays as it was planned: IK only from there.
  size_t keep = 0;
  if (!updates.empty() && current.joint_names == plan.joint_names) {
    while (keep < current.joints.size() && keep < plan.times.size() &&
           plan.times[keep] < updates.back().time)
      ++keep;
    plan.joints.assign(current.joints.begin(), current.joints.begin() + static_cast<long>(keep));
    plan.max_ik_position_error = current.max_ik_position_error;
    plan.max_ik_orientation_error = current.max_ik_orientation_error;
    plan.max_speed_ratio = current.max_speed_ratio;
  }
  solveIk(ik_, keep > 0 ? plan.joints[keep - 1] : q_start, keep, poll, plan);
  plan.gripper_events = gripperEvents(plan.gripper, options.gripper_threshold_fraction,
                                      options.gripper_hysteresis, options.gripper_min_range);
  return plan;
}

}  // namespace lfd_dmp
