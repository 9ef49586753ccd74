#include "lfd_core/kinematics/kinematic_chain.hpp"
#include "lfd_core/io/safe_paths.hpp"

#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <urdf_parser/urdf_parser.h>

namespace lfd {
namespace {

Eigen::Isometry3d toIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() << pose.position.x, pose.position.y, pose.position.z;
  t.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  return t;
}

}  // namespace

KinematicChain KinematicChain::fromUrdfFile(const std::string& path, const std::string& base_link,
                                            const std::string& tip_link) {
  std::ifstream in;
  try {
    in.open(openInputFile(path).readPath());  // opened once: no FIFO swapped in
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("KinematicChain: cannot read URDF file: ") + e.what());
  }
  if (!in) throw std::runtime_error("KinematicChain: cannot read URDF file '" + path + "'");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return fromUrdfString(buffer.str(), base_link, tip_link);
}

KinematicChain KinematicChain::fromUrdfString(const std::string& urdf_xml,
                                              const std::string& base_link,
                                              const std::string& tip_link) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(urdf_xml);
  if (!model) throw std::invalid_argument("KinematicChain: the URDF could not be parsed");
  if (!model->getLink(base_link))
    throw std::invalid_argument("KinematicChain: unknown base link '" + base_link + "'");
  urdf::LinkConstSharedPtr link = model->getLink(tip_link);
  if (!link) throw std::invalid_argument("KinematicChain: unknown tip link '" + tip_link + "'");

  // Walk up from the tip to the base, then replay the joints base -> tip.
  std::vector<urdf::JointConstSharedPtr> joints;
  while (link->name != base_link) {
    if (!link->parent_joint)
      throw std::invalid_argument("KinematicChain: tip link '" + tip_link +
                                  "' is not below base link '" + base_link + "'");
    joints.push_back(link->parent_joint);
    link = model->getLink(link->parent_joint->parent_link_name);
  }
  std::reverse(joints.begin(), joints.end());

  KinematicChain chain;
  chain.base_link_ = base_link;
  chain.tip_link_ = tip_link;
  std::vector<double> lower, upper, velocity, effort;
  Eigen::Isometry3d pending = Eigen::Isometry3d::Identity();
  for (const auto& joint : joints) {
    pending = pending * toIsometry(joint->parent_to_joint_origin_transform);
    if (joint->type == urdf::Joint::FIXED) continue;
    if (joint->type != urdf::Joint::REVOLUTE && joint->type != urdf::Joint::CONTINUOUS &&
        joint->type != urdf::Joint::PRISMATIC)
      throw std::invalid_argument("KinematicChain: joint '" + joint->name +
                                  "' is floating or planar and cannot be in a serial chain");
    if (joint->mimic)
      throw std::invalid_argument("KinematicChain: mimic joint '" + joint->name +
                                  "' cannot be part of a chain");
    Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
    if (axis.norm() < 1e-12)
      throw std::invalid_argument("KinematicChain: joint '" + joint->name + "' has a zero axis");
    chain.joint_names_.push_back(joint->name);
    chain.types_.push_back(joint->type == urdf::Joint::PRISMATIC ? JointType::kPrismatic
                                                                 : JointType::kRevolute);
    chain.pre_.push_back(pending);
    chain.axes_.push_back(axis.normalized());
    pending = Eigen::Isometry3d::Identity();
    const double inf = std::numeric_limits<double>::infinity();
    const bool bounded = joint->type != urdf::Joint::CONTINUOUS && joint->limits;
    if (bounded && joint->limits->lower > joint->limits->upper)
      throw std::invalid_argument("KinematicChain: joint '" + joint->name +
                                  "' has lower limit above upper limit");
    lower.push_back(bounded ? joint->limits->lower : -inf);
    upper.push_back(bounded ? joint->limits->upper : inf);
    const bool has_vel = joint->limits && joint->limits->velocity > 0;
    velocity.push_back(has_vel ? joint->limits->velocity : inf);
    const bool has_effort = joint->limits && joint->limits->effort > 0;
    effort.push_back(has_effort ? joint->limits->effort : inf);
  }
  chain.tip_offset_ = pending;
  const auto to_vector = [](const std::vector<double>& v) {
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), v.size()));
  };
  chain.lower_ = to_vector(lower);
  chain.upper_ = to_vector(upper);
  chain.velocity_ = to_vector(velocity);
  chain.effort_ = to_vector(effort);
  return chain;
}

