// n-dimensional position DMP (Hoffmann/Pastor 2009 form, see dmp_common.hpp). A 1-D instance is
// the gripper DMP. Learning: ridge regression on Gaussian basis functions of forcing targets
// computed from the demo and its Savitzky-Golay velocities/accelerations. Rollout: exact
// discretization of the linear transformation system; allocation-free inner loop.
#pragma once

#include "lfd_core/dmp/dmp_common.hpp"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace lfd {

/// A rollout of an n-D DMP: one row per time step.
struct PositionTrajectory {
  Eigen::VectorXd times;       ///< starts at 0
  Eigen::MatrixXd positions;   ///< steps x D
  Eigen::MatrixXd velocities;  ///< steps x D (dy/dt)
};

/// What to change for a rollout; unset fields keep the learned (demo) values.
struct PositionRolloutOptions {
  double dt = 0.01;                      ///< integration / output step [s]
  std::optional<double> tau;             ///< movement duration [s]
  std::optional<double> duration;        ///< rollout length [s] (default tau; may exceed it)
  std::optional<Eigen::VectorXd> start;  ///< y0
  std::optional<Eigen::VectorXd> goal;   ///< g
  std::optional<Eigen::VectorXd> start_velocity;  ///< dy/dt at t = 0 (default: the demo's)
};

class PositionDmp {
 public:
  PositionDmp() = default;
  /// Rebuilds a learned DMP from stored parameters (e.g. the skill library). weights: N x D.
  PositionDmp(const DmpParameters& params, double tau, Eigen::MatrixXd weights,
              Eigen::VectorXd start, Eigen::VectorXd goal, Eigen::VectorXd start_velocity);

  /// times: M strictly increasing; positions: M x D. Throws std::invalid_argument on bad input.
  static PositionDmp learn(const Eigen::VectorXd& times, const Eigen::MatrixXd& positions,
                           const DmpParameters& params = {});

  /// Learn from precomputed velocities/accelerations (used by SegmentDmp, which shares the phase
  /// and the least-squares factorization among position, orientation and gripper).
  static Eigen::MatrixXd forcingTargets(const Eigen::VectorXd& times,
                                        const Eigen::MatrixXd& positions,
                                        const Eigen::MatrixXd& velocities,
                                        const Eigen::MatrixXd& accelerations,
                                        const Eigen::VectorXd& phases, const DmpParameters& params);

  int dims() const { return static_cast<int>(goal_.size()); }
  double tau() const { return tau_; }
  const DmpParameters& parameters() const { return params_; }
  const Eigen::MatrixXd& weights() const { return weights_; }
  const Eigen::VectorXd& start() const { return start_; }
  const Eigen::VectorXd& goal() const { return goal_; }
  const Eigen::VectorXd& startVelocity() const { return start_velocity_; }
  const CanonicalSystem& canonical() const { return canonical_; }
  const GaussianBasis& basis() const { return basis_; }

  PositionTrajectory rollout(const PositionRolloutOptions& options = {}) const;

  /// Tight fixed-step rollout: writes `steps` rows (t = 0, dt, ...) of positions into `out`
  /// (row-major steps x D) and, when out_velocity is not null, dy/dt likewise. No allocation for
  /// D <= 16; the benchmark measures this.
  void rolloutInto(const double* start, const double* goal, const double* start_velocity,
                   double tau, double dt, int steps, double* out,
                   double* out_velocity = nullptr) const;

  /// Forcing f_d(x) of every dimension from gated activations [begin, begin + count).
  inline void forcing(const double* act, int begin, int count, double* f) const {
    const int d_count = dims();
    const Eigen::Index n = weights_.rows();
    for (int d = 0; d < d_count; ++d) {
      const double* w = weights_.data() + d * n + begin;
      double s = 0.0;
      for (int i = 0; i < count; ++i) s += act[i] * w[i];
      f[d] = s;
    }
  }

 private:
  DmpParameters params_;
  CanonicalSystem canonical_;
  GaussianBasis basis_;
  double tau_ = 1.0;
  Eigen::MatrixXd weights_;  // N x D, column-major: one contiguous column per dimension
  Eigen::VectorXd start_, goal_, start_velocity_;
};

}  // namespace lfd
