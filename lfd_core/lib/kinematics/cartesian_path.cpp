#include "lfd_core/kinematics/cartesian_path.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lfd {
namespace {

void requireFinite(const TimedPose& sample) {
  if (!std::isfinite(sample.t) || !sample.pose.position.allFinite() ||
      !sample.pose.orientation.coeffs().allFinite()) {
    throw std::invalid_argument("TCP pose at t=" + std::to_string(sample.t) +
                                " s is not finite; no joint solution can be computed");
  }
}

double speedRatio(const KinematicChain& chain, const Eigen::VectorXd& from,
                  const Eigen::VectorXd& to, double dt) {
  if (!(dt > 0.0)) return 0.0;
  const Eigen::VectorXd& vmax = chain.velocityLimits();
  double worst = 0.0;
  for (int j = 0; j < chain.dof(); ++j) {
    if (!(vmax[j] > 0.0) || !std::isfinite(vmax[j])) continue;
    worst = std::max(worst, std::abs(to[j] - from[j]) / dt / vmax[j]);
  }
  return worst;
}

}  // namespace

CartesianToJoints::CartesianToJoints(const KinematicChain& chain,
                                     const Eigen::Isometry3d& chain_base_in_frame,
                                     const IkOptions& options, const IkTolerance& tolerance)
    : ik_(chain, options), chain_base_(chain_base_in_frame), tolerance_(tolerance) {}

Pose CartesianToJoints::forward(const Eigen::VectorXd& q) const {
  return toPose(chain_base_ * ik_.chain().forward(q));
}

bool CartesianToJoints::acceptable(const IkResult& r) const {
  return r.converged ||
         (r.position_error <= tolerance_.position && r.orientation_error <= tolerance_.orientation);
}

JointPath CartesianToJoints::convert(const std::vector<TimedPose>& samples,
                                     const Eigen::VectorXd& seed) {
  const KinematicChain& chain = ik_.chain();
  if (seed.size() != chain.dof())
    throw std::invalid_argument("IK seed has " + std::to_string(seed.size()) +
                                " values, the chain has " + std::to_string(chain.dof()));
  JointPath path;
  path.joint_names = chain.jointNames();
  path.times.reserve(samples.size());
  path.positions.reserve(samples.size());
  const Eigen::Isometry3d base_inv = chain_base_.inverse();
  Eigen::VectorXd previous = seed;
  for (const TimedPose& sample : samples) {
    requireFinite(sample);
    const Eigen::Isometry3d target = base_inv * toIsometry(sample.pose);
    if (!target.matrix().allFinite())
      throw std::invalid_argument("TCP pose at t=" + std::to_string(sample.t) +
                                  " s overflows in the chain base frame");
    ik_.solve(target, previous, result_);
    if (!acceptable(result_)) {
      // Warm start failed (e.g. a joint limit blocks the branch): try the solver's restarts.
      const IkResult retry = ik_.reach(target, previous);
      if (!retry.failure.empty())
        throw std::runtime_error("IK failed for " + robot_name_ + " at the TCP pose at t=" +
                                 std::to_string(sample.t) + " s: " + retry.failure);
      if (!acceptable(retry)) {
        std::ostringstream msg;
        msg << robot_name_ << " cannot reach the TCP pose at t=" << sample.t << " s, position ("
            << sample.pose.position.transpose() << "): IK residual "
            << retry.position_error * 1000.0 << " mm, " << retry.orientation_error << " rad";
        throw std::runtime_error(msg.str());
      }
      result_ = retry;
    }
    if (!path.times.empty())
      path.max_speed_ratio =
          std::max(path.max_speed_ratio,
                   speedRatio(chain, previous, result_.q, sample.t - path.times.back()));
    path.max_position_error = std::max(path.max_position_error, result_.position_error);
    path.max_orientation_error = std::max(path.max_orientation_error, result_.orientation_error);
    path.times.push_back(sample.t);
    path.positions.push_back(result_.q);
    previous = result_.q;
  }
  return path;
}

}  // namespace lfd
