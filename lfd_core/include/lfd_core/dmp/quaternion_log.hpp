// Unit-quaternion logarithm / exponential maps (Ude et al. 2014 convention) and the helpers the
// orientation DMP needs: hemisphere continuity along a sampled path, normalization with a flag.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace lfd {

/// log of a unit quaternion: the vector u * theta / 2 ... in Ude's convention log(q) = arccos(w) *
/// v / |v|, so 2 * log(q) is the rotation vector of q. Uses the shortest arc (w >= 0 hemisphere)
/// so the result has norm <= pi/2. Stable near the identity.
Eigen::Vector3d quaternionLog(const Eigen::Quaterniond& q);

/// exp(r) = (cos|r|, sin|r| r/|r|): inverse of quaternionLog; exp(rotvec / 2) is the rotation.
Eigen::Quaterniond quaternionExp(const Eigen::Vector3d& r);

/// Rotation-vector error that the orientation DMP drives to zero: 2 * log(goal * conj(q)).
Eigen::Vector3d orientationError(const Eigen::Quaterniond& goal, const Eigen::Quaterniond& q);

/// Result of making a quaternion sequence usable: unit norm, no sign flips between neighbours.
struct QuaternionSequence {
  std::vector<Eigen::Quaterniond> quaternions;
  bool normalized_input = false;  ///< at least one input was off unit norm by > 1e-6 (warning)
  int sign_flips = 0;             ///< how many samples were negated to keep the path continuous
};

/// rows: M x 4 in (w, x, y, z) order. Throws std::invalid_argument on NaN/inf or (near) zero norm.
QuaternionSequence makeContinuousQuaternions(const Eigen::MatrixXd& wxyz_rows);

/// The inverse layout: M x 4 rows in (w, x, y, z) order.
Eigen::MatrixXd quaternionRows(const std::vector<Eigen::Quaterniond>& quaternions);

}  // namespace lfd
