#include "lfd_core/kinematics/inverse_kinematics.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

void validateOptions(const IkOptions& o) {
  if (o.max_iterations < 1) throw std::invalid_argument("IkOptions: max_iterations must be >= 1");
  if (!(o.position_tolerance > 0) || !(o.orientation_tolerance > 0))
    throw std::invalid_argument("IkOptions: tolerances must be positive");
  if ((o.weights.array() < 0).any() || !o.weights.allFinite() || o.weights.sum() <= 0)
    throw std::invalid_argument("IkOptions: weights must be finite, >= 0 and not all zero");
  if (!(o.max_step > 0)) throw std::invalid_argument("IkOptions: max_step must be positive");
  if (o.joint_costs.size() > 0 &&
      (!o.joint_costs.allFinite() || (o.joint_costs.array() <= 0).any()))
    throw std::invalid_argument("IkOptions: joint_costs must be finite and positive");
  if (o.singular_threshold <= 0 || o.max_damping < 0 || o.error_damping < 0)
    throw std::invalid_argument("IkOptions: damping parameters must be >= 0 (threshold > 0)");
}

}  // namespace

InverseKinematics::InverseKinematics(const KinematicChain& chain, const IkOptions& options)
    : chain_(chain) {
  setOptions(options);
  const int n = chain_.dof();
  if (n == 0) throw std::invalid_argument("InverseKinematics: the chain has no movable joint");
  preferred_ = chain_.midRange();
  range_ = chain_.upperLimits() - chain_.lowerLimits();
  jac_.resize(6, n);
  jac_w_.resize(6, n);
  q_.resize(n);
  dq_.resize(n);
  z_.resize(n);
  tmp_n_.resize(n);
  frozen_.resize(n);
}

void InverseKinematics::setOptions(const IkOptions& options) {
  validateOptions(options);
  if (options.joint_costs.size() != 0 && options.joint_costs.size() != chain_.dof())
    throw std::invalid_argument("IkOptions: joint_costs has " +
                                std::to_string(options.joint_costs.size()) + " values, chain has " +
                                std::to_string(chain_.dof()) + " joints");
  options_ = options;
  inv_sqrt_cost_ = options.joint_costs.size() == 0
                       ? Eigen::VectorXd::Ones(chain_.dof())
                       : Eigen::VectorXd(options.joint_costs.cwiseSqrt().cwiseInverse());
}

void InverseKinematics::setPreferredPosture(const Eigen::Ref<const Eigen::VectorXd>& q) {
  if (q.size() != chain_.dof())
    throw std::invalid_argument("InverseKinematics: preferred posture has " +
                                std::to_string(q.size()) + " values, chain has " +
                                std::to_string(chain_.dof()) + " joints");
  preferred_ = q;
  chain_.clampToLimits(preferred_);
}

Vector6d InverseKinematics::poseError(const Eigen::Isometry3d& target,
                                      const Eigen::Isometry3d& current) {
  Vector6d e;
  e.head<3>() = target.translation() - current.translation();
  const Eigen::AngleAxisd rot(target.linear() * current.linear().transpose());
  e.tail<3>() = rot.angle() * rot.axis();
  return e;
}

void InverseKinematics::secondaryTask(const Eigen::VectorXd& q) {
  const Eigen::VectorXd& lo = chain_.lowerLimits();
  const Eigen::VectorXd& hi = chain_.upperLimits();
  for (int i = 0; i < q.size(); ++i) {
    double z = options_.posture_gain * (preferred_[i] - q[i]);
    if (std::isfinite(range_[i]) && range_[i] > 0) {
      const double zone = options_.limit_zone * range_[i];
      const double d_lo = q[i] - lo[i], d_hi = hi[i] - q[i];
      if (d_lo < zone) z += options_.limit_gain * (zone - d_lo);
      if (d_hi < zone) z -= options_.limit_gain * (zone - d_hi);
    }
    z_[i] = z;
  }
}

