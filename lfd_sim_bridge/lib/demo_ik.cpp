#include "lfd_sim_bridge/demo_ik.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {
namespace {

Eigen::Isometry3d toIsometry(const Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = p.position;
  t.linear() = p.orientation.normalized().toRotationMatrix();
  return t;
}

}  // namespace

CartesianToJoints::CartesianToJoints(const lfd::KinematicChain& chain,
                                     const Eigen::Isometry3d& chain_base_in_base_link,
                                     const lfd::IkOptions& options, const IkTolerance& tolerance)
    : ik_(chain, options), chain_base_(chain_base_in_base_link), tolerance_(tolerance) {}

Pose CartesianToJoints::forward(const Eigen::VectorXd& q) const {
  const Eigen::Isometry3d t = chain_base_ * ik_.chain().forward(q);
  Pose p;
  p.position = t.translation();
  p.orientation = Eigen::Quaterniond(t.linear()).normalized();
  return p;
}

JointPath CartesianToJoints::convert(const std::vector<TimedPose>& samples,
                                     const Eigen::VectorXd& seed) {
  const lfd::KinematicChain& chain = ik_.chain();
  if (seed.size() != chain.dof())
    throw std::invalid_argument("IK seed has " + std::to_string(seed.size()) +
                                " values, the chain has " + std::to_string(chain.dof()));
  JointPath path;
  path.joint_names = chain.jointNames();
  path.times.reserve(samples.size());
  path.positions.reserve(samples.size());
  const Eigen::Isometry3d base_inv = chain_base_.inverse();
  Eigen::VectorXd previous = seed;
  const Eigen::VectorXd& vmax = chain.velocityLimits();
  for (const TimedPose& sample : samples) {
    if (!std::isfinite(sample.t) || !sample.pose.position.allFinite() ||
        !sample.pose.orientation.coeffs().allFinite()) {
      throw std::invalid_argument("TCP pose at t=" + std::to_string(sample.t) +
                                  " s is not finite; no joint solution can be computed");
    }
    const Eigen::Isometry3d target = base_inv * toIsometry(sample.pose);
    if (!target.matrix().allFinite())
      throw std::invalid_argument("TCP pose at t=" + std::to_string(sample.t) +
                                  " s overflows in the chain base frame");
    ik_.solve(target, previous, result_);
    auto within = [this](const lfd::IkResult& r) {
      return r.converged || (r.position_error <= tolerance_.position &&
                             r.orientation_error <= tolerance_.orientation);
    };
    if (!within(result_)) {
      // Warm start failed (e.g. a joint limit blocks the branch): try the solver's restarts.
      const lfd::IkResult retry = ik_.reach(target, previous);
      if (!retry.failure.empty()) {
        throw std::runtime_error("IK failed for the TCP pose at t=" + std::to_string(sample.t) +
                                 " s: " + retry.failure);
      }
      if (!within(retry)) {
        std::ostringstream msg;
        msg << "IK cannot reach the TCP pose at t=" << sample.t << " s, position ("
            << sample.pose.position.transpose() << ") in base_link: residual "
            << retry.position_error * 1000.0 << " mm, " << retry.orientation_error << " rad";
        throw std::runtime_error(msg.str());
      }
      result_ = retry;
    }
    if (!path.times.empty()) {
      const double dt = sample.t - path.times.back();
      if (dt > 0.0) {
        for (int j = 0; j < chain.dof(); ++j) {
          if (!(vmax[j] > 0.0) || !std::isfinite(vmax[j])) continue;
          path.max_speed_ratio =
              std::max(path.max_speed_ratio, std::abs(result_.q[j] - previous[j]) / dt / vmax[j]);
        }
      }
    }
    path.max_position_error = std::max(path.max_position_error, result_.position_error);
    path.max_orientation_error = std::max(path.max_orientation_error, result_.orientation_error);
    path.times.push_back(sample.t);
    path.positions.push_back(result_.q);
    previous = result_.q;
  }
  return path;
}

}  // namespace demo
}  // namespace lfd_sim_bridge
