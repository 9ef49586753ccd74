#include "lfd_core/dmp/segment_dmp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace lfd {
namespace {

// The demo has at least one part, and every part it has is one sample per time (finite).
void checkDemoParts(const SegmentDemo& demo, bool has_pos, bool has_ori, bool has_grip) {
  const Eigen::Index m = demo.times.size();
  if (!has_pos && !has_ori && !has_grip) {
    throw std::invalid_argument(
        "SegmentDmp::learn: the demo has no position, orientation or gripper");
  }
  auto check_rows = [&](Eigen::Index rows, const char* what) {
    if (rows != m) {
      throw std::invalid_argument(std::string("SegmentDmp::learn: ") + what + " has " +
                                  std::to_string(rows) + " samples, times has " +
                                  std::to_string(m));
    }
  };
  if (has_pos) {
    check_rows(demo.positions.rows(), "positions");
    requireFinite(demo.positions, "SegmentDmp::learn positions");
  }
  if (has_ori) check_rows(demo.quaternions.rows(), "quaternions");
  if (has_grip) {
    check_rows(demo.gripper.size(), "gripper");
    requireFinite(demo.gripper, "SegmentDmp::learn gripper");
  }
}

// A rollout option's vector (same size as the learned one, finite), else the learned one.
Eigen::VectorXd givenOrLearned(const std::optional<Eigen::VectorXd>& given,
                               const Eigen::VectorXd& learned, const char* name) {
  if (!given) return learned;
  if (given->size() != learned.size()) {
    throw std::invalid_argument(std::string("SegmentDmpRunner: ") + name + " has " +
                                std::to_string(given->size()) + " dims, the DMP has " +
                                std::to_string(learned.size()));
  }
  requireFinite(*given, name);
  return *given;
}

Eigen::Quaterniond checkedNormalized(const Eigen::Quaterniond& q, const char* name) {
  if (!q.coeffs().allFinite() || q.norm() < 1e-6) {
    throw std::invalid_argument(std::string("SegmentDmpRunner: ") + name +
                                " must be a finite non-zero quaternion");
  }
  return q.normalized();
}

double checkedFinite(double v, const char* name) {
  if (!std::isfinite(v)) {
    throw std::invalid_argument(std::string("SegmentDmpRunner: ") + name + " is not finite");
  }
  return v;
}

}  // namespace

SegmentDmp SegmentDmp::learn(const SegmentDemo& demo, const DmpParameters& params) {
  params.validate();
  validateDemoTimes(demo.times, "SegmentDmp::learn");
  const Eigen::Index m = demo.times.size();
  const bool has_pos = demo.positions.cols() > 0;
  const bool has_ori = demo.quaternions.cols() > 0;
  const bool has_grip = demo.gripper.size() > 0;
  checkDemoParts(demo, has_pos, has_ori, has_grip);

  const double tau = demo.times[m - 1] - demo.times[0];
  const CanonicalSystem canonical(params.alpha_x);
  const GaussianBasis basis(params.num_basis, canonical, params.width_scale);
  const Eigen::VectorXd phases = demoPhases(demo.times, canonical);

  // Stack every part's forcing targets so one banded least-squares solve serves them all.
  const Eigen::Index dp = has_pos ? demo.positions.cols() : 0;
  const Eigen::Index cols = dp + (has_ori ? 3 : 0) + (has_grip ? 1 : 0);
  Eigen::MatrixXd targets(m, cols);
  SmoothDerivatives pos_der, grip_der;
  QuaternionSequence quats;
  AngularDerivatives ang_der;
  if (has_pos) {
    pos_der = smoothDerivatives(demo.times, demo.positions, params.derivatives);
    targets.leftCols(dp) = PositionDmp::forcingTargets(demo.times, demo.positions, pos_der.velocity,
                                                       pos_der.acceleration, phases, params);
  }
  if (has_ori) {
    quats = makeContinuousQuaternions(demo.quaternions);
    ang_der = angularDerivatives(demo.times, quats.quaternions, params.derivatives);
    targets.middleCols(dp, 3) =
        OrientationDmp::forcingTargets(demo.times, quats.quaternions, ang_der, phases, params);
  }
  Eigen::MatrixXd grip_mat;
  if (has_grip) {
    grip_mat = demo.gripper;
    grip_der = smoothDerivatives(demo.times, grip_mat, params.derivatives);
    targets.rightCols(1) = PositionDmp::forcingTargets(demo.times, grip_mat, grip_der.velocity,
                                                       grip_der.acceleration, phases, params);
  }
  const Eigen::MatrixXd weights = fitForcingWeights(basis, phases, targets, params.ridge);

  SegmentDmp out;
  out.params = params;
  out.tau = tau;
  if (has_pos) {
    out.position.emplace(params, tau, weights.leftCols(dp), demo.positions.row(0).transpose(),
                         demo.positions.row(m - 1).transpose(),
                         pos_der.velocity.row(0).transpose());
  }
  if (has_ori) {
    out.orientation.emplace(params, tau, weights.middleCols(dp, 3), quats.quaternions.front(),
                            quats.quaternions.back(), ang_der.omega.row(0).transpose());
    out.orientation->normalized_input_ = quats.normalized_input;
    out.orientation->sign_flips_ = quats.sign_flips;
    if (quats.normalized_input) {
      out.warnings.push_back("non-unit quaternions in the demo were normalized");
    }
  }
  if (has_grip) {
    out.gripper.emplace(params, tau, weights.rightCols(1), grip_mat.row(0).transpose(),
                        grip_mat.row(m - 1).transpose(), grip_der.velocity.row(0).transpose());
  }
  return out;
}