void KinematicChain::checkSize(const Eigen::Ref<const Eigen::VectorXd>& q) const {
  if (q.size() != dof())
    throw std::invalid_argument("KinematicChain: expected " + std::to_string(dof()) +
                                " joint values, got " + std::to_string(q.size()));
}

Eigen::Isometry3d KinematicChain::forward(const Eigen::Ref<const Eigen::VectorXd>& q) const {
  checkSize(q);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < dof(); ++i) {
    t = t * pre_[i];
    if (types_[i] == JointType::kRevolute) {
      t.linear() = t.linear() * Eigen::AngleAxisd(q[i], axes_[i]).toRotationMatrix();
    } else {
      t.translation() += t.linear() * (axes_[i] * q[i]);
    }
  }
  return t * tip_offset_;
}

Matrix6Xd KinematicChain::jacobian(const Eigen::Ref<const Eigen::VectorXd>& q) const {
  Eigen::Isometry3d pose;
  Matrix6Xd jac(6, dof());
  forwardAndJacobian(q, pose, jac);
  return jac;
}

void KinematicChain::forwardAndJacobian(const Eigen::Ref<const Eigen::VectorXd>& q,
                                        Eigen::Isometry3d& pose, Matrix6Xd& jac) const {
  checkSize(q);
  if (jac.cols() != dof()) jac.resize(6, dof());
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  // The linear column of a revolute joint is z x (p_tip - p_i); p_tip is known only at the end,
  // so store p_i x z now and add z x p_tip afterwards (no per-joint workspace needed).
  for (int i = 0; i < dof(); ++i) {
    t = t * pre_[i];
    const Eigen::Vector3d z = t.linear() * axes_[i];
    if (types_[i] == JointType::kRevolute) {
      jac.col(i).head<3>() = t.translation().cross(z);
      jac.col(i).tail<3>() = z;
      t.linear() = t.linear() * Eigen::AngleAxisd(q[i], axes_[i]).toRotationMatrix();
    } else {
      jac.col(i).head<3>() = z;
      jac.col(i).tail<3>().setZero();
      t.translation() += z * q[i];
    }
  }
  pose = t * tip_offset_;
  const Eigen::Vector3d p_tip = pose.translation();
  for (int i = 0; i < dof(); ++i) {
    if (types_[i] == JointType::kRevolute)
      jac.col(i).head<3>() += Eigen::Vector3d(jac.col(i).tail<3>()).cross(p_tip);
  }
}

bool KinematicChain::withinLimits(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  double tolerance) const {
  checkSize(q);
  return ((q.array() >= lower_.array() - tolerance) && (q.array() <= upper_.array() + tolerance))
      .all();
}

double KinematicChain::limitMargin(const Eigen::Ref<const Eigen::VectorXd>& q) const {
  checkSize(q);
  if (dof() == 0) return std::numeric_limits<double>::infinity();
  return (q - lower_).cwiseMin(upper_ - q).minCoeff();
}

void KinematicChain::clampToLimits(Eigen::Ref<Eigen::VectorXd> q) const {
  checkSize(q);
  q = q.cwiseMax(lower_).cwiseMin(upper_);
}

Eigen::VectorXd KinematicChain::midRange() const {
  Eigen::VectorXd mid(dof());
  for (int i = 0; i < dof(); ++i)
    mid[i] =
        std::isfinite(lower_[i]) && std::isfinite(upper_[i]) ? 0.5 * (lower_[i] + upper_[i]) : 0.0;
  return mid;
}

int KinematicChain::jointIndex(const std::string& name) const {
  const auto it = std::find(joint_names_.begin(), joint_names_.end(), name);
  return it == joint_names_.end() ? -1 : static_cast<int>(it - joint_names_.begin());
}

}  // namespace lfd
