#include "lfd_sim_bridge/demo_plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {
namespace {

using task::StepKind;

Eigen::Quaterniond yawRotation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

// Wraps a yaw into (-pi/n, pi/n]: a tool that looks the same turned by 2 pi / n takes the turn
// nearest the wrist's comfortable middle.
double wrapYaw(double yaw, int n) {
  const double period = 2.0 * M_PI / n;
  while (yaw > period / 2) yaw -= period;
  while (yaw <= -period / 2) yaw += period;
  return yaw;
}

Pose poseAt(const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation) {
  Pose p;
  p.position = position;
  p.orientation = orientation.normalized();
  return p;
}

Segment move(const std::string& label, const Pose& target, double duration) {
  Segment s;
  s.label = label;
  s.target = target;
  s.duration = duration;
  return s;
}

Segment hold(const std::string& label, const Pose& at, double duration) {
  Segment s = move(label, at, duration);
  s.is_move = false;
  return s;
}

Frame fromWorld(const Eigen::Isometry3d& base_from_world, const Pose& world) {
  Frame f;
  f.position = base_from_world * world.position;
  f.yaw = yawOf(Eigen::Quaterniond(base_from_world.linear()) * world.orientation);
  return f;
}

// `f` moved by `local` (position and yaw in f's axes).
Frame compose(const Frame& f, const Pose& local) {
  Frame out;
  out.position = f.position + yawRotation(f.yaw) * local.position;
  out.yaw = f.yaw + yawOf(local.orientation);
  return out;
}

// `f` moved by a uniform draw within the object's +- ranges (none listed: unchanged).
Frame jittered(const Frame& f, const std::map<std::string, task::Jitter>& ranges,
               const std::string& object, std::mt19937& rng) {
  const auto j = ranges.find(object);
  if (j == ranges.end()) return f;
  std::uniform_real_distribution<double> sym(-1.0, 1.0);
  Pose local;
  for (int i = 0; i < 3; ++i) local.position[i] = j->second.position[i] * sym(rng);
  local.orientation = yawRotation(j->second.yaw * sym(rng));
  return compose(f, local);
}

}  // namespace

double Phase::duration() const {
  double total = 0.0;
  for (const Segment& s : segments) total += s.duration;
  return total;
}

double DemoPlan::duration() const {
  double total = 0.0;
  for (const Phase& p : phases) total += p.duration();
  return total;
}

double yawOf(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q.normalized() * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

double contactDistance(const Eigen::Vector3d& dir, const Eigen::Vector2d& half, double yaw,
                       double pusher_half) {
  const double angle = std::atan2(dir.y(), dir.x()) - yaw;
  const Eigen::Vector2d d(std::cos(angle), std::sin(angle));  // in the box's frame
  const Eigen::Vector2d n(-d.y(), d.x());
  // Depth of the box behind the centre along the line at lateral offset l: the largest s with
  // -s d + l n inside, i.e. the tighter of the two axes' bounds; concave and piecewise linear in l.
  const auto depth = [&](double l) {
    double s = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 2; ++k)
      if (std::abs(d[k]) > 1e-12)
        s = std::min(s, (half[k] + l * n[k] * (d[k] > 0 ? 1 : -1)) / std::abs(d[k]));
    return s;
  };
  double best = std::max(depth(-pusher_half), depth(pusher_half));
  // The depth is concave in l and peaks on the line through the box's rearmost corner.
  const Eigen::Vector2d corner = -half.cwiseProduct(d.cwiseSign());
  if (std::abs(corner.dot(n)) <= pusher_half) best = std::max(best, -corner.dot(d));
  return best;
}

TaskInterpreter::TaskInterpreter(task::TaskDefinition task, task::Scene scene,
                                 lfd::GripperSetup gripper, ToolGeometry tool, TeleopStyle teleop)
    : task_(std::move(task)),
      scene_(std::move(scene)),
      gripper_(std::move(gripper)),
      tool_(tool),
      teleop_(teleop) {}

StepTiming TaskInterpreter::drawTiming(const task::Step& step, double speed,
                                       std::mt19937& rng) const {
  StepTiming t;
  t.duration = step.duration / speed;
  const bool moves =
      step.kind == StepKind::kMove || step.kind == StepKind::kCarry || step.kind == StepKind::kPush;
  if (!teleop_.enabled || !moves) return t;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  t.duration *= 1.0 + teleop_.duration_jitter * (2.0 * unit(rng) - 1.0);
  if (unit(rng) < teleop_.slowdown_probability) t.duration *= teleop_.slowdown_factor;
  if (unit(rng) < teleop_.hesitation_probability) {
    t.hesitate = true;
    t.split = 0.45 + 0.35 * unit(rng);
    t.pause = teleop_.pause_min + (teleop_.pause_max - teleop_.pause_min) * unit(rng);
  }
  return t;
}

