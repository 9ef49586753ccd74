#include "lfd_sim_bridge/demo_plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {
namespace {

Eigen::Quaterniond yawRotation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

// Wraps a stick yaw into (-pi/2, pi/2]: the stick is symmetric, and the wrist prefers small yaws.
double symmetricYaw(double yaw) {
  while (yaw > M_PI / 2) yaw -= M_PI;
  while (yaw <= -M_PI / 2) yaw += M_PI;
  return yaw;
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

// How far behind the centre of a square (half size `half`, rotated by `yaw`) a flat pusher of
// half width `pusher_half` first touches it, moving along the horizontal unit `dir` through the
// centre. Off the square's axes the contact is an edge or a corner, farther out than `half`; a
// pusher narrower than the square may still miss the corner and meet the face.
double contactDistance(const Eigen::Vector3d& dir, double half, double yaw, double pusher_half) {
  const double angle = std::atan2(dir.y(), dir.x()) - yaw;
  const Eigen::Vector2d d(std::cos(angle), std::sin(angle));  // in the square's frame
  const Eigen::Vector2d n(-d.y(), d.x());
  // Depth of the square behind the centre along the line at lateral offset l: the largest s with
  // -s d + l n inside, i.e. the tighter of the two axes' bounds; concave and piecewise linear in l.
  const auto depth = [&](double l) {
    double s = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 2; ++k)
      if (std::abs(d[k]) > 1e-12)
        s = std::min(s, (half + l * n[k] * (d[k] > 0 ? 1 : -1)) / std::abs(d[k]));
    return s;
  };
  double best = std::max(depth(-pusher_half), depth(pusher_half));
  // The depth is concave in l and peaks on the line through the square's rearmost corner.
  const Eigen::Vector2d corner = -half * d.cwiseSign();
  if (std::abs(corner.dot(n)) <= pusher_half) best = std::max(best, -corner.dot(d));
  return best;
}

Pose poseAt(const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation) {
  Pose p;
  p.position = position;
  p.orientation = orientation.normalized();
  return p;
}

// Applies the speed factor and, in teleop-like mode, the operator's uneven timing and
// hesitations (a move split into two minimum-jerk sub-movements with a pause in between, the
// "submovement" structure of human reaching).
class Timer {
 public:
  Timer(double speed, const TeleopStyle& teleop, std::mt19937& rng)
      : speed_(speed), teleop_(teleop), rng_(rng) {}

  void addMove(std::vector<Segment>* out, const Pose& from, const std::string& label,
               const Pose& to, double nominal) {
    double duration = nominal / speed_;
    if (!teleop_.enabled) {
      out->push_back(move(label, to, duration));
      return;
    }
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    duration *= 1.0 + teleop_.duration_jitter * (2.0 * unit(rng_) - 1.0);
    if (unit(rng_) < teleop_.slowdown_probability) duration *= teleop_.slowdown_factor;
    if (unit(rng_) < teleop_.hesitation_probability) {
      const double split = 0.45 + 0.35 * unit(rng_);
      const double pause = teleop_.pause_min + (teleop_.pause_max - teleop_.pause_min) * unit(rng_);
      const Pose midway = interpolate(from, to, split);
      out->push_back(move(label, midway, duration * std::sqrt(split)));
      out->push_back(hold(label + "_hesitate", midway, pause));
      out->push_back(move(label, to, duration * std::sqrt(1.0 - split)));
    } else {
      out->push_back(move(label, to, duration));
    }
  }

  double scaled(double nominal) const { return nominal / speed_; }

