// Serial kinematic chain extracted from a URDF between a base link and a tip link.
//
// Fixed joints are folded into constant transforms, so the chain only holds movable joints
// (revolute, continuous, prismatic). Forward kinematics and the geometric Jacobian are
// allocation-free once the output matrix has the right size, which keeps IK loops fast.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace lfd {

using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

class KinematicChain {
 public:
  enum class JointType { kRevolute, kPrismatic };

  // Throws std::invalid_argument on a malformed URDF, unknown links, a tip that is not below the
  // base, or joints that cannot be part of a serial chain (floating, planar, mimic).
  static KinematicChain fromUrdfString(const std::string& urdf_xml, const std::string& base_link,
                                       const std::string& tip_link);
  // Throws std::runtime_error when the file cannot be read, else as fromUrdfString.
  static KinematicChain fromUrdfFile(const std::string& path, const std::string& base_link,
                                     const std::string& tip_link);

  int dof() const { return static_cast<int>(joint_names_.size()); }
  const std::string& baseLink() const { return base_link_; }
  const std::string& tipLink() const { return tip_link_; }
  const std::vector<std::string>& jointNames() const { return joint_names_; }
  const std::vector<JointType>& jointTypes() const { return types_; }
  // Position limits (+-infinity for continuous joints), velocity and effort limits.
  const Eigen::VectorXd& lowerLimits() const { return lower_; }
  const Eigen::VectorXd& upperLimits() const { return upper_; }
  const Eigen::VectorXd& velocityLimits() const { return velocity_; }
  const Eigen::VectorXd& effortLimits() const { return effort_; }

  // Pose of the tip link in the base link frame. q must have dof() entries.
  Eigen::Isometry3d forward(const Eigen::Ref<const Eigen::VectorXd>& q) const;
  // Geometric Jacobian of the tip origin in the base frame: rows 0-2 linear, rows 3-5 angular.
  Matrix6Xd jacobian(const Eigen::Ref<const Eigen::VectorXd>& q) const;
  // Both at once without allocating (jac is resized only if its column count is wrong).
  void forwardAndJacobian(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Isometry3d& pose,
                          Matrix6Xd& jac) const;

  bool withinLimits(const Eigen::Ref<const Eigen::VectorXd>& q, double tolerance = 1e-9) const;
  // Smallest distance of any joint to one of its position limits (negative when outside).
  double limitMargin(const Eigen::Ref<const Eigen::VectorXd>& q) const;
  void clampToLimits(Eigen::Ref<Eigen::VectorXd> q) const;
  // Centre of each joint's range (0 for continuous joints).
  Eigen::VectorXd midRange() const;
  // Index of a joint of the chain by name, or -1.
  int jointIndex(const std::string& name) const;

 private:
  void checkSize(const Eigen::Ref<const Eigen::VectorXd>& q) const;

  std::string base_link_, tip_link_;
  std::vector<std::string> joint_names_;
  std::vector<JointType> types_;
  // pre_[i]: transform from the moving frame of joint i-1 (or the base) to the frame of joint i.
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> pre_;
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> axes_;
  Eigen::Isometry3d tip_offset_ = Eigen::Isometry3d::Identity();  // last joint frame -> tip
  Eigen::VectorXd lower_, upper_, velocity_, effort_;
};

}  // namespace lfd
