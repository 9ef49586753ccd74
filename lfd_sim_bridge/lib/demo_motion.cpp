#include "lfd_sim_bridge/demo_motion.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {

double minJerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  const double u3 = u * u * u;
  return u3 * (10.0 - 15.0 * u + 6.0 * u * u);
}

double minJerkRate(double u) {
  if (u <= 0.0 || u >= 1.0) return 0.0;
  const double v = u * (1.0 - u);
  return 30.0 * v * v;
}

Pose interpolate(const Pose& from, const Pose& to, double s) {
  Pose out;
  out.position = from.position + s * (to.position - from.position);
  out.orientation = from.orientation.normalized().slerp(s, to.orientation.normalized());
  return out;
}

Tremor::Tremor(double rms_m, double low_hz, double high_hz, uint32_t seed, int components)
    : rms_(rms_m) {
  if (rms_m < 0.0 || low_hz <= 0.0 || high_hz < low_hz || components < 1)
    throw std::invalid_argument("Tremor needs rms >= 0, 0 < low_hz <= high_hz and components >= 1");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> freq(low_hz, high_hz);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  std::uniform_real_distribution<double> weight(0.5, 1.5);
  for (auto& axis : axes_) {
    double power = 0.0;
    for (int i = 0; i < components; ++i) {
      const double w = weight(rng);
      axis.push_back({2.0 * M_PI * freq(rng), phase(rng), w});
      power += 0.5 * w * w;  // mean square of w*sin(.)
    }
    // Frequencies differ, so the components are uncorrelated over a long window: scale the sum of
    // their powers to the requested mean square.
    const double scale = rms_m / std::sqrt(power);
    for (auto& c : axis) c.amplitude *= scale;
  }
}

Eigen::Vector3d Tremor::at(double t) const {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    for (const auto& c : axes_[k]) out[k] += c.amplitude * std::sin(c.omega * t + c.phase);
  return out;
}

}  // namespace demo
}  // namespace lfd_sim_bridge
