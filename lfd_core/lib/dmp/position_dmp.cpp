#include "lfd_core/dmp/position_dmp.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lfd {

PositionDmp::PositionDmp(const DmpParameters& params, double tau, Eigen::MatrixXd weights,
                         Eigen::VectorXd start, Eigen::VectorXd goal,
                         Eigen::VectorXd start_velocity)
    : params_(params),
      canonical_((params.validate(), params.alpha_x)),
      basis_(params.num_basis, canonical_, params.width_scale),
      tau_(tau),
      weights_(std::move(weights)),
      start_(std::move(start)),
      goal_(std::move(goal)),
      start_velocity_(std::move(start_velocity)) {
  if (!(tau_ > 0.0) || !std::isfinite(tau_)) {
    throw std::invalid_argument("PositionDmp: tau must be positive, got " + std::to_string(tau_));
  }
  const Eigen::Index d = goal_.size();
  if (weights_.rows() != params.num_basis || weights_.cols() != d || start_.size() != d ||
      start_velocity_.size() != d) {
    throw std::invalid_argument(
        "PositionDmp: inconsistent shapes (weights " + std::to_string(weights_.rows()) + "x" +
        std::to_string(weights_.cols()) + ", expected " + std::to_string(params.num_basis) + "x" +
        std::to_string(d) + "; start " + std::to_string(start_.size()) + ", velocity " +
        std::to_string(start_velocity_.size()) + ")");
  }
  requireFinite(weights_, "PositionDmp weights");
  requireFinite(start_, "PositionDmp start");
  requireFinite(goal_, "PositionDmp goal");
  requireFinite(start_velocity_, "PositionDmp start velocity");
}

Eigen::MatrixXd PositionDmp::forcingTargets(const Eigen::VectorXd& times,
                                            const Eigen::MatrixXd& positions,
                                            const Eigen::MatrixXd& velocities,
                                            const Eigen::MatrixXd& accelerations,
                                            const Eigen::VectorXd& phases,
                                            const DmpParameters& params) {
  const Eigen::Index m = times.size();
  const double tau = times[m - 1] - times[0];
  const double k = params.stiffness();
  const double d = params.damping();
  const Eigen::RowVectorXd y0 = positions.row(0);
  const Eigen::RowVectorXd g = positions.row(m - 1);
  Eigen::MatrixXd f(m, positions.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    // From tau^2 ydd = K (g - y) - D tau yd - K (g - y0) x + K f.
    f.row(i) = (tau * tau * accelerations.row(i) + d * tau * velocities.row(i)) / k -
               (g - positions.row(i)) + (g - y0) * phases[i];
  }
  return f;
}

PositionDmp PositionDmp::learn(const Eigen::VectorXd& times, const Eigen::MatrixXd& positions,
                               const DmpParameters& params) {
  params.validate();
  validateDemoTimes(times, "PositionDmp::learn");
  if (positions.rows() != times.size() || positions.cols() < 1) {
    throw std::invalid_argument("PositionDmp::learn: positions must be " +
                                std::to_string(times.size()) + " x D with D >= 1, got " +
                                std::to_string(positions.rows()) + " x " +
                                std::to_string(positions.cols()));
  }
  requireFinite(positions, "PositionDmp::learn positions");
  const double tau = times[times.size() - 1] - times[0];
  const CanonicalSystem canonical(params.alpha_x);
  const GaussianBasis basis(params.num_basis, canonical, params.width_scale);
  const SmoothDerivatives der = smoothDerivatives(times, positions, params.derivatives);
  const Eigen::VectorXd phases = demoPhases(times, canonical);
  const Eigen::MatrixXd targets =
      forcingTargets(times, positions, der.velocity, der.acceleration, phases, params);
  Eigen::MatrixXd weights = fitForcingWeights(basis, phases, targets, params.ridge);
  return PositionDmp(params, tau, std::move(weights), positions.row(0).transpose(),
                     positions.row(positions.rows() - 1).transpose(),
                     der.velocity.row(0).transpose());
}

