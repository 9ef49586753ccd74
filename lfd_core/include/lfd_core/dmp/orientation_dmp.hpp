// Orientation DMP on unit quaternions (Ude, Nemec, Petric, Morimoto 2014, "Orientation in Cartesian
// space dynamic movement primitives", ICRA), in normalized time sigma = t / tau, eta = tau * omega:
//     d eta / d sigma = K (e(q) - e(q0) x + f(x)) - D eta,    dq / d sigma = 1/2 eta * q,
//     e(q) = 2 log(g * conj(q)).
// Like the position DMP we use the Hoffmann-style start coupling "- e(q0) x" rather than Ude's
// scaling of f by diag(e(q0)), so q0 ~ g needs no division and the forcing vanishes with x.
// Integration: Heun (second order) on the group, q advanced by the quaternion exponential, so q
// stays a unit quaternion by construction.
#pragma once

#include "lfd_core/dmp/dmp_common.hpp"
#include "lfd_core/dmp/quaternion_log.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>

namespace lfd {

struct OrientationTrajectory {
  Eigen::VectorXd times;
  Eigen::MatrixXd quaternions;         ///< steps x 4, (w, x, y, z)
  Eigen::MatrixXd angular_velocities;  ///< steps x 3, world frame [rad/s]
};

struct OrientationRolloutOptions {
  double dt = 0.01;
  std::optional<double> tau;
  std::optional<double> duration;
  std::optional<Eigen::Quaterniond> start;
  std::optional<Eigen::Quaterniond> goal;
  std::optional<Eigen::Vector3d> start_angular_velocity;
};

/// Angular velocity and acceleration (world frame) of a continuous unit-quaternion path, from
/// Savitzky-Golay derivatives of its components: omega = 2 vec(dq * conj(q)),
/// domega = 2 vec(ddq * conj(q)).
struct AngularDerivatives {
  Eigen::MatrixXd omega;      ///< M x 3
  Eigen::MatrixXd omega_dot;  ///< M x 3
};
AngularDerivatives angularDerivatives(const Eigen::VectorXd& times,
                                      const std::vector<Eigen::Quaterniond>& quaternions,
                                      const SmoothDerivativeOptions& options);

class OrientationDmp {
 public:
  /// Integration state: orientation and eta = tau * omega.
  struct State {
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    Eigen::Vector3d eta = Eigen::Vector3d::Zero();
  };

  OrientationDmp() = default;
  OrientationDmp(const DmpParameters& params, double tau, Eigen::MatrixXd weights,
                 const Eigen::Quaterniond& start, const Eigen::Quaterniond& goal,
                 const Eigen::Vector3d& start_angular_velocity);

  /// quaternions_wxyz: M x 4. Non-unit rows are normalized (normalizedInput() reports it) and sign
  /// flips removed. Throws std::invalid_argument on NaN, zero norm, too few samples.
  static OrientationDmp learn(const Eigen::VectorXd& times, const Eigen::MatrixXd& quaternions_wxyz,
                              const DmpParameters& params = {});

  /// Forcing targets for a continuous unit quaternion path (M x 3).
  static Eigen::MatrixXd forcingTargets(const Eigen::VectorXd& times,
                                        const std::vector<Eigen::Quaterniond>& quaternions,
                                        const AngularDerivatives& derivatives,
                                        const Eigen::VectorXd& phases, const DmpParameters& params);

  double tau() const { return tau_; }
  const DmpParameters& parameters() const { return params_; }
  const Eigen::MatrixXd& weights() const { return weights_; }  ///< N x 3
  const Eigen::Quaterniond& start() const { return start_; }
  const Eigen::Quaterniond& goal() const { return goal_; }
  const Eigen::Vector3d& startAngularVelocity() const { return start_angular_velocity_; }
  const GaussianBasis& basis() const { return basis_; }
  const CanonicalSystem& canonical() const { return canonical_; }
  bool normalizedInput() const { return normalized_input_; }
  int signFlips() const { return sign_flips_; }

  OrientationTrajectory rollout(const OrientationRolloutOptions& options = {}) const;

  inline Eigen::Vector3d forcing(const double* act, int begin, int count) const {
    Eigen::Vector3d f;
    const Eigen::Index n = weights_.rows();
    for (int d = 0; d < 3; ++d) {
      const double* w = weights_.data() + d * n + begin;
      double s = 0.0;
      for (int i = 0; i < count; ++i) s += act[i] * w[i];
      f[d] = s;
    }
    return f;
  }

  /// One Heun step of normalized length h. drive0/drive1 = f(x) - e(q0) x at the start / end of
  /// the step (the time-varying input); goal is the (possibly moving) attractor.
  void step(State& state, const Eigen::Quaterniond& goal, const Eigen::Vector3d& drive0,
            const Eigen::Vector3d& drive1, double h) const;

 private:
  friend struct SegmentDmp;
  DmpParameters params_;
  CanonicalSystem canonical_;
  GaussianBasis basis_;
  double tau_ = 1.0;
  Eigen::MatrixXd weights_;  // N x 3
  Eigen::Quaterniond start_ = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond goal_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d start_angular_velocity_ = Eigen::Vector3d::Zero();
  bool normalized_input_ = false;
  int sign_flips_ = 0;
};

}  // namespace lfd
