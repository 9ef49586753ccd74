// Canonical system and Gaussian basis functions shared by every DMP of one segment.
//
// Phase: x(t) = exp(-alpha_x * t / tau), so x(0) = 1 and x(tau) = exp(-alpha_x) (1e-3 by default).
// The same phase drives position, orientation and gripper, which keeps them synchronized.
// Basis functions: N Gaussians psi_i(x) = exp(-h_i (x - c_i)^2) whose centers are spaced evenly in
// normalized time (c_i = exp(-alpha_x * i / (N - 1))) and whose widths come from the spacing to the
// neighbouring center. The forcing term is x * sum_i psi_i w_i / sum_i psi_i: the factor x gates it
// to zero at the end of the movement.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace lfd {

/// Exponentially decaying phase x(t) = exp(-alpha * t / tau).
class CanonicalSystem {
 public:
  /// alpha: decay constant; x(tau) = exp(-alpha). Must be > 0.
  explicit CanonicalSystem(double alpha = 6.907755278982137);

  double alpha() const { return alpha_; }
  /// Phase at time t for a movement of duration tau (t may exceed tau; x keeps decaying).
  double phase(double t, double tau) const;
  /// Multiplicative phase decay over one step: x(t + dt) = x(t) * stepFactor(dt, tau).
  double stepFactor(double dt, double tau) const;

 private:
  double alpha_;
};

/// N Gaussian basis functions over the phase, evaluated sparsely (only the ones that matter).
class GaussianBasis {
 public:
  GaussianBasis() = default;
  /// num_basis >= 2; width_scale multiplies h_i = 1 / (c_i - c_{i+1})^2 (larger = narrower).
  GaussianBasis(int num_basis, const CanonicalSystem& canonical, double width_scale = 1.0);

  int size() const { return static_cast<int>(centers_.size()); }
  const Eigen::VectorXd& centers() const { return centers_; }
  const Eigen::VectorXd& widths() const { return widths_; }

  /// Half-open index range [begin, end) of basis functions that are non-negligible at phase x.
  /// Outside it every psi_i(x) < exp(-kCutoffExponent).
  void activeRange(double x, int* begin, int* end) const;

  /// Writes x * psi_i(x) / sum_j psi_j(x) for i in [begin, end) to out[0 .. end-begin), the
  /// "gated normalized activations"; returns begin. When x is beyond the last (or before the
  /// first) center so far that every psi underflows, the limit (all weight on the nearest basis)
  /// is used, so the forcing term stays continuous.
  int gatedActivations(double x, double* out, int* count) const;

  /// Active-range cursor for non-increasing phases (a rollout): amortized O(1) instead of two
  /// binary searches per call. Start each rollout with a fresh cursor.
  struct Cursor {
    int begin = 0;
    int end = 0;
  };
  int gatedActivations(double x, double* out, int* count, Cursor* cursor) const;

  /// Dense version used for learning: row of length size().
  void gatedActivationsDense(double x, double* row) const;

  /// Largest number of simultaneously active basis functions (buffer size for gatedActivations).
  int maxActive() const { return max_active_; }

  static constexpr double kCutoffExponent = 30.0;

 private:
  int gatedActivationsInRange(double x, int begin, int end, double* out, int* count) const;

  Eigen::VectorXd centers_;
  Eigen::VectorXd widths_;
  // Active interval of each basis function [lo_i, hi_i] and monotone envelopes used to find the
  // active index range by binary search.
  std::vector<double> lo_envelope_;  // min_{j <= i} lo_j, non-increasing
  std::vector<double> hi_envelope_;  // max_{j >= i} hi_j, non-increasing
  int max_active_ = 0;
};

}  // namespace lfd