void InverseKinematics::checkSolveInputs(const Eigen::Isometry3d& target,
                                         const Eigen::Ref<const Eigen::VectorXd>& seed) const {
  const int n = chain_.dof();
  if (seed.size() != n)
    throw std::invalid_argument("InverseKinematics: seed has " + std::to_string(seed.size()) +
                                " values, chain has " + std::to_string(n) + " joints");
  if (!seed.allFinite()) throw std::invalid_argument("InverseKinematics: seed is not finite");
  if (!target.matrix().allFinite())
    throw std::invalid_argument("InverseKinematics: target pose is not finite");
}

void InverseKinematics::setNullSpaceTask(const IkResult& progress) {
  // Null-space motion moves the tip at second order; close to the goal it would keep the error
  // from shrinking below the tolerance, so the last iterations polish with the primary task only.
  const bool polishing =
      progress.position_error < options_.polish_factor * options_.position_tolerance &&
      progress.orientation_error < options_.polish_factor * options_.orientation_tolerance;
  if (polishing) {
    z_.setZero();
  } else {
    secondaryTask(q_);
    z_.array() /= inv_sqrt_cost_.array();  // so that the unscaled null-space step is z
  }
}

void InverseKinematics::dampedStep(const Vector6d& ew, int unweighted_axes, double eps2,
                                   double lambda_max2) {
  const int n = chain_.dof();
  const Matrix6d a = jac_w_ * jac_w_.transpose();
  eigen_.compute(a);
  const Vector6d& s = eigen_.eigenvalues();  // ascending; the first ones belong to free axes
  const double sigma_min2 = std::max(0.0, s[unweighted_axes]);
  double lambda2 = options_.error_damping * ew.squaredNorm() + 1e-10;
  if (sigma_min2 < eps2) lambda2 += (1.0 - sigma_min2 / eps2) * lambda_max2;
  const Matrix6d& v = eigen_.eigenvectors();
  const Vector6d inv_diag = (s.array().max(0.0) + lambda2).inverse();
  const Matrix6d a_inv = v * inv_diag.asDiagonal() * v.transpose();
  for (int i = 0; i < n; ++i)
    if (frozen_[i]) z_[i] = 0.0;
  // Primary task plus the damped null-space projection of the secondary task.
  const Vector6d jz = jac_w_ * z_;
  dq_.noalias() = jac_w_.transpose() * (a_inv * (ew - jz));
  dq_ += z_;
  dq_.array() *= inv_sqrt_cost_.array();  // back to joint units
  const double biggest = dq_.cwiseAbs().maxCoeff();
  if (biggest > options_.max_step) dq_ *= options_.max_step / biggest;
}

bool InverseKinematics::freezeJointsPushedPastLimits() {
  const int n = chain_.dof();
  const Eigen::VectorXd& lo = chain_.lowerLimits();
  const Eigen::VectorXd& hi = chain_.upperLimits();
  bool newly_frozen = false;
  for (int i = 0; i < n; ++i) {
    if (frozen_[i]) continue;
    const double next = q_[i] + dq_[i];
    if ((next < lo[i] && q_[i] <= lo[i] + 1e-9) || (next > hi[i] && q_[i] >= hi[i] - 1e-9)) {
      frozen_[i] = true;  // already at the limit and pushed further: let the others work
      jac_w_.col(i).setZero();
      newly_frozen = true;
    }
  }
  return newly_frozen;
}

