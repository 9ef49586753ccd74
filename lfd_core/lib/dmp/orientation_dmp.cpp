#include "lfd_core/dmp/orientation_dmp.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

Eigen::Quaterniond checkedUnit(const Eigen::Quaterniond& q, const char* what) {
  if (!q.coeffs().allFinite()) throw std::invalid_argument(std::string(what) + " is not finite");
  const double n = q.norm();
  if (n < 1e-6) throw std::invalid_argument(std::string(what) + " has (near) zero norm");
  return Eigen::Quaterniond(q.coeffs() / n);
}

}  // namespace

AngularDerivatives angularDerivatives(const Eigen::VectorXd& times,
                                      const std::vector<Eigen::Quaterniond>& quaternions,
                                      const SmoothDerivativeOptions& options) {
  const Eigen::Index m = times.size();
  const SmoothDerivatives der = smoothDerivatives(times, quaternionRows(quaternions), options);
  AngularDerivatives out;
  out.omega.resize(m, 3);
  out.omega_dot.resize(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Quaterniond qc = quaternions[static_cast<size_t>(i)].conjugate();
    const Eigen::Quaterniond dq(der.velocity(i, 0), der.velocity(i, 1), der.velocity(i, 2),
                                der.velocity(i, 3));
    const Eigen::Quaterniond ddq(der.acceleration(i, 0), der.acceleration(i, 1),
                                 der.acceleration(i, 2), der.acceleration(i, 3));
    out.omega.row(i) = 2.0 * (dq * qc).vec().transpose();
    // d/dt (2 dq conj(q)) = 2 ddq conj(q) + 2 dq conj(dq); the last term is real for unit q.
    out.omega_dot.row(i) = 2.0 * (ddq * qc).vec().transpose();
  }
  return out;
}

OrientationDmp::OrientationDmp(const DmpParameters& params, double tau, Eigen::MatrixXd weights,
                               const Eigen::Quaterniond& start, const Eigen::Quaterniond& goal,
                               const Eigen::Vector3d& start_angular_velocity)
    : params_(params),
      canonical_((params.validate(), params.alpha_x)),
      basis_(params.num_basis, canonical_, params.width_scale),
      tau_(tau),
      weights_(std::move(weights)),
      start_(checkedUnit(start, "OrientationDmp start")),
      goal_(checkedUnit(goal, "OrientationDmp goal")),
      start_angular_velocity_(start_angular_velocity) {
  if (!(tau_ > 0.0) || !std::isfinite(tau_)) {
    throw std::invalid_argument("OrientationDmp: tau must be positive, got " +
                                std::to_string(tau_));
  }
  if (weights_.rows() != params.num_basis || weights_.cols() != 3) {
    throw std::invalid_argument(
        "OrientationDmp: weights must be " + std::to_string(params.num_basis) + " x 3, got " +
        std::to_string(weights_.rows()) + " x " + std::to_string(weights_.cols()));
  }
  requireFinite(weights_, "OrientationDmp weights");
  requireFinite(start_angular_velocity_, "OrientationDmp start angular velocity");
}

Eigen::MatrixXd OrientationDmp::forcingTargets(const Eigen::VectorXd& times,
                                               const std::vector<Eigen::Quaterniond>& quaternions,
                                               const AngularDerivatives& der,
                                               const Eigen::VectorXd& phases,
                                               const DmpParameters& params) {
  const Eigen::Index m = times.size();
  const double tau = times[m - 1] - times[0];
  const double k = params.stiffness();
  const double d = params.damping();
  const Eigen::Quaterniond& goal = quaternions.back();
  const Eigen::Vector3d e0 = orientationError(goal, quaternions.front());
  Eigen::MatrixXd f(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Vector3d e = orientationError(goal, quaternions[static_cast<size_t>(i)]);
    f.row(i) = (tau * tau * der.omega_dot.row(i) + d * tau * der.omega.row(i)) / k - e.transpose() +
               e0.transpose() * phases[i];
  }
  return f;
}