void SegmentDmp::validate() const {
  params.validate();
  if (!(tau > 0.0) || !std::isfinite(tau)) {
    throw std::invalid_argument("SegmentDmp: tau must be positive");
  }
  if (!position && !orientation && !gripper) {
    throw std::invalid_argument("SegmentDmp: no position, orientation or gripper part");
  }
  auto same = [&](const DmpParameters& p, double t, const char* what) {
    if (p.num_basis != params.num_basis || p.alpha_x != params.alpha_x ||
        p.width_scale != params.width_scale || p.alpha_z != params.alpha_z ||
        p.beta_z != params.beta_z || std::abs(t - tau) > 1e-12 * tau) {
      throw std::invalid_argument(std::string("SegmentDmp: the ") + what +
                                  " part does not share the segment's parameters/tau");
    }
  };
  if (position) same(position->parameters(), position->tau(), "position");
  if (orientation) same(orientation->parameters(), orientation->tau(), "orientation");
  if (gripper) {
    same(gripper->parameters(), gripper->tau(), "gripper");
    if (gripper->dims() != 1) throw std::invalid_argument("SegmentDmp: gripper must be 1-D");
  }
}

SegmentTrajectory SegmentDmp::rollout(const SegmentRolloutOptions& o) const {
  SegmentDmpRunner runner(*this, o);
  const double duration = o.duration.value_or(runner.tau());
  if (!(duration >= 0.0) || !std::isfinite(duration)) {
    throw std::invalid_argument("rollout: duration must be >= 0");
  }
  const double steps_real = std::floor(duration / o.dt + 1e-9) + 1.0;
  if (steps_real > 5e7) throw std::invalid_argument("rollout: more than 5e7 steps requested");
  const int steps = static_cast<int>(steps_real);
  SegmentTrajectory traj;
  traj.times = Eigen::VectorXd::LinSpaced(steps, 0.0, (steps - 1) * o.dt);
  traj.phases.resize(steps);
  const Eigen::Index dp = position ? position->dims() : 0;
  traj.positions.resize(steps, dp);
  traj.velocities.resize(steps, dp);
  traj.quaternions.resize(steps, orientation ? 4 : 0);
  traj.angular_velocities.resize(steps, orientation ? 3 : 0);
  if (gripper) traj.gripper.resize(steps);
  std::vector<GoalSwitch> switches = o.goal_switches;
  for (const GoalSwitch& g : switches)
    if (!std::isfinite(g.time)) throw std::invalid_argument("rollout: a goal switch time is NaN");
  std::stable_sort(switches.begin(), switches.end(),
                   [](const GoalSwitch& a, const GoalSwitch& b) { return a.time < b.time; });
  auto next_switch = switches.begin();
  for (int k = 0; k < steps; ++k) {
    if (k > 0) {
      // A switch at or before the step's start: the step already drives toward the new goal.
      const double now = (k - 1) * o.dt;
      for (; next_switch != switches.end() && next_switch->time <= now + 1e-9 * o.dt; ++next_switch)
        runner.setGoal(next_switch->goal);
      runner.step(o.dt);
    }
    traj.phases[k] = runner.phase();
    if (position) {
      traj.positions.row(k) = runner.position().transpose();
      traj.velocities.row(k) = runner.velocity().transpose();
    }
    if (orientation) {
      const Eigen::Quaterniond& q = runner.orientation();
      traj.quaternions.row(k) << q.w(), q.x(), q.y(), q.z();
      traj.angular_velocities.row(k) = runner.angularVelocity().transpose();
    }
    if (gripper) traj.gripper[k] = runner.gripper();
  }
  return traj;
}

