#include "lfd_core/dmp/dmp_common.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace lfd {
namespace {

// exp(A) for a small dense matrix: scaling and squaring with a Taylor series (A here is 4x4 with a
// norm of a few units at most after scaling, so 20 terms reach machine precision).
Eigen::Matrix4d expm4(const Eigen::Matrix4d& a) {
  const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();
  int squarings = 0;
  if (norm > 0.5) squarings = static_cast<int>(std::ceil(std::log2(norm / 0.5)));
  const Eigen::Matrix4d scaled = a / std::ldexp(1.0, squarings);
  Eigen::Matrix4d result = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d term = Eigen::Matrix4d::Identity();
  for (int k = 1; k <= 20; ++k) {
    term = term * scaled / static_cast<double>(k);
    result += term;
  }
  for (int i = 0; i < squarings; ++i) result = result * result;
  return result;
}

}  // namespace

void DmpParameters::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(std::string("DmpParameters: ") + name +
                                  " must be positive and finite, got " + std::to_string(v));
    }
  };
  if (num_basis < 2 || num_basis > 10000) {
    throw std::invalid_argument("DmpParameters: num_basis must be in [2, 10000], got " +
                                std::to_string(num_basis));
  }
  positive(alpha_x, "alpha_x");
  positive(width_scale, "width_scale");
  positive(alpha_z, "alpha_z");
  positive(beta_z, "beta_z");
  if (!(ridge >= 0.0) || !std::isfinite(ridge)) {
    throw std::invalid_argument("DmpParameters: ridge must be >= 0");
  }
  if (derivatives.half_window < 1 || derivatives.poly_order < 2) {
    throw std::invalid_argument("DmpParameters: derivative half_window >= 1, poly_order >= 2");
  }
}

LinearStep LinearStep::make(double stiffness, double damping, double h) {
  if (!(h > 0.0) || !std::isfinite(h)) {
    throw std::invalid_argument("LinearStep: the normalized step dt / tau must be positive");
  }
  // Augmented state [y, v, u, du/dsigma]: u ramps linearly during the step.
  Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
  a(0, 1) = 1.0;
  a(1, 0) = -stiffness;
  a(1, 1) = -damping;
  a(1, 2) = stiffness;
  a(2, 3) = 1.0;
  const Eigen::Matrix4d e = expm4(a * h);
  LinearStep s;
  s.h = h;
  s.a_yy = e(0, 0);
  s.a_yv = e(0, 1);
  s.a_vy = e(1, 0);
  s.a_vv = e(1, 1);
  // u(sigma) = u0 + (u1 - u0) sigma / h  ->  contributions E02 u0 + E03 (u1 - u0) / h.
  s.b_y0 = e(0, 2) - e(0, 3) / h;
  s.b_y1 = e(0, 3) / h;
  s.b_v0 = e(1, 2) - e(1, 3) / h;
  s.b_v1 = e(1, 3) / h;
  return s;
}

void requireFinite(const Eigen::MatrixXd& m, const char* what) {
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      if (!std::isfinite(m(r, c))) {
        throw std::invalid_argument(std::string(what) +
                                    ": non-finite value (NaN or inf) at sample " +
                                    std::to_string(r) + ", column " + std::to_string(c));
      }
    }
  }
}

void validateDemoTimes(const Eigen::VectorXd& times, const char* what) {
  const Eigen::Index m = times.size();
  if (m < kMinDmpSamples) {
    throw std::invalid_argument(std::string(what) + ": segment has " + std::to_string(m) +
                                " samples; a DMP needs at least " + std::to_string(kMinDmpSamples));
  }
  requireFinite(times, what);
  for (Eigen::Index i = 1; i < m; ++i) {
    if (!(times[i] > times[i - 1])) {
      throw std::invalid_argument(
          std::string(what) + ": time stamps must be strictly increasing (" +
          std::to_string(times[i - 1]) + " then " + std::to_string(times[i]) + " at sample " +
          std::to_string(i) + ")");
    }
  }
}

Eigen::VectorXd demoPhases(const Eigen::VectorXd& times, const CanonicalSystem& canonical) {
  const double t0 = times[0];
  const double tau = times[times.size() - 1] - t0;
  Eigen::VectorXd x(times.size());
  for (Eigen::Index i = 0; i < times.size(); ++i) x[i] = canonical.phase(times[i] - t0, tau);
  return x;
}

Eigen::MatrixXd fitForcingWeights(const GaussianBasis& basis, const Eigen::VectorXd& phases,
                                  const Eigen::MatrixXd& targets, double ridge) {
  const int n = basis.size();
  const Eigen::Index dims = targets.cols();
  if (targets.rows() != phases.size()) {
    throw std::invalid_argument("fitForcingWeights: phases and targets differ in length");
  }
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, dims);
  std::vector<double> act(static_cast<size_t>(basis.maxActive()) + 1);
  for (Eigen::Index k = 0; k < phases.size(); ++k) {
    int count = 0;
    const int begin = basis.gatedActivations(phases[k], act.data(), &count);
    for (int i = 0; i < count; ++i) {
      const double ai = act[i];
      for (int j = i; j < count; ++j) gram(begin + i, begin + j) += ai * act[j];
      for (Eigen::Index d = 0; d < dims; ++d) rhs(begin + i, d) += ai * targets(k, d);
    }
  }
  gram.triangularView<Eigen::StrictlyLower>() = gram.transpose();
  // Relative ridge: each weight is shrunk in proportion to its own data energy, plus a tiny floor
  // so basis functions the demo never reaches get weight zero instead of a singular system.
  const double max_diag = gram.diagonal().maxCoeff();
  const double floor = 1e-12 * (max_diag > 0.0 ? max_diag : 1.0);
  for (int i = 0; i < n; ++i) gram(i, i) += ridge * gram(i, i) + floor;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(gram);
  if (ldlt.info() != Eigen::Success) {
    throw std::runtime_error("fitForcingWeights: the regularized normal equations are singular");
  }
  return ldlt.solve(rhs);
}

}  // namespace lfd
