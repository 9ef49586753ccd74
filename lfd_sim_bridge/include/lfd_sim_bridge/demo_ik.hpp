// Cartesian TCP path -> joint path with the core damped-least-squares IK (the same kinematics the
// DMP executor uses), warm-started sample to sample so the arm follows one continuous branch.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lfd_core/inverse_kinematics.hpp"
#include "lfd_core/kinematic_chain.hpp"
#include "lfd_sim_bridge/demo_plan.hpp"

namespace lfd_sim_bridge {
namespace demo {

struct JointPath {
  std::vector<std::string> joint_names;
  std::vector<double> times;               // s from the path start
  std::vector<Eigen::VectorXd> positions;  // one per time
  double max_position_error = 0.0;         // m, worst IK residual along the path
  double max_orientation_error = 0.0;      // rad
  double max_speed_ratio = 0.0;            // worst |dq/dt| / velocity limit between samples
};

struct IkTolerance {
  double position = 2e-3;     // m accepted when the solver stops short of its own tolerance
  double orientation = 0.03;  // rad
};

class CartesianToJoints {
 public:
  // `chain_base_in_base_link`: pose of the IK chain's base link in base_link (identity when the
  // chain starts at base_link); Cartesian samples are given in base_link.
  CartesianToJoints(
      const lfd::KinematicChain& chain,
      const Eigen::Isometry3d& chain_base_in_base_link = Eigen::Isometry3d::Identity(),
      const lfd::IkOptions& options = lfd::IkOptions(),
      const IkTolerance& tolerance = IkTolerance());

  void setPreferredPosture(const Eigen::VectorXd& q) { ik_.setPreferredPosture(q); }
  const lfd::KinematicChain& chain() const { return ik_.chain(); }

  // TCP pose (base_link) of a joint vector of the chain.
  Pose forward(const Eigen::VectorXd& q) const;

  // Solves every sample starting from `seed`. Throws std::runtime_error naming the sample time
  // and the residual when a pose is out of reach within the tolerance.
  JointPath convert(const std::vector<TimedPose>& samples, const Eigen::VectorXd& seed);

 private:
  lfd::InverseKinematics ik_;
  Eigen::Isometry3d chain_base_;
  IkTolerance tolerance_;
  lfd::IkResult result_;
};

}  // namespace demo
}  // namespace lfd_sim_bridge