SegmentDmp SegmentDmp::rotated(const Eigen::Matrix3d& r) const {
  if (!r.allFinite() || !(r.transpose() * r).isIdentity(1e-9) || !(r.determinant() > 0.0)) {
    throw std::invalid_argument("SegmentDmp::rotated: the matrix is not a rotation");
  }
  if (position && position->dims() != 3) {
    throw std::invalid_argument("SegmentDmp::rotated: the position part is " +
                                std::to_string(position->dims()) + "-D, not 3-D");
  }
  SegmentDmp out = *this;
  // Weights are rows of 3-vectors (one per basis function): w' = w r^T.
  if (position) {
    const PositionDmp& p = *position;
    out.position.emplace(params, tau, p.weights() * r.transpose(), r * p.start(), r * p.goal(),
                         r * p.startVelocity());
  }
  if (orientation) {
    const OrientationDmp& o = *orientation;
    const Eigen::Quaterniond q(r);
    out.orientation.emplace(params, tau, o.weights() * r.transpose(), q * o.start(), q * o.goal(),
                            r * o.startAngularVelocity());
    out.orientation->normalized_input_ = o.normalizedInput();
    out.orientation->sign_flips_ = o.signFlips();
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

SegmentDmpRunner::SegmentDmpRunner(const SegmentDmp& dmp, const SegmentRolloutOptions& o)
    : dmp_(dmp) {
  dmp.validate();
  tau_ = o.tau.value_or(dmp.tau);
  if (!(tau_ > 0.0) || !std::isfinite(tau_)) {
    throw std::invalid_argument("SegmentDmpRunner: tau must be positive");
  }
  if (!(o.dt > 0.0) || !std::isfinite(o.dt)) {
    throw std::invalid_argument("SegmentDmpRunner: dt must be positive");
  }
  if (!(o.goal_filter >= 0.0) || !std::isfinite(o.goal_filter)) {
    throw std::invalid_argument("SegmentDmpRunner: goal_filter must be >= 0");
  }
  goal_filter_ = o.goal_filter;
  if (dmp.position) {
    basis_ = &dmp.position->basis();
    canonical_ = &dmp.position->canonical();
  } else if (dmp.orientation) {
    basis_ = &dmp.orientation->basis();
    canonical_ = &dmp.orientation->canonical();
  } else {
    basis_ = &dmp.gripper->basis();
    canonical_ = &dmp.gripper->canonical();
  }
  act_.resize(static_cast<size_t>(basis_->maxActive()) + 1);

  if (dmp.position) setUpPosition(o);
  if (dmp.orientation) setUpOrientation(o);
  if (dmp.gripper) setUpGripper(o);
  x_end_ = std::exp(-dmp.params.alpha_x);
  if (dmp.position) u0_.resize(dmp.position->dims());
  x_ = 1.0;
  evaluateForcing(x_);
}

void SegmentDmpRunner::setUpPosition(const SegmentRolloutOptions& o) {
  start_pos_ = givenOrLearned(o.start_position, dmp_.position->start(), "start_position");
  goal_pos_ = givenOrLearned(o.goal_position, dmp_.position->goal(), "goal_position");
  target_goal_pos_ = goal_pos_;
  y_ = start_pos_;
  // Default start velocities are the demo's, time-scaled with tau (v = tau * dy/dt invariant).
  const double scale = dmp_.tau / tau_;
  v_ = tau_ * givenOrLearned(o.start_velocity,
                             Eigen::VectorXd(dmp_.position->startVelocity() * scale),
                             "start_velocity");
  f_pos_.resize(dmp_.position->dims());
}

void SegmentDmpRunner::setUpOrientation(const SegmentRolloutOptions& o) {
  start_ori_ = checkedNormalized(o.start_orientation.value_or(dmp_.orientation->start()),
                                 "start_orientation");
  goal_ori_ =
      checkedNormalized(o.goal_orientation.value_or(dmp_.orientation->goal()), "goal_orientation");
  target_goal_ori_ = goal_ori_;
  orient_.q = start_ori_;
  const Eigen::Vector3d w0 = o.start_angular_velocity.value_or(
      Eigen::Vector3d(dmp_.orientation->startAngularVelocity() * (dmp_.tau / tau_)));
  requireFinite(w0, "start_angular_velocity");
  orient_.eta = tau_ * w0;
}

void SegmentDmpRunner::setUpGripper(const SegmentRolloutOptions& o) {
  grip_start_ = checkedFinite(o.start_gripper.value_or(dmp_.gripper->start()[0]), "start_gripper");
  grip_goal_ = checkedFinite(o.goal_gripper.value_or(dmp_.gripper->goal()[0]), "goal_gripper");
  grip_target_goal_ = grip_goal_;
  grip_y_ = grip_start_;
  grip_v_ = dmp_.tau * dmp_.gripper->startVelocity()[0];
}

void SegmentDmpRunner::setGoal(const SegmentGoal& goal) {
  if (goal.position) {
    if (!dmp_.position || goal.position->size() != goal_pos_.size()) {
      throw std::invalid_argument("SegmentDmpRunner::setGoal: position goal has the wrong size");
    }
    requireFinite(*goal.position, "SegmentDmpRunner::setGoal position");
    target_goal_pos_ = *goal.position;
    if (goal_filter_ <= 0.0) goal_pos_ = target_goal_pos_;
  }
  if (goal.orientation) {
    if (!dmp_.orientation) throw std::invalid_argument("setGoal: the DMP has no orientation");
    if (!goal.orientation->coeffs().allFinite() || goal.orientation->norm() < 1e-6) {
      throw std::invalid_argument("setGoal: orientation goal must be a finite non-zero quaternion");
    }
    target_goal_ori_ = goal.orientation->normalized();
    if (goal_filter_ <= 0.0) goal_ori_ = target_goal_ori_;
  }
  if (goal.gripper) {
    if (!dmp_.gripper) throw std::invalid_argument("setGoal: the DMP has no gripper");
    if (!std::isfinite(*goal.gripper)) throw std::invalid_argument("setGoal: gripper goal NaN");
    grip_target_goal_ = *goal.gripper;
    if (goal_filter_ <= 0.0) grip_goal_ = grip_target_goal_;
  }
}

void SegmentDmpRunner::evaluateForcing(double x) {
  int count = 0;
  const int begin = basis_->gatedActivations(x, act_.data(), &count);
  if (dmp_.position) dmp_.position->forcing(act_.data(), begin, count, f_pos_.data());
  if (dmp_.orientation) f_ori_ = dmp_.orientation->forcing(act_.data(), begin, count);
  if (dmp_.gripper) dmp_.gripper->forcing(act_.data(), begin, count, &f_grip_);
}

void SegmentDmpRunner::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("SegmentDmpRunner::step: dt must be positive");
  }
  const double h_total = dt / tau_;
  // The orientation integrator is explicit: sub-step large steps. The linear parts are exact.
  const int sub = dmp_.orientation ? std::max(1, static_cast<int>(std::ceil(h_total / 0.01))) : 1;
  const double h = h_total / sub;
  if (std::abs(linear_.h - h) > 1e-15 * h) {
    linear_ = LinearStep::make(dmp_.params.stiffness(), dmp_.params.damping(), h);
  }
  const double decay = canonical_->stepFactor(dt / sub, tau_);
  const double filter_gain = goal_filter_ > 0.0 ? 1.0 - std::exp(-goal_filter_ * h) : 1.0;
  for (int j = 0; j < sub; ++j) {
    const double x0 = x_;
    const double x1 = x0 * decay;
    // Inputs at the start of the step use the current goal and the cached forcing f(x0).
    const double gate0 = forcingGate(x0, x_end_, dmp_.params.alpha_x);
    const double gate1 = forcingGate(x1, x_end_, dmp_.params.alpha_x);
    if (dmp_.position) {
      u0_ = goal_pos_ + gate0 * (f_pos_ - (goal_pos_ - start_pos_) * x0);
    }
    Eigen::Vector3d ori_drive0 = Eigen::Vector3d::Zero();
    if (dmp_.orientation) {
      ori_drive0 = gate0 * (f_ori_ - orientationError(goal_ori_, start_ori_) * x0);
    }
    const double grip_u0 = grip_goal_ + gate0 * (f_grip_ - (grip_goal_ - grip_start_) * x0);

    // Goal filter (exact first-order step), then forcing at the end of the step.
    if (goal_filter_ > 0.0) {
      if (dmp_.position) goal_pos_ += filter_gain * (target_goal_pos_ - goal_pos_);
      if (dmp_.orientation) {
        const Eigen::Vector3d r = quaternionLog(target_goal_ori_ * goal_ori_.conjugate());
        goal_ori_ = (quaternionExp(filter_gain * r) * goal_ori_).normalized();
      }
      grip_goal_ += filter_gain * (grip_target_goal_ - grip_goal_);
    }
    evaluateForcing(x1);

    if (dmp_.position) {
      for (Eigen::Index d = 0; d < y_.size(); ++d) {
        const double u1 = goal_pos_[d] + gate1 * (f_pos_[d] - (goal_pos_[d] - start_pos_[d]) * x1);
        linear_.apply(y_[d], v_[d], u0_[d], u1);
      }
    }
    if (dmp_.orientation) {
      const Eigen::Vector3d ori_drive1 =
          gate1 * (f_ori_ - orientationError(goal_ori_, start_ori_) * x1);
      dmp_.orientation->step(orient_, goal_ori_, ori_drive0, ori_drive1, h);
    }
    if (dmp_.gripper) {
      const double grip_u1 = grip_goal_ + gate1 * (f_grip_ - (grip_goal_ - grip_start_) * x1);
      linear_.apply(grip_y_, grip_v_, grip_u0, grip_u1);
    }
    x_ = x1;
  }
  time_ += dt;
}

}  // namespace lfd