DemoState TaskInterpreter::begin(const task::Configuration& c,
                                 const Eigen::Isometry3d& world_from_base, const Pose& start,
                                 double speed, std::mt19937& rng) const {
  if (!(speed > 0.0) || !std::isfinite(speed))
    throw std::invalid_argument("demo speed factor must be > 0, got " + std::to_string(speed));
  const Eigen::Isometry3d base_from_world = world_from_base.inverse();
  DemoState s;
  s.start = start;
  s.grasp_tcp = start;
  Frame base;
  s.frames["base"] = base;
  s.frames["goal"] = fromWorld(base_from_world, c.goal);
  Frame tcp_start{start.position, yawOf(start.orientation), start.orientation};
  s.frames["start"] = tcp_start;
  s.frames["tcp"] = tcp_start;
  for (const std::string& name : task_.objects) {
    const Frame truth = fromWorld(base_from_world, c.objects.at(name));
    // Where the hand takes it: the task's variation and, in teleop mode, the operator's error.
    Frame aim = jittered(truth, task_.variation, name, rng);
    if (teleop_.enabled) aim = jittered(aim, task_.teleop_placement, name, rng);
    s.frames[name] = aim;
    s.true_starts[name] = truth;
    // The object's own frames (a drawer's handle), moved by their joint's start value.
    for (const auto& [part, f] : scene_.find(name)->frames) {
      Pose local = f.pose;
      if (!f.joint.empty()) {
        const auto q = c.joints.find(f.joint);
        const double value = q == c.joints.end() ? 0.0 : q->second;
        local.position += value * scene_.find(name)->joints.at(f.joint).axis;
      }
      s.frames[name + "." + part] = compose(aim, local);
      s.true_starts[name + "." + part] = compose(truth, local);
    }
  }
  for (const auto& [name, spec] : task_.frames) s.frames[name] = resolveFrame(s, spec);
  for (const task::PhaseSpec& phase : task_.phases) {
    s.timings.emplace_back();
    for (const task::Step& step : phase.steps)
      s.timings.back().push_back(drawTiming(step, speed, rng));
  }
  return s;
}

const Frame& TaskInterpreter::frame(const DemoState& s, const std::string& name) const {
  const auto it = s.frames.find(name);
  if (it == s.frames.end())
    throw std::invalid_argument("task file '" + task_.path + "': no frame '" + name + "'");
  return it->second;
}

Frame TaskInterpreter::resolveFrame(const DemoState& s, const task::FrameSpec& f) const {
  if (f.kind == task::FrameSpec::Kind::kRelative) return targetFrame(s, f.relative);
  if (f.kind == task::FrameSpec::Kind::kHeading) {
    Frame out = frame(s, f.from);
    const Eigen::Vector3d d = frame(s, f.to).position - out.position;
    if (d.head<2>().norm() < 1e-3)
      throw std::invalid_argument("task file '" + task_.path + "': " + f.where + ": '" + f.to +
                                  "' is within 1 mm of '" + f.from + "': no heading");
    out.yaw = std::atan2(d.y(), d.x());
    out.orientation.reset();
    return out;
  }
  // kTouch: the closed fist's face on the object, approaching along `along`'s x axis.
  const Frame& object = frame(s, f.object);
  const Frame& along = frame(s, f.along);
  const Eigen::Vector3d dir(std::cos(along.yaw), std::sin(along.yaw), 0.0);
  const Eigen::Vector3d& half = scene_.find(f.object)->half_size;
  const double face = contactDistance(dir, half.head<2>(), object.yaw, tool_.fist_half_width) +
                      tool_.fist_half_width;
  Frame out;
  out.position = object.position - face * dir;
  out.yaw = along.yaw;
  return out;
}

Frame TaskInterpreter::targetFrame(const DemoState& s, const task::PoseSpec& spec) const {
  const Frame& f = frame(s, spec.frame);
  const Frame& axes = spec.axes.empty() ? f : frame(s, spec.axes);
  Frame out;
  out.position = f.position + yawRotation(axes.yaw) * spec.position;
  out.yaw = f.yaw + spec.yaw;
  if (f.orientation) out.orientation = yawRotation(spec.yaw) * *f.orientation;
  return out;
}

Pose TaskInterpreter::target(const DemoState& s, const task::PoseSpec& spec) const {
  const Frame t = targetFrame(s, spec);
  if (t.orientation) return poseAt(t.position, *t.orientation);
  return poseAt(t.position, yawRotation(wrapYaw(t.yaw, spec.symmetry)) * scene_.tool_orientation);
}