void PositionDmp::rolloutInto(const double* start, const double* goal, const double* start_velocity,
                              double tau, double dt, int steps, double* out,
                              double* out_velocity) const {
  const int dim = dims();
  constexpr int kStackDims = 16;
  double stack[4 * kStackDims];
  std::vector<double> heap;
  double* buf = stack;
  if (dim > kStackDims) {
    heap.resize(static_cast<size_t>(4 * dim));
    buf = heap.data();
  }
  double* y = buf;
  double* v = buf + dim;
  double* f = buf + 2 * dim;
  double* u0 = buf + 3 * dim;
  double act_stack[64];
  std::vector<double> act_heap;
  double* act = act_stack;
  if (basis_.maxActive() > 64) {
    act_heap.resize(static_cast<size_t>(basis_.maxActive()));
    act = act_heap.data();
  }

  const LinearStep step = LinearStep::make(params_.stiffness(), params_.damping(), dt / tau);
  const double decay = canonical_.stepFactor(dt, tau);
  const double x_end = std::exp(-params_.alpha_x);
  double x = 1.0;
  int count = 0;
  GaussianBasis::Cursor cursor;
  int begin = basis_.gatedActivations(x, act, &count, &cursor);
  forcing(act, begin, count, f);
  for (int d = 0; d < dim; ++d) {
    y[d] = start[d];
    v[d] = tau * start_velocity[d];
    u0[d] = goal[d] - (goal[d] - start[d]) * x + f[d];
    out[d] = y[d];
    if (out_velocity) out_velocity[d] = start_velocity[d];
  }
  const double inv_tau = 1.0 / tau;
  for (int k = 1; k < steps; ++k) {
    x *= decay;
    const double gate = forcingGate(x, x_end, params_.alpha_x);
    double* row = out + static_cast<ptrdiff_t>(k) * dim;
    if (gate > 0.0) {
      begin = basis_.gatedActivations(x, act, &count, &cursor);
      forcing(act, begin, count, f);
    }
    for (int d = 0; d < dim; ++d) {
      const double u1 = goal[d] + gate * (f[d] - (goal[d] - start[d]) * x);
      step.apply(y[d], v[d], u0[d], u1);
      u0[d] = u1;
      row[d] = y[d];
    }
    if (out_velocity) {
      double* vrow = out_velocity + static_cast<ptrdiff_t>(k) * dim;
      for (int d = 0; d < dim; ++d) vrow[d] = v[d] * inv_tau;
    }
  }
}

PositionTrajectory PositionDmp::rollout(const PositionRolloutOptions& o) const {
  const int dim = dims();
  const double tau = o.tau.value_or(tau_);
  const double duration = o.duration.value_or(tau);
  if (!(tau > 0.0) || !std::isfinite(tau)) throw std::invalid_argument("rollout: tau must be > 0");
  if (!(o.dt > 0.0) || !std::isfinite(o.dt)) throw std::invalid_argument("rollout: dt must be > 0");
  if (!(duration >= 0.0) || !std::isfinite(duration)) {
    throw std::invalid_argument("rollout: duration must be >= 0");
  }
  auto pick = [&](const std::optional<Eigen::VectorXd>& given, const Eigen::VectorXd& learned,
                  const char* name) -> Eigen::VectorXd {
    if (!given) return learned;
    if (given->size() != dim) {
      throw std::invalid_argument(std::string("rollout: ") + name + " has " +
                                  std::to_string(given->size()) + " dims, the DMP has " +
                                  std::to_string(dim));
    }
    requireFinite(*given, name);
    return *given;
  };
  const Eigen::VectorXd start = pick(o.start, start_, "start");
  const Eigen::VectorXd goal = pick(o.goal, goal_, "goal");
  // Default start velocity: the demo's, time-scaled like the rest of the movement.
  const Eigen::VectorXd vel0 =
      pick(o.start_velocity, Eigen::VectorXd(start_velocity_ * (tau_ / tau)), "start_velocity");
  const double steps_real = std::floor(duration / o.dt + 1e-9) + 1.0;
  if (steps_real > 5e7) throw std::invalid_argument("rollout: more than 5e7 steps requested");
  const int steps = static_cast<int>(steps_real);

  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  RowMajor rows(steps, dim), vel_rows(steps, dim);
  rolloutInto(start.data(), goal.data(), vel0.data(), tau, o.dt, steps, rows.data(),
              vel_rows.data());
  PositionTrajectory traj;
  traj.times = Eigen::VectorXd::LinSpaced(steps, 0.0, (steps - 1) * o.dt);
  traj.positions = rows;
  traj.velocities = vel_rows;
  return traj;
}

}  // namespace lfd
