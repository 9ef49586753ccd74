// A rigid pose (position + unit quaternion) and a timed one: the Cartesian vocabulary shared by
// the demonstrator's plans, the executor's DMP rollouts and the IK path conversion.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace lfd {

struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

struct TimedPose {
  double t = 0.0;  // s from the start of the sampled span
  Pose pose;
};

inline Eigen::Isometry3d toIsometry(const Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = p.position;
  t.linear() = p.orientation.normalized().toRotationMatrix();
  return t;
}

inline Pose toPose(const Eigen::Isometry3d& t) {
  Pose p;
  p.position = t.translation();
  p.orientation = Eigen::Quaterniond(t.linear()).normalized();
  return p;
}

}  // namespace lfd
