#include "lfd_core/dmp/quaternion_log.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lfd {

Eigen::Vector3d quaternionLog(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in;
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest arc
  const Eigen::Vector3d v = q.vec();
  const double vn = v.norm();
  // atan2 is accurate over the whole range, unlike acos near w = 1.
  const double half_angle = std::atan2(vn, q.w());
  if (vn < 1e-12) return v;  // first-order: log(q) ~ v near the identity
  return v * (half_angle / vn);
}

Eigen::Quaterniond quaternionExp(const Eigen::Vector3d& r) {
  const double n = r.norm();
  if (n < 1e-12) {
    Eigen::Quaterniond q(1.0, r.x(), r.y(), r.z());
    return q.normalized();
  }
  const double s = std::sin(n) / n;
  return Eigen::Quaterniond(std::cos(n), s * r.x(), s * r.y(), s * r.z());
}

Eigen::Vector3d orientationError(const Eigen::Quaterniond& goal, const Eigen::Quaterniond& q) {
  return 2.0 * quaternionLog(goal * q.conjugate());
}

QuaternionSequence makeContinuousQuaternions(const Eigen::MatrixXd& rows) {
  if (rows.cols() != 4) {
    throw std::invalid_argument("quaternions need 4 columns (w, x, y, z), got " +
                                std::to_string(rows.cols()));
  }
  QuaternionSequence out;
  out.quaternions.reserve(static_cast<size_t>(rows.rows()));
  for (Eigen::Index i = 0; i < rows.rows(); ++i) {
    if (!rows.row(i).allFinite()) {
      throw std::invalid_argument("quaternion at sample " + std::to_string(i) +
                                  " contains NaN or inf");
    }
    const double n = rows.row(i).norm();
    if (n < 1e-6) {
      throw std::invalid_argument("quaternion at sample " + std::to_string(i) +
                                  " has (near) zero norm");
    }
    if (std::abs(n - 1.0) > 1e-6) out.normalized_input = true;
    Eigen::Quaterniond q(rows(i, 0) / n, rows(i, 1) / n, rows(i, 2) / n, rows(i, 3) / n);
    if (!out.quaternions.empty() && out.quaternions.back().coeffs().dot(q.coeffs()) < 0.0) {
      q.coeffs() = -q.coeffs();
      ++out.sign_flips;
    }
    out.quaternions.push_back(q);
  }
  return out;
}

Eigen::MatrixXd quaternionRows(const std::vector<Eigen::Quaterniond>& quaternions) {
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(quaternions.size()), 4);
  for (size_t i = 0; i < quaternions.size(); ++i) {
    const Eigen::Quaterniond& q = quaternions[i];
    rows.row(static_cast<Eigen::Index>(i)) << q.w(), q.x(), q.y(), q.z();
  }
  return rows;
}

}  // namespace lfd
