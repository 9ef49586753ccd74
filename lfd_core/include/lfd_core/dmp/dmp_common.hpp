// Pieces shared by the position, orientation and gripper DMPs.
//
// Transformation system (Hoffmann, Pastor et al. 2009, "Biologically-inspired dynamical systems for
// movement generation", ICRA), written in normalized time sigma = t / tau with v = tau * dy/dt:
//     dv/dsigma = K (u - y) - D v,    dy/dsigma = v,
//     u(x) = g - (g - y0) x + f(x),   f(x) = x * sum_i psi_i(x) w_i / sum_i psi_i(x).
// Why this form: the forcing term is not multiplied by (g - y0), so a dimension whose start and
// goal coincide learns and reproduces its motion without any division blow-up, and a goal that
// moves during execution only shifts the attractor (no rescaling of the learned shape). Both the
// (g - y0) x term and f vanish with the phase, so after the movement the system is a critically
// damped spring on g: rolling out past the duration settles instead of drifting.
//
// Integration: the linear part is discretized exactly (matrix exponential) with u linearly
// interpolated over each step (first-order hold). The only integration error is that
// interpolation, O(dt^2), which keeps reproductions accurate even at coarse dt and costs the same
// as an Euler step.
#pragma once

#include "lfd_core/dmp/dmp_canonical.hpp"
#include "lfd_core/segmentation/smooth_derivatives.hpp"

#include <Eigen/Core>

#include <cmath>

namespace lfd {

/// Hyper-parameters of the DMPs of one segment (shared by position, orientation and gripper).
struct DmpParameters {
  int num_basis = 50;                   ///< Gaussian basis functions per dimension
  double alpha_x = 6.907755278982137;   ///< phase decay; x(tau) = exp(-alpha_x) = 1e-3
  double width_scale = 1.0;             ///< h_i = width_scale / spacing^2
  double alpha_z = 25.0;                ///< damping D = alpha_z
  double beta_z = 6.25;                 ///< stiffness K = alpha_z * beta_z (critical: alpha/4)
  double ridge = 1e-6;                  ///< relative ridge on each weight (of its data energy)
  SmoothDerivativeOptions derivatives;  ///< Savitzky-Golay window for demo velocities

  double stiffness() const { return alpha_z * beta_z; }
  double damping() const { return alpha_z; }
  /// Throws std::invalid_argument with the offending field.
  void validate() const;
};

/// Normalized time (fraction of tau) over which the phase-driven part of the attractor,
/// f(x) - (g - y0) x, fades to zero after the movement's duration. Demos that do not end exactly
/// at rest leave a large last weight (their end acceleration divided by the small phase); without
/// the gate that weight would keep pushing after tau. During t <= tau the gate is exactly 1, so
/// learning and reproduction are unaffected.
constexpr double kForcingFadeOut = 0.005;

/// Gate multiplying f(x) - (g - y0) x: 1 for x >= x_end = exp(-alpha_x) (t <= tau), then a C1
/// smoothstep to 0 over kForcingFadeOut of normalized time.
inline double forcingGate(double x, double x_end, double alpha_x) {
  if (x >= x_end) return 1.0;
  const double s = std::log(x_end / x) / (alpha_x * kForcingFadeOut);
  if (s >= 1.0) return 0.0;
  return 1.0 - s * s * (3.0 - 2.0 * s);
}

/// Fewest samples a segment needs to be learned (derivatives need a polynomial fit).
constexpr int kMinDmpSamples = 8;

/// Exact discretization of dy = v, dv = K (u - y) - D v over a normalized-time step h with
/// u interpolated linearly between u0 (start of step) and u1 (end of step).
struct LinearStep {
  double a_yy = 1, a_yv = 0, a_vy = 0, a_vv = 1;
  double b_y0 = 0, b_y1 = 0, b_v0 = 0, b_v1 = 0;
  double h = 0;

  static LinearStep make(double stiffness, double damping, double h);

  inline void apply(double& y, double& v, double u0, double u1) const {
    const double yn = a_yy * y + a_yv * v + b_y0 * u0 + b_y1 * u1;
    const double vn = a_vy * y + a_vv * v + b_v0 * u0 + b_v1 * u1;
    y = yn;
    v = vn;
  }
};

/// Phases x_k of the sample times of a demo (relative to its first sample) for duration tau.
Eigen::VectorXd demoPhases(const Eigen::VectorXd& times, const CanonicalSystem& canonical);

/// Ridge regression of forcing targets (M x D) on the gated normalized activations of the basis at
/// the given phases (M). Uses the band structure of the design matrix: O(M * active^2 + N^3).
Eigen::MatrixXd fitForcingWeights(const GaussianBasis& basis, const Eigen::VectorXd& phases,
                                  const Eigen::MatrixXd& targets, double ridge);

/// Validates demo time stamps: finite, strictly increasing, at least kMinDmpSamples, positive
/// duration. `what` names the caller in the error message.
void validateDemoTimes(const Eigen::VectorXd& times, const char* what);

/// Throws std::invalid_argument naming the first non-finite entry of `m`.
void requireFinite(const Eigen::MatrixXd& m, const char* what);

}  // namespace lfd
