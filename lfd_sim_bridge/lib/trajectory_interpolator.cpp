#include "lfd_sim_bridge/trajectory_interpolator.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace lfd_sim {
namespace {

bool allFinite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// Shape-preserving slope at an interior knot: zero at local extrema, else the harmonic mean of
// the neighbouring secant slopes (Fritsch-Butland), which keeps each segment monotone.
double monotoneSlope(double d_prev, double d_next) {
  if (d_prev * d_next <= 0.0) return 0.0;
  return 2.0 * d_prev * d_next / (d_prev + d_next);
}

}  // namespace

void validateTrajectory(const JointTrajectory& trajectory) {
  const size_t n = trajectory.joint_names.size();
  if (n == 0) throw std::invalid_argument("trajectory has no joint names");
  if (trajectory.points.empty()) throw std::invalid_argument("trajectory has no points");
  std::set<std::string> unique(trajectory.joint_names.begin(), trajectory.joint_names.end());
  if (unique.size() != n) throw std::invalid_argument("trajectory has duplicate joint names");
  double previous = -1.0;
  for (size_t k = 0; k < trajectory.points.size(); ++k) {
    const TrajectoryPoint& p = trajectory.points[k];
    const std::string where = "trajectory point " + std::to_string(k);
    if (p.positions.size() != n) {
      throw std::invalid_argument(where + " has " + std::to_string(p.positions.size()) +
                                  " positions for " + std::to_string(n) + " joints");
    }
    if (!p.velocities.empty() && p.velocities.size() != n) {
      throw std::invalid_argument(where + " has " + std::to_string(p.velocities.size()) +
                                  " velocities for " + std::to_string(n) + " joints");
    }
    if (!allFinite(p.positions) || !allFinite(p.velocities)) {
      throw std::invalid_argument(where + " has a NaN or infinite value");
    }
    if (!std::isfinite(p.time_from_start) || p.time_from_start < 0.0) {
      throw std::invalid_argument(where + " has a negative or non-finite time_from_start");
    }
    if (k > 0 && p.time_from_start <= previous) {
      throw std::invalid_argument(where + " time_from_start " + std::to_string(p.time_from_start) +
                                  " is not after the previous point's " + std::to_string(previous));
    }
    previous = p.time_from_start;
  }
}

TrajectoryInterpolator::TrajectoryInterpolator(const JointTrajectory& trajectory, double start_time,
                                               const std::vector<double>& start_positions)
    : joint_names_(trajectory.joint_names), start_time_(start_time) {
  validateTrajectory(trajectory);
  const size_t n = joint_names_.size();
  if (start_positions.size() != n) {
    throw std::invalid_argument("trajectory start has the wrong number of positions");
  }
  // Knot 0 is "where the targets were when the trajectory arrived"; a first point at t=0
  // replaces it (the rate limiter downstream smooths any jump).
  std::vector<bool> given_velocity;
  const bool first_at_zero = trajectory.points.front().time_from_start <= 0.0;
  if (!first_at_zero) {
    times_.push_back(0.0);
    positions_.push_back(start_positions);
    velocities_.push_back(std::vector<double>(n, 0.0));
    given_velocity.push_back(true);
  }
  for (const TrajectoryPoint& p : trajectory.points) {
    times_.push_back(p.time_from_start);
    positions_.push_back(p.positions);
    velocities_.push_back(p.velocities.empty() ? std::vector<double>(n, 0.0) : p.velocities);
    given_velocity.push_back(!p.velocities.empty());
  }
  // Estimate missing interior velocities; the last knot's missing velocity stays zero (hold).
  for (size_t k = 1; k + 1 < times_.size(); ++k) {
    if (given_velocity[k]) continue;
    for (size_t j = 0; j < n; ++j) {
      const double d_prev = (positions_[k][j] - positions_[k - 1][j]) / (times_[k] - times_[k - 1]);
      const double d_next = (positions_[k + 1][j] - positions_[k][j]) / (times_[k + 1] - times_[k]);
      velocities_[k][j] = monotoneSlope(d_prev, d_next);
    }
  }
}

void TrajectoryInterpolator::sample(double t, std::vector<double>* positions,
                                    std::vector<double>* velocities) const {
  const size_t n = joint_names_.size();
  positions->resize(n);
  if (velocities) velocities->resize(n);
  const double tau = t - start_time_;
  if (tau <= times_.front() || times_.size() == 1) {
    const size_t k = tau <= times_.front() ? 0 : times_.size() - 1;
    *positions = positions_[k];
    if (velocities) std::fill(velocities->begin(), velocities->end(), 0.0);
    return;
  }
  if (tau >= times_.back()) {
    *positions = positions_.back();
    if (velocities) std::fill(velocities->begin(), velocities->end(), 0.0);
    return;
  }
  const size_t k = std::upper_bound(times_.begin(), times_.end(), tau) - times_.begin() - 1;
  const double h = times_[k + 1] - times_[k];
  const double s = (tau - times_[k]) / h;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
  const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  const double d00 = (6 * s2 - 6 * s) / h, d10 = 3 * s2 - 4 * s + 1;
  const double d01 = (-6 * s2 + 6 * s) / h, d11 = 3 * s2 - 2 * s;
  for (size_t j = 0; j < n; ++j) {
    const double p0 = positions_[k][j], p1 = positions_[k + 1][j];
    const double v0 = velocities_[k][j], v1 = velocities_[k + 1][j];
    (*positions)[j] = h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1;
    if (velocities) (*velocities)[j] = d00 * p0 + d10 * v0 + d01 * p1 + d11 * v1;
  }
}

}  // namespace lfd_sim