bool InverseKinematics::solve(const Eigen::Isometry3d& target,
                              const Eigen::Ref<const Eigen::VectorXd>& seed, IkResult& result) {
  checkSolveInputs(target, seed);
  const int n = chain_.dof();
  result.failure.clear();
  const Vector6d& w = options_.weights;
  const Vector6d sqrt_w = w.cwiseSqrt();
  const Vector6d mask = (w.array() > 0).cast<double>();
  int unweighted_axes = 0;
  for (int k = 0; k < 6; ++k) unweighted_axes += w[k] > 0 ? 0 : 1;
  const double eps2 = options_.singular_threshold * options_.singular_threshold;
  const double lambda_max2 = options_.max_damping * options_.max_damping;

  q_ = seed;
  chain_.clampToLimits(q_);
  Eigen::Isometry3d pose;
  result.converged = false;
  result.iterations = 0;
  for (int it = 0; it <= options_.max_iterations; ++it) {
    chain_.forwardAndJacobian(q_, pose, jac_);
    const Vector6d e = poseError(target, pose).cwiseProduct(mask);
    result.position_error = e.head<3>().norm();
    result.orientation_error = e.tail<3>().norm();
    result.iterations = it;
    if (result.position_error <= options_.position_tolerance &&
        result.orientation_error <= options_.orientation_tolerance) {
      result.converged = true;
      break;
    }
    if (it == options_.max_iterations) break;

    const Vector6d ew = e.cwiseProduct(sqrt_w);
    // Weighted task rows and cost-scaled joint columns: the step is solved for dq' = C^1/2 dq.
    jac_w_ = sqrt_w.asDiagonal() * jac_ * inv_sqrt_cost_.asDiagonal();
    setNullSpaceTask(result);
    frozen_.setConstant(false);
    // Up to three passes: joints whose step would cross a limit are frozen and the step redone.
    for (int pass = 0; pass < 3; ++pass) {
      dampedStep(ew, unweighted_axes, eps2, lambda_max2);
      if (!freezeJointsPushedPastLimits()) break;
    }
    for (int i = 0; i < n; ++i)
      if (frozen_[i]) dq_[i] = 0.0;
    q_ += dq_;
    chain_.clampToLimits(q_);
  }
  result.q = q_;
  return result.converged;
}

IkResult InverseKinematics::solve(const Eigen::Isometry3d& target,
                                  const Eigen::Ref<const Eigen::VectorXd>& seed) {
  IkResult result;
  solve(target, seed, result);
  return result;
}

IkResult InverseKinematics::reach(const Eigen::Isometry3d& target,
                                  const Eigen::Ref<const Eigen::VectorXd>& seed) {
  IkResult best, trial;
  double best_cost = std::numeric_limits<double>::infinity();
  const int n = chain_.dof();
  const Eigen::VectorXd& lo = chain_.lowerLimits();
  const Eigen::VectorXd& hi = chain_.upperLimits();
  Eigen::VectorXd start(n);
  std::uint64_t state = 0x9E3779B97F4A7C15ULL;  // fixed: the query is deterministic
  const auto uniform = [&state]() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0);
  };
  for (int attempt = 0; attempt < options_.restarts + 2; ++attempt) {
    if (attempt == 0) {
      start = seed;
    } else if (attempt == 1) {
      start = preferred_;
    } else {
      for (int i = 0; i < n; ++i) {
        const double a = std::isfinite(lo[i]) ? lo[i] : -M_PI;
        const double b = std::isfinite(hi[i]) ? hi[i] : M_PI;
        start[i] = a + (0.1 + 0.8 * uniform()) * (b - a);
      }
    }
    solve(target, start, trial);
    const double cost = trial.position_error + 0.1 * trial.orientation_error;
    if (trial.converged) return trial;
    if (cost < best_cost) {  // false for a NaN or infinite cost
      best_cost = cost;
      best = trial;
    }
  }
  if (!std::isfinite(best_cost)) {
    // Every attempt's pose error overflowed (e.g. a target 1e300 m away): there is no best
    // effort to return, and a zero error would read as success.
    best.q = seed;
    chain_.clampToLimits(best.q);
    best.converged = false;
    best.position_error = best.orientation_error = std::numeric_limits<double>::infinity();
    best.failure = "the pose error is not finite for any seed (target position " +
                   std::to_string(target.translation().norm()) + " m from the chain base)";
  }
  return best;
}

}  // namespace lfd