OrientationDmp OrientationDmp::learn(const Eigen::VectorXd& times,
                                     const Eigen::MatrixXd& quaternions_wxyz,
                                     const DmpParameters& params) {
  params.validate();
  validateDemoTimes(times, "OrientationDmp::learn");
  if (quaternions_wxyz.rows() != times.size()) {
    throw std::invalid_argument("OrientationDmp::learn: " + std::to_string(times.size()) +
                                " time stamps but " + std::to_string(quaternions_wxyz.rows()) +
                                " quaternions");
  }
  const QuaternionSequence seq = makeContinuousQuaternions(quaternions_wxyz);
  const double tau = times[times.size() - 1] - times[0];
  const CanonicalSystem canonical(params.alpha_x);
  const GaussianBasis basis(params.num_basis, canonical, params.width_scale);
  const AngularDerivatives der = angularDerivatives(times, seq.quaternions, params.derivatives);
  const Eigen::VectorXd phases = demoPhases(times, canonical);
  const Eigen::MatrixXd targets = forcingTargets(times, seq.quaternions, der, phases, params);
  OrientationDmp dmp(params, tau, fitForcingWeights(basis, phases, targets, params.ridge),
                     seq.quaternions.front(), seq.quaternions.back(), der.omega.row(0).transpose());
  dmp.normalized_input_ = seq.normalized_input;
  dmp.sign_flips_ = seq.sign_flips;
  return dmp;
}

void OrientationDmp::step(State& s, const Eigen::Quaterniond& goal, const Eigen::Vector3d& drive0,
                          const Eigen::Vector3d& drive1, double h) const {
  const double k = params_.stiffness();
  const double d = params_.damping();
  const Eigen::Vector3d a0 = k * (orientationError(goal, s.q) + drive0) - d * s.eta;
  const Eigen::Vector3d eta_pred = s.eta + h * a0;
  const Eigen::Quaterniond q_pred = quaternionExp(0.5 * h * s.eta) * s.q;
  const Eigen::Vector3d a1 = k * (orientationError(goal, q_pred) + drive1) - d * eta_pred;
  const Eigen::Vector3d eta_next = s.eta + 0.5 * h * (a0 + a1);
  s.q = (quaternionExp(0.25 * h * (s.eta + eta_next)) * s.q).normalized();
  s.eta = eta_next;
}

OrientationTrajectory OrientationDmp::rollout(const OrientationRolloutOptions& o) const {
  const double tau = o.tau.value_or(tau_);
  const double duration = o.duration.value_or(tau);
  if (!(tau > 0.0) || !std::isfinite(tau)) throw std::invalid_argument("rollout: tau must be > 0");
  if (!(o.dt > 0.0) || !std::isfinite(o.dt)) throw std::invalid_argument("rollout: dt must be > 0");
  if (!(duration >= 0.0) || !std::isfinite(duration)) {
    throw std::invalid_argument("rollout: duration must be >= 0");
  }
  const Eigen::Quaterniond start = o.start ? checkedUnit(*o.start, "rollout start") : start_;
  const Eigen::Quaterniond goal = o.goal ? checkedUnit(*o.goal, "rollout goal") : goal_;
  const Eigen::Vector3d omega0 =
      o.start_angular_velocity.value_or(Eigen::Vector3d(start_angular_velocity_ * (tau_ / tau)));
  const int steps = static_cast<int>(std::floor(duration / o.dt + 1e-9)) + 1;

  // Sub-step so the explicit scheme stays well inside its stability region.
  const double h_total = o.dt / tau;
  const int sub = std::max(1, static_cast<int>(std::ceil(h_total / 0.01)));
  const double h = h_total / sub;
  const double decay = canonical_.stepFactor(o.dt / sub, tau);
  const Eigen::Vector3d e0 = orientationError(goal, start);

  std::vector<double> act(static_cast<size_t>(basis_.maxActive()) + 1);
  const double x_end = std::exp(-params_.alpha_x);
  auto drive = [&](double x) {
    const double gate = forcingGate(x, x_end, params_.alpha_x);
    if (gate <= 0.0) return Eigen::Vector3d::Zero().eval();
    int count = 0;
    const int begin = basis_.gatedActivations(x, act.data(), &count);
    return Eigen::Vector3d(gate * (forcing(act.data(), begin, count) - e0 * x));
  };

  OrientationTrajectory traj;
  traj.times = Eigen::VectorXd::LinSpaced(steps, 0.0, (steps - 1) * o.dt);
  traj.quaternions.resize(steps, 4);
  traj.angular_velocities.resize(steps, 3);
  State s;
  s.q = start;
  s.eta = tau * omega0;
  double x = 1.0;
  Eigen::Vector3d d0 = drive(x);
  for (int k = 0; k < steps; ++k) {
    if (k > 0) {
      for (int j = 0; j < sub; ++j) {
        x *= decay;
        const Eigen::Vector3d d1 = drive(x);
        step(s, goal, d0, d1, h);
        d0 = d1;
      }
    }
    traj.quaternions.row(k) << s.q.w(), s.q.x(), s.q.y(), s.q.z();
    traj.angular_velocities.row(k) = (s.eta / tau).transpose();
  }
  return traj;
}

}  // namespace lfd
