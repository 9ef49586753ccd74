// Smooth Cartesian motion primitives of the demonstrator (ROS-free): the minimum-jerk time law,
// pose interpolation and the band-limited "hand tremor" added in teleop-like mode.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "lfd_core/kinematics/pose.hpp"

namespace lfd_sim_bridge {
namespace demo {

using Pose = lfd::Pose;

// Minimum-jerk progress s(u) = 10u^3 - 15u^4 + 6u^5 for u in [0, 1] (clamped outside): zero
// velocity and acceleration at both ends, like a human reaching movement.
double minJerk(double u);
// ds/du of the minimum-jerk law (peak 1.875 at u = 0.5).
double minJerkRate(double u);

// Position interpolated linearly and orientation by slerp (shortest arc) at progress s in [0, 1].
Pose interpolate(const Pose& from, const Pose& to, double s);

// Band-limited 3-D noise: per axis, a sum of sinusoids with frequencies drawn uniformly in
// [low_hz, high_hz] and random phases, scaled to the requested RMS amplitude per axis. Smooth and
// defined at any time, so the same tremor can be sampled at any trajectory rate.
class Tremor {
 public:
  Tremor() = default;  // zero tremor
  Tremor(double rms_m, double low_hz, double high_hz, uint32_t seed, int components = 16);
  Eigen::Vector3d at(double t) const;
  double rms() const { return rms_; }

 private:
  struct Component {
    double omega, phase, amplitude;
  };
  double rms_ = 0.0;
  std::vector<Component> axes_[3];
};

}  // namespace demo
}  // namespace lfd_sim_bridge