 private:
  double speed_;
  const TeleopStyle& teleop_;
  std::mt19937& rng_;
};

DemoPlan planGrasp(const TaskInstance& inst, const Pose& start, const Geometry& g, const Timing& tm,
                   const Variation& var, const TeleopStyle& teleop, std::mt19937& rng) {
  Timer timer(var.speed, teleop, rng);
  const double stick_yaw = symmetricYaw(yawOf(inst.object_start.orientation));
  const Eigen::Vector3d axis = yawRotation(stick_yaw) * Eigen::Vector3d::UnitX();
  const Eigen::Quaterniond grip =
      yawRotation(symmetricYaw(stick_yaw + var.grasp_yaw)) * g.grasp_orientation;
  Eigen::Vector3d grasp_position = inst.object_start.position + var.grasp_offset_along * axis +
                                   Eigen::Vector3d(0, 0, g.grasp_height);
  if (teleop.enabled) {
    std::uniform_real_distribution<double> error(-teleop.grasp_position_noise,
                                                 teleop.grasp_position_noise);
    grasp_position.x() += error(rng);
    grasp_position.y() += error(rng);
  }
  const Pose grasp = poseAt(grasp_position, grip);
  const Pose pregrasp = poseAt(grasp_position + Eigen::Vector3d(0, 0, g.pregrasp_height), grip);
  const Pose lifted = poseAt(grasp_position + Eigen::Vector3d(0, 0, g.lift_height), grip);
  // The stick moves rigidly with the hand: the TCP goal is the grasp pose carried by the
  // transform that takes the stick's start pose to its goal pose.
  const Eigen::Quaterniond object_motion =
      inst.goal.orientation.normalized() * inst.object_start.orientation.normalized().inverse();
  const Eigen::Quaterniond goal_yaw_only = yawRotation(yawOf(object_motion));
  const Pose carried =
      poseAt(inst.goal.position + goal_yaw_only * (grasp_position - inst.object_start.position),
             goal_yaw_only * grip);

  DemoPlan plan;
  plan.task = "grasp";
  plan.start = start;
  Phase approach{"approach", 0, {}};
  Segment open = hold("open", start, timer.scaled(tm.open));
  open.gripper = GripperAction{g.open_opening, 0.0};
  approach.segments.push_back(open);
  timer.addMove(&approach.segments, start, "pregrasp", pregrasp, tm.to_pregrasp);
  timer.addMove(&approach.segments, pregrasp, "descend", grasp, tm.descend);

  Phase closing{"grasp", 1, {}};
  if (teleop.enabled) {
    // No force feedback: the operator closes fully after a reaction delay and waits a fixed time.
    closing.segments.push_back(hold("react", grasp, teleop.reaction_delay));
    Segment close = hold("close", grasp, timer.scaled(teleop.timed_close));
    close.gripper = GripperAction{g.teleop_close_opening, g.grasp_effort};
    closing.segments.push_back(close);
  } else {
    Segment close = hold("close", grasp, timer.scaled(tm.close));
    close.gripper = GripperAction{g.grasp_opening, g.grasp_effort};
    close.until_contact = true;
    close.settle = tm.settle;
    closing.segments.push_back(close);
  }

  Phase carry{"move", 2, {}};
  timer.addMove(&carry.segments, grasp, "lift", lifted, tm.lift);
  timer.addMove(&carry.segments, lifted, "carry", carried, tm.carry);
  carry.segments.push_back(hold("hold", carried, timer.scaled(tm.hold)));

  plan.phases = {approach, closing, carry};
  return plan;
}

DemoPlan planPush(const TaskInstance& inst, const Pose& start, const Geometry& g, const Timing& tm,
                  const Variation& var, const TeleopStyle& teleop, std::mt19937& rng) {
  Timer timer(var.speed, teleop, rng);
  Eigen::Vector3d travel = inst.goal.position - inst.object_start.position;
  travel.z() = 0.0;
  if (travel.norm() < 1e-3)
    throw std::invalid_argument("push target is within 1 mm of the box start: nothing to push");
  const Eigen::Vector3d dir = travel.normalized();
  const Eigen::Quaterniond hand =
      yawRotation(std::atan2(dir.y(), dir.x())) * g.push_orientation.normalized();
  const Eigen::Vector3d height(0, 0, g.push_height);
  // TCP-to-box-centre distance along the push when the fist touches the box.
  // The fist is a square block of half size tcp_to_face, squarely facing the push.
  const double face =
      contactDistance(dir, g.box_half_length, yawOf(inst.object_start.orientation), g.tcp_to_face) +
      g.tcp_to_face;
  const Pose behind =
      poseAt(inst.object_start.position + height - (face + g.push_clearance) * dir, hand);
  const Pose above = poseAt(behind.position + Eigen::Vector3d(0, 0, g.push_prelift), hand);
  // The paper's push phase is the time in contact: the approach ends with the fist on the face,
  // so the box starts moving (and the touch sensors fire) as the push phase starts.
  const Pose touching =
      poseAt(inst.object_start.position + height - (face - g.push_contact_depth) * dir, hand);
  const Pose pushed = poseAt(inst.goal.position + height - face * dir, hand);
  const Pose retreated =
      poseAt(pushed.position - g.retreat * dir + Eigen::Vector3d(0, 0, g.retreat), hand);

  DemoPlan plan;
  plan.task = "push";
  plan.start = start;
  Phase approach{"approach", 0, {}};
  Segment fist = hold("close", start, timer.scaled(tm.open));
  fist.gripper = GripperAction{0.0, 0.0};  // a closed hand gives a flat, stiff pushing face
  approach.segments.push_back(fist);
  timer.addMove(&approach.segments, start, "prepush", above, tm.to_prepush);
  timer.addMove(&approach.segments, above, "lower", behind, tm.lower);
  timer.addMove(&approach.segments, behind, "touch", touching, tm.touch);

  Phase push{"push", 1, {}};
  timer.addMove(&push.segments, touching, "push", pushed, tm.push);

  Phase back{"return", 2, {}};
  timer.addMove(&back.segments, pushed, "retreat", retreated, tm.retreat);
  timer.addMove(&back.segments, retreated, "home", start, tm.go_home);
  (void)var;

  plan.phases = {approach, push, back};
  return plan;
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

DemoPlan planDemo(const TaskInstance& instance, const Pose& start, const Geometry& geometry,
                  const Timing& timing, const Variation& variation, const TeleopStyle& teleop,
                  std::mt19937& rng) {
  if (!(variation.speed > 0.0) || !std::isfinite(variation.speed))
    throw std::invalid_argument("demo speed factor must be > 0, got " +
                                std::to_string(variation.speed));
  if (instance.task == "grasp")
    return planGrasp(instance, start, geometry, timing, variation, teleop, rng);
  if (instance.task == "push")
    return planPush(instance, start, geometry, timing, variation, teleop, rng);
  throw std::invalid_argument("unknown task '" + instance.task + "' (expected grasp or push)");
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
