// Piecewise cubic Hermite interpolation of a joint trajectory on simulation time.
// Used by the workcell to turn JointTrajectory-like waypoints into smooth per-step targets.
#pragma once

#include <string>
#include <vector>

namespace lfd_sim {

struct TrajectoryPoint {
  double time_from_start = 0.0;    // s, strictly increasing along the trajectory
  std::vector<double> positions;   // one per trajectory joint
  std::vector<double> velocities;  // empty = estimated (shape-preserving), else one per joint
};

struct JointTrajectory {
  std::vector<std::string> joint_names;
  std::vector<TrajectoryPoint> points;
};

inline bool operator==(const TrajectoryPoint& a, const TrajectoryPoint& b) {
  return a.time_from_start == b.time_from_start && a.positions == b.positions &&
         a.velocities == b.velocities;
}
inline bool operator==(const JointTrajectory& a, const JointTrajectory& b) {
  return a.joint_names == b.joint_names && a.points == b.points;
}

// Throws std::invalid_argument with a precise message if the trajectory is unusable: no joints,
// no points, duplicate joint names, size mismatches, non-finite values, negative or
// non-increasing times.
void validateTrajectory(const JointTrajectory& trajectory);

// Interpolates one validated trajectory that starts at `start_time` from `start_positions` (the
// targets held when it was received). Between waypoints the curve is a cubic Hermite spline; the
// velocities it uses are the waypoint's own when given, else a shape-preserving estimate (zero at
// the ends and at local extrema, so the curve never overshoots a waypoint). After the last point
// it holds that point.
class TrajectoryInterpolator {
 public:
  TrajectoryInterpolator(const JointTrajectory& trajectory, double start_time,
                         const std::vector<double>& start_positions);

  // Positions (and velocities) of every trajectory joint at absolute time t.
  void sample(double t, std::vector<double>* positions, std::vector<double>* velocities) const;

  double startTime() const { return start_time_; }
  double endTime() const { return start_time_ + times_.back(); }
  const std::vector<std::string>& jointNames() const { return joint_names_; }

 private:
  std::vector<std::string> joint_names_;
  double start_time_;
  std::vector<double> times_;                    // knot times relative to start (first is 0)
  std::vector<std::vector<double>> positions_;   // [knot][joint]
  std::vector<std::vector<double>> velocities_;  // [knot][joint]
};

}  // namespace lfd_sim
