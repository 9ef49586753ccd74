#include "lfd_dmp/executor.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

Eigen::Quaterniond yawRotation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

// Wraps yaw into (-period/2, period/2]: a stick is symmetric under pi, the closed fist under pi/2.
double wrapYaw(double yaw, double period) {
  while (yaw > period / 2) yaw -= period;
  while (yaw <= -period / 2) yaw += period;
  return yaw;
}

Eigen::Vector3d pushDirection(const TaskSituation& s) {
  Eigen::Vector3d d = s.goal_position - s.object_position;
  d.z() = 0.0;
  if (d.norm() < 1e-3)
    throw std::invalid_argument("the goal is within 1 mm of the object in xy: no push direction");
  return d.normalized();
}

std::string vec(const Eigen::VectorXd& v) {
  std::ostringstream o;
  o.precision(3);
  o << "(";
  for (int i = 0; i < v.size(); ++i) o << (i ? ", " : "") << v[i];
  o << ")";
  return o.str();
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

// A shorter stroke does not fix its direction: 1 mm of tremor at 2 cm is already 3 degrees.
constexpr double kMinHeadingLength = 0.02;  // m

Eigen::Matrix3d yawMatrix(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// The task frame of a plan: the new heading and, per demo id, the demo's own heading of the frame
// segment (demos whose heading is undefined are left out with a warning).
struct TaskFrame {
  double yaw = 0.0;
  std::map<std::string, double> demo_yaw;
};

TaskFrame taskFrame(const SkillLibrary& library, const std::vector<SegmentTarget>& targets,
                    const Eigen::Vector3d& tcp_start, const std::string& segment,
                    std::vector<std::string>* warnings) {
  size_t k = 0;
  while (k < targets.size() && targets[k].name != segment) ++k;
  if (k == targets.size())
    throw std::invalid_argument("task frame segment '" + segment +
                                "' is not a segment of the task goal model");
  TaskFrame frame;
  const Eigen::Vector3d from = k == 0 ? tcp_start : targets[k - 1].position;
  try {
    frame.yaw = headingYaw(from, targets[k].position, kMinHeadingLength);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("task frame: the new '" + segment + "' segment: " + e.what());
  }
  for (const DemoSkill& d : library.segments[k].demos) {
    if (!d.dmp.position || d.dmp.position->dims() != 3) continue;
    try {
      const Eigen::Vector3d a = d.dmp.position->start(), b = d.dmp.position->goal();
      frame.demo_yaw[d.demo_id] = headingYaw(a, b, kMinHeadingLength);
    } catch (const std::invalid_argument& e) {
      warnings->push_back("demo " + d.demo_id + " left out of the task frame: " + e.what());
    }
  }
  if (frame.demo_yaw.empty())
    throw std::invalid_argument("task frame: no demo has a defined '" + segment + "' heading");
  return frame;
}

}  // namespace

double headingYaw(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double min_length) {
  const Eigen::Vector2d d = (to - from).head<2>();
  if (!d.allFinite() || !(d.norm() >= min_length)) {
    std::ostringstream m;
    m << "its start and goal are " << d.norm() << " m apart in xy (heading needs >= " << min_length
      << " m)";
    throw std::invalid_argument(m.str());
  }
  return std::atan2(d.y(), d.x());
}

GoalReference parseGoalReference(const std::string& s) {
  if (s == "object") return GoalReference::kObject;
  if (s == "goal") return GoalReference::kGoal;
  if (s == "start") return GoalReference::kStart;
  throw std::invalid_argument("unknown goal reference '" + s + "' (object | goal | start)");
}

OrientationRule parseOrientationRule(const std::string& s) {
  if (s == "object_yaw") return OrientationRule::kObjectYaw;
  if (s == "goal_yaw") return OrientationRule::kGoalYaw;
  if (s == "push_yaw") return OrientationRule::kPushYaw;
  if (s == "start") return OrientationRule::kStart;
  if (s == "learned") return OrientationRule::kLearned;
  throw std::invalid_argument("unknown orientation rule '" + s +
                              "' (object_yaw | goal_yaw | push_yaw | start | learned)");
}

std::vector<SegmentTarget> segmentTargets(const TaskGoalModel& model,
                                          const TaskSituation& situation, const TcpPose& start,
                                          const Eigen::Quaterniond& gripper_orientation) {
  std::vector<SegmentTarget> targets;
  const Eigen::Quaterniond grip = gripper_orientation.normalized();
  for (const SegmentGoalRule& rule : model.segments) {
    SegmentTarget t;
    t.name = rule.name;
    t.frame = rule.frame;
    switch (rule.reference) {
      case GoalReference::kObject:
        t.position = situation.object_position;
        break;
      case GoalReference::kGoal:
        t.position = situation.goal_position;
        break;
      case GoalReference::kStart:
        t.position = start.position;
        break;
    }
    t.position += rule.offset;
    if (rule.along_push != 0.0) t.position += rule.along_push * pushDirection(situation);
    switch (rule.orientation) {
      case OrientationRule::kObjectYaw:
        t.orientation = yawRotation(wrapYaw(situation.object_yaw, M_PI)) * grip;
        break;
      case OrientationRule::kGoalYaw:
        t.orientation = yawRotation(wrapYaw(situation.goal_yaw, M_PI)) * grip;
        break;
      case OrientationRule::kPushYaw: {
        const Eigen::Vector3d d = pushDirection(situation);
        t.orientation = yawRotation(std::atan2(d.y(), d.x())) * grip;
        break;
      }
      case OrientationRule::kStart:
        t.orientation = start.orientation.normalized();
        break;
      case OrientationRule::kLearned:
        break;
    }
    targets.push_back(t);
  }
  return targets;
}

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

TaskPlanner::TaskPlanner(const lfd::CartesianToJoints& ik) : ik_(ik) {}

ExecutionPlan TaskPlanner::plan(const SkillLibrary& library,
                                const std::vector<SegmentTarget>& targets,
                                const Eigen::VectorXd& q_start, std::optional<double> gripper_start,
                                const ExecutorOptions& options) {
  if (library.segments.empty()) throw std::invalid_argument("the skill library has no segments");
  if (targets.size() != library.segments.size()) {
    std::ostringstream m;
    m << "the skill library '" << library.task << "' has " << library.segments.size()
      << " segments but the task goal model gives " << targets.size()
      << " segment goals (was the task segmented into the expected phases?)";
    throw std::invalid_argument(m.str());
  }
  if (library.generalization_parameters != "goal_position")
    throw std::invalid_argument("unsupported generalization_parameters '" +
                                library.generalization_parameters + "' (need goal_position)");
  if (q_start.size() != chain().dof())
    throw std::invalid_argument("start joint vector has " + std::to_string(q_start.size()) +
                                " values, the IK chain has " + std::to_string(chain().dof()));
  if (!(options.dt > 0.0) || !(options.duration_scale > 0.0))
    throw std::invalid_argument("dt and duration_scale must be > 0");

  const auto all_params = allSegmentParameters(library);
  const bool use_all = options.all_segment_goals && all_params.size() >= 1;
  Eigen::VectorXd all_query;
  if (use_all) {
    all_query.resize(3 * static_cast<Eigen::Index>(targets.size()));
    for (size_t s = 0; s < targets.size(); ++s) all_query.segment<3>(3 * s) = targets[s].position;
  }

  ExecutionPlan plan;
  plan.joint_names = chain().jointNames();
  plan.dt = options.dt;
  const TcpPose start = forward(q_start);
  std::map<std::string, TaskFrame> frames;  // by frame segment name
  for (const SegmentTarget& t : targets)
    if (!t.frame.empty() && !frames.count(t.frame))
      frames[t.frame] = taskFrame(library, targets, start.position, t.frame, &plan.warnings);
  Eigen::Vector3d position = start.position;
  Eigen::Quaterniond orientation = start.orientation;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  std::optional<double> gripper = gripper_start;
  double t_offset = 0.0;

  for (size_t s = 0; s < library.segments.size(); ++s) {
    const SegmentSkills& seg = library.segments[s];
    const SegmentTarget& target = targets[s];
    std::vector<lfd::SegmentDmp> dmps;
    std::vector<Eigen::VectorXd> params;
    PlannedSegment planned;
    planned.name = seg.name.empty() ? target.name : seg.name;
    const TaskFrame* frame = target.frame.empty() ? nullptr : &frames.at(target.frame);
    for (const DemoSkill& d : seg.demos) {
      if (frame && !frame->demo_yaw.count(d.demo_id)) continue;
      if (use_all) {
        const auto it = all_params.find(d.demo_id);
        if (it == all_params.end()) continue;
        params.push_back(it->second);
      } else {
        params.push_back(d.parameters);
      }
      dmps.push_back(frame ? d.dmp.rotated(yawMatrix(-frame->demo_yaw.at(d.demo_id))) : d.dmp);
      planned.demos.push_back(d.demo_id);
    }
    if (dmps.empty())
      throw std::invalid_argument("segment " + std::to_string(s) + " has no usable demonstration");
    if (!dmps.front().position || dmps.front().position->dims() != 3)
      throw std::invalid_argument("segment " + std::to_string(s) + " has no 3-D position DMP");
    const Eigen::VectorXd query = use_all ? all_query : Eigen::VectorXd(target.position);
    lfd::GeneralizationResult gen =
        lfd::generalizeSegment(dmps, params, query, options.generalization);
    if (frame) gen.dmp = gen.dmp.rotated(yawMatrix(frame->yaw));
    if (gen.outside_demo_range) {
      planned.outside_demo_range = true;
      plan.warnings.push_back("segment " + planned.name + ": " + gen.warning);
    }

    lfd::SegmentRolloutOptions ro;
    ro.dt = options.dt;
    ro.tau = gen.dmp.tau * options.duration_scale;
    ro.start_position = Eigen::VectorXd(position);
    ro.goal_position = Eigen::VectorXd(target.position);
    ro.start_velocity = Eigen::VectorXd(velocity);
    if (gen.dmp.orientation) {
      ro.start_orientation = orientation;
      ro.start_angular_velocity = Eigen::Vector3d::Zero();
      if (target.orientation) ro.goal_orientation = *target.orientation;
    }
    if (gen.dmp.gripper && gripper) ro.start_gripper = *gripper;
    const lfd::SegmentTrajectory traj = gen.dmp.rollout(ro);

    planned.begin = plan.times.size();
    planned.duration = *ro.tau;
    planned.goal.position = target.position;
    planned.goal.orientation =
        target.orientation ? *target.orientation
                           : (gen.dmp.orientation ? gen.dmp.orientation->goal() : orientation);
    const Eigen::Index n = traj.times.size();
    // Each later segment starts where the previous ended: skip its duplicate first sample.
    for (Eigen::Index k = (s == 0 ? 0 : 1); k < n; ++k) {
      TcpPose p;
      p.position = traj.positions.row(k).transpose();
      p.orientation = traj.quaternions.cols() == 4
                          ? Eigen::Quaterniond(traj.quaternions(k, 0), traj.quaternions(k, 1),
                                               traj.quaternions(k, 2), traj.quaternions(k, 3))
                                .normalized()
                          : orientation;
      plan.times.push_back(t_offset + traj.times[k]);
      plan.poses.push_back(p);
      plan.gripper.push_back(traj.gripper.size() ? traj.gripper[k] : (gripper ? *gripper : 0.0));
    }
    planned.end = plan.times.size();
    t_offset = plan.times.back();
    position = plan.poses.back().position;
    orientation = plan.poses.back().orientation;
    velocity = traj.velocities.row(n - 1).transpose();
    if (traj.gripper.size()) gripper = traj.gripper[n - 1];
    plan.segments.push_back(planned);
  }

  // Reachability of the WHOLE path before anything moves.
  std::vector<lfd::TimedPose> samples(plan.poses.size());
  for (size_t k = 0; k < samples.size(); ++k) samples[k] = {plan.times[k], plan.poses[k]};
  lfd::JointPath path;
  try {
    path = ik_.convert(samples, q_start);
  } catch (const std::runtime_error& e) {
    // Name the segment the failing time belongs to.
    std::string where;
    const std::string msg = e.what();
    const auto at = msg.find("t=");
    if (at != std::string::npos) {
      const double t = std::atof(msg.c_str() + at + 2);
      for (const PlannedSegment& ps : plan.segments)
        if (t <= plan.times[ps.end - 1] + 1e-9) {
          where = " in segment '" + ps.name + "' (goal " + vec(ps.goal.position) + " in base_link)";
          break;
        }
    }
    throw std::runtime_error("unreachable" + where + ": " + msg);
  }
  plan.joints = std::move(path.positions);
  plan.max_ik_position_error = path.max_position_error;
  plan.max_ik_orientation_error = path.max_orientation_error;
  plan.max_speed_ratio = path.max_speed_ratio;
  plan.gripper_events = gripperEvents(plan.gripper, options.gripper_threshold_fraction,
                                      options.gripper_hysteresis, options.gripper_min_range);
  return plan;
}

}  // namespace lfd_dmp
