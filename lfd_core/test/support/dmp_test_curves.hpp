// Smooth demo curves shared by the DMP tests (not a test binary: no test_ prefix).
#pragma once

#include <Eigen/Core>

#include <cmath>

namespace lfd_test {

/// 2-D curve: a loop-like path with non-zero start velocity, `samples` points over `duration`.
inline Eigen::MatrixXd curve2d(const Eigen::VectorXd& t, double duration) {
  Eigen::MatrixXd y(t.size(), 2);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / duration;
    y(i, 0) = 0.4 * s + 0.15 * std::sin(2.0 * M_PI * s);
    y(i, 1) = 0.2 * std::sin(M_PI * s) + 0.05 * std::cos(3.0 * M_PI * s);
  }
  return y;
}

/// 3-D curve: a reach-like motion (minimum-jerk progress) with a sideways bump and a lift.
inline Eigen::MatrixXd curve3d(const Eigen::VectorXd& t, double duration) {
  Eigen::MatrixXd y(t.size(), 3);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / duration;
    const double mj = 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
    y(i, 0) = 0.3 + 0.25 * mj;
    y(i, 1) = -0.2 + 0.1 * mj + 0.08 * std::sin(M_PI * mj);
    y(i, 2) = 0.8 + 0.15 * std::sin(M_PI * s) * std::sin(M_PI * s) + 0.05 * mj;
  }
  return y;
}

inline double extent(const Eigen::MatrixXd& y) {
  return (y.colwise().maxCoeff() - y.colwise().minCoeff()).maxCoeff();
}

inline double rmse(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return std::sqrt((a - b).rowwise().squaredNorm().mean());
}

}  // namespace lfd_test
