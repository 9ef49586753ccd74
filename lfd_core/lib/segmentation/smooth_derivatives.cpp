#include "lfd_core/segmentation/smooth_derivatives.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

// Coefficients (rows: derivative order 1 and 2) that map the window samples to the derivatives
// at the sample whose offset from the window start is `center`. Offsets are scaled by `scale`
// so the Vandermonde system stays well conditioned.
Eigen::Matrix<double, 2, Eigen::Dynamic> derivativeCoefficients(const double* t, int window,
                                                                int center, int order) {
  const double t0 = t[center];
  const double scale = std::max(std::abs(t[window - 1] - t[0]), 1e-300);
  Eigen::MatrixXd vander(window, order + 1);
  for (int r = 0; r < window; ++r) {
    const double s = (t[r] - t0) / scale;
    double p = 1.0;
    for (int c = 0; c <= order; ++c) {
      vander(r, c) = p;
      p *= s;
    }
  }
  // Least-squares polynomial coefficients a = pinv(V) y; derivative at s=0: a1 / scale,
  // 2 a2 / scale^2.
  const Eigen::MatrixXd pinv =
      (vander.transpose() * vander).ldlt().solve(vander.transpose());  // (order+1) x window
  Eigen::Matrix<double, 2, Eigen::Dynamic> coeffs(2, window);
  coeffs.row(0) = pinv.row(1) / scale;
  coeffs.row(1) = 2.0 * pinv.row(2) / (scale * scale);
  return coeffs;
}

}  // namespace

SmoothDerivatives smoothDerivatives(const Eigen::VectorXd& times, const Eigen::MatrixXd& values,
                                    const SmoothDerivativeOptions& options) {
  const int m = static_cast<int>(times.size());
  if (values.rows() != m) {
    throw std::invalid_argument("smoothDerivatives: " + std::to_string(m) + " time stamps but " +
                                std::to_string(values.rows()) + " value rows");
  }
  if (options.poly_order < 2 || options.half_window < 1) {
    throw std::invalid_argument("smoothDerivatives: need poly_order >= 2 and half_window >= 1");
  }
  if (m < options.poly_order + 1) {
    throw std::invalid_argument("smoothDerivatives: " + std::to_string(m) +
                                " samples are too few for a degree-" +
                                std::to_string(options.poly_order) + " fit");
  }
  for (int i = 1; i < m; ++i) {
    if (!(times[i] > times[i - 1])) {
      throw std::invalid_argument(
          "smoothDerivatives: time stamps must be strictly increasing (index " + std::to_string(i) +
          ")");
    }
  }
  const int window = std::min(m, 2 * options.half_window + 1);
  const int order = std::min(options.poly_order, window - 1);
  const int half = window / 2;

  SmoothDerivatives out;
  out.velocity.resize(m, values.cols());
  out.acceleration.resize(m, values.cols());

  const double mean_dt = (times[m - 1] - times[0]) / (m - 1);
  double max_dev = 0.0;
  for (int i = 1; i < m; ++i)
    max_dev = std::max(max_dev, std::abs(times[i] - times[i - 1] - mean_dt));
  const bool uniform = max_dev < 1e-9 * mean_dt;

  Eigen::Matrix<double, 2, Eigen::Dynamic> interior;
  if (uniform && m >= window) interior = derivativeCoefficients(times.data(), window, half, order);

  for (int i = 0; i < m; ++i) {
    const int start = std::clamp(i - half, 0, m - window);
    Eigen::Matrix<double, 2, Eigen::Dynamic> coeffs;
    const bool is_interior = uniform && (start == i - half);
    if (!is_interior)
      coeffs = derivativeCoefficients(times.data() + start, window, i - start, order);
    const auto& c = is_interior ? interior : coeffs;
    const auto block = values.middleRows(start, window);
    out.velocity.row(i).noalias() = c.row(0) * block;
    out.acceleration.row(i).noalias() = c.row(1) * block;
  }
  return out;
}

Eigen::MatrixXd gaussianSmooth(const Eigen::VectorXd& times, const Eigen::MatrixXd& values,
                               double sigma) {
  if (!(sigma >= 0.0) || !std::isfinite(sigma))
    throw std::invalid_argument("gaussianSmooth: sigma must be a finite value >= 0");
  if (times.size() != values.rows())
    throw std::invalid_argument("gaussianSmooth: " + std::to_string(times.size()) + " times but " +
                                std::to_string(values.rows()) + " samples");
  if (!times.allFinite() || !values.allFinite())
    throw std::invalid_argument("gaussianSmooth: NaN or infinite input");
  const Eigen::Index m = times.size();
  for (Eigen::Index i = 1; i < m; ++i)
    if (!(times[i] > times[i - 1]))
      throw std::invalid_argument("gaussianSmooth: times must be strictly increasing");
  if (sigma == 0.0 || m < 2) return values;
  const double reach = 4.0 * sigma, inv2s2 = 0.5 / (sigma * sigma);
  Eigen::MatrixXd out(m, values.cols());
  Eigen::Index lo = 0, hi = 0;  // window [lo, hi) slides with i
  for (Eigen::Index i = 0; i < m; ++i) {
    while (times[i] - times[lo] > reach) ++lo;
    while (hi < m && times[hi] - times[i] <= reach) ++hi;
    double s0 = 0.0;
    Eigen::RowVectorXd acc = Eigen::RowVectorXd::Zero(values.cols());
    for (Eigen::Index j = lo; j < hi; ++j) {
      const double d = times[j] - times[i], w = std::exp(-d * d * inv2s2);
      s0 += w;
      acc += w * values.row(j);
    }
    out.row(i) = acc / s0;
  }
  return out;
}

}  // namespace lfd
