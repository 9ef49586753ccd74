// Cartesian TCP path -> joint path with the damped-least-squares IK, warm-started sample to sample
// so the arm follows one continuous branch. The demonstrator turns its planned motions into joint
// trajectories with it and the DMP executor checks and converts its rollouts with it, so a path the
// demonstrator could follow is one the executor accepts.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lfd_core/kinematics/inverse_kinematics.hpp"
#include "lfd_core/kinematics/kinematic_chain.hpp"
#include "lfd_core/kinematics/pose.hpp"

namespace lfd {

struct JointPath {
  std::vector<std::string> joint_names;
  std::vector<double> times;               // s from the path start
  std::vector<Eigen::VectorXd> positions;  // one per time
  double max_position_error = 0.0;         // m, worst IK residual along the path
  double max_orientation_error = 0.0;      // rad
  double max_speed_ratio = 0.0;            // worst |dq/dt| / velocity limit between samples
};

// IK residual accepted on a path sample when the solver stops short of its own tolerance.
struct IkTolerance {
  double position = 2e-3;     // m
  double orientation = 0.03;  // rad
};

class CartesianToJoints {
 public:
  // `chain_base_in_frame`: pose of the IK chain's base link in the frame the Cartesian samples
  // are given in (identity when the chain starts at that frame).
  CartesianToJoints(const KinematicChain& chain,
                    const Eigen::Isometry3d& chain_base_in_frame = Eigen::Isometry3d::Identity(),
                    const IkOptions& options = IkOptions(),
                    const IkTolerance& tolerance = IkTolerance());

  void setPreferredPosture(const Eigen::VectorXd& q) { ik_.setPreferredPosture(q); }
  // The robot an unreachable pose's error names (its robot file's `name`).
  void setRobotName(std::string name) { robot_name_ = std::move(name); }
  const KinematicChain& chain() const { return ik_.chain(); }

  // TCP pose (in the samples' frame) of a joint vector of the chain.
  Pose forward(const Eigen::VectorXd& q) const;

  // Solves every sample starting from `seed`. Throws std::invalid_argument for a non-finite
  // sample or a seed of the wrong size, std::runtime_error naming the sample time and the residual
  // when a pose is out of reach within the tolerance.
  JointPath convert(const std::vector<TimedPose>& samples, const Eigen::VectorXd& seed);

 private:
  bool acceptable(const IkResult& r) const;

  InverseKinematics ik_;
  Eigen::Isometry3d chain_base_;
  IkTolerance tolerance_;
  IkResult result_;
  std::string robot_name_ = "the robot";
};

}  // namespace lfd