void TaskInterpreter::addStep(DemoState& s, const task::Step& step, const StepTiming& timing,
                              Pose* tcp, std::vector<Segment>* out) const {
  s.frames["tcp"] = Frame{tcp->position, yawOf(tcp->orientation), tcp->orientation};
  Pose to = *tcp;
  switch (step.kind) {
    case StepKind::kHold:
      out->push_back(hold(step.label, *tcp, timing.duration));
      return;
    case StepKind::kGripper: {
      if (!step.open) s.grasp_tcp = *tcp;  // what the hand closes on moves with it from here
      const GripperAction action =
          step.open ? GripperAction{gripper_.open_opening, 0.0}
                    : GripperAction{gripper_.close_opening, gripper_.close_effort};
      if (step.until_contact != Contact::kNone && teleop_.enabled) {
        // No force feedback: the operator closes after a reaction delay and waits a fixed time.
        out->push_back(hold("react", *tcp, teleop_.reaction_delay));
        Segment close =
            hold(step.label, *tcp, teleop_.timed_close * timing.duration / step.duration);
        close.gripper = action;
        out->push_back(close);
        return;
      }
      Segment g = hold(step.label, *tcp, timing.duration);
      g.gripper = action;
      g.until_contact = step.until_contact;
      g.settle = step.settle;
      out->push_back(g);
      return;
    }
    case StepKind::kMove:
      to = target(s, step.target);
      break;
    case StepKind::kCarry: {  // the held thing keeps its place in the hand
      const Frame goal = targetFrame(s, step.target);
      const Frame& held = s.true_starts.at(step.held);
      const Eigen::Quaterniond turn = yawRotation(goal.yaw - held.yaw);
      to = poseAt(goal.position + turn * (s.grasp_tcp.position - held.position),
                  turn * s.grasp_tcp.orientation);
      break;
    }
    case StepKind::kPush: {  // the hand moves the object along the table by its displacement
      Eigen::Vector3d travel =
          targetFrame(s, step.target).position - s.true_starts.at(step.held).position;
      travel.z() = 0.0;
      to = poseAt(tcp->position + travel, tcp->orientation);
      break;
    }
  }
  std::vector<Segment> moves;
  if (timing.hesitate) {  // two minimum-jerk sub-movements with a pause: human reaching
    const Pose midway = interpolate(*tcp, to, timing.split);
    moves.push_back(move(step.label, midway, timing.duration * std::sqrt(timing.split)));
    moves.push_back(hold(step.label + "_hesitate", midway, timing.pause));
    moves.push_back(move(step.label, to, timing.duration * std::sqrt(1.0 - timing.split)));
  } else {
    moves.push_back(move(step.label, to, timing.duration));
  }
  for (Segment& m : moves) m.until_contact = step.until_contact;
  moves.back().settle = step.settle;
  out->insert(out->end(), moves.begin(), moves.end());
  *tcp = to;
}

Phase TaskInterpreter::planPhase(DemoState& s, size_t i, const Pose& tcp) const {
  const task::PhaseSpec& spec = task_.phases.at(i);
  Phase phase;
  phase.name = spec.name;
  phase.index = static_cast<int>(i);
  phase.window = spec.window;
  Pose at = tcp;
  for (size_t k = 0; k < spec.steps.size(); ++k)
    addStep(s, spec.steps[k], s.timings[i][k], &at, &phase.segments);
  return phase;
}

DemoPlan TaskInterpreter::planAll(DemoState s) const {
  DemoPlan plan;
  plan.task = task_.name;
  plan.start = s.start;
  Pose at = s.start;
  for (size_t i = 0; i < task_.phases.size(); ++i) {
    plan.phases.push_back(planPhase(s, i, at));
    at = plan.phases.back().segments.back().target;
  }
  return plan;
}

Pose phasePoseAt(const Pose& start, const Phase& phase, double t) {
  Pose from = start;
  double t_begin = 0.0;
  for (const Segment& s : phase.segments) {
    const double t_end = t_begin + s.duration;
    if (t < t_end || &s == &phase.segments.back()) {
      if (!s.is_move) return s.target;
      const double u = s.duration > 0.0 ? (t - t_begin) / s.duration : 1.0;
      return interpolate(from, s.target, minJerk(u));
    }
    from = s.target;
    t_begin = t_end;
  }
  return from;
}

std::vector<TimedPose> samplePhase(const Pose& start, const Phase& phase, double dt, double t0,
                                   const Tremor* tremor) {
  if (!(dt > 0.0)) throw std::invalid_argument("sampling period must be > 0");
  const double total = phase.duration();
  const int steps = std::max(1, static_cast<int>(std::ceil(total / dt - 1e-9)));
  std::vector<TimedPose> samples;
  samples.reserve(steps + 1);
  for (int k = 0; k <= steps; ++k) {
    const double t = std::min(k * dt, total);
    TimedPose sample{t, phasePoseAt(start, phase, t)};
    if (tremor) sample.pose.position += tremor->at(t0 + t);
    samples.push_back(sample);
  }
  return samples;
}

}  // namespace demo
}  // namespace lfd_sim_bridge
