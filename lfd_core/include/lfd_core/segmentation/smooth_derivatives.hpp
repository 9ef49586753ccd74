// First and second time derivatives of sampled signals by local polynomial least squares
// (Savitzky-Golay). Works on non-uniform time stamps; uniform sampling takes a fast path that
// reuses one set of convolution coefficients for the interior. Near the ends the window is
// shifted inside the signal (asymmetric fit) instead of padding, so no artificial edge effects.
#pragma once

#include <Eigen/Core>

namespace lfd {

struct SmoothDerivativeOptions {
  int half_window = 5;  ///< window = 2 * half_window + 1 samples
  int poly_order = 4;   ///< local polynomial degree (>= 2 for accelerations)
};

struct SmoothDerivatives {
  Eigen::MatrixXd velocity;      ///< same shape as the input values (samples x dims)
  Eigen::MatrixXd acceleration;  ///< same shape
};

/// times: strictly increasing, length M; values: M x D. Requires M >= poly_order + 1.
/// The window shrinks to M when the signal is shorter than it. Throws std::invalid_argument.
SmoothDerivatives smoothDerivatives(const Eigen::VectorXd& times, const Eigen::MatrixXd& values,
                                    const SmoothDerivativeOptions& options = {});

/// Zero-phase low-pass of every column: Gaussian-weighted mean of standard deviation `sigma`
/// seconds (truncated at 4 sigma, renormalized at the ends), gain exp(-2 (pi sigma f)^2) at
/// frequency f. Why: a teleoperated demonstration carries the operator's tremor (~10 Hz), which a
/// DMP with enough basis functions would learn and replay. A local constant rather than a local
/// line: a recording starts and ends at rest, and a one-sided line fit there lets up to 77 % of a
/// 10 Hz tremor through (sigma 0.05 s), the one-sided mean 29 %. Exact on lines in the interior of
/// uniform sampling. times: strictly increasing; sigma = 0 returns values.
/// Throws std::invalid_argument on sigma < 0, NaN or a shape mismatch.
Eigen::MatrixXd gaussianSmooth(const Eigen::VectorXd& times, const Eigen::MatrixXd& values,
                               double sigma);

}  // namespace lfd
