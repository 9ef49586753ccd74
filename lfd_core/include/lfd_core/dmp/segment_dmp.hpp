// The DMPs of one segment of one demonstration: position (n-D, usually the 3-D end-effector
// position), orientation (unit quaternion) and gripper (1-D), all driven by ONE phase variable, as
// in the paper ("one DMP for the 6d-pose and one for the state of the gripper, coordinated by the
// same phase variable"). Each part is optional so the same type serves e.g. a 2-D curve.
#pragma once

#include "lfd_core/dmp/orientation_dmp.hpp"
#include "lfd_core/dmp/position_dmp.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace lfd {

/// A sampled demonstration segment. Leave a part empty (0 columns / size 0) when absent.
struct SegmentDemo {
  Eigen::VectorXd times;        ///< M, strictly increasing [s]
  Eigen::MatrixXd positions;    ///< M x D (D >= 0)
  Eigen::MatrixXd quaternions;  ///< M x 4 (w, x, y, z) or M x 0
  Eigen::VectorXd gripper;      ///< M or empty
};

struct SegmentTrajectory {
  Eigen::VectorXd times;               ///< steps, starting at 0
  Eigen::VectorXd phases;              ///< steps
  Eigen::MatrixXd positions;           ///< steps x D
  Eigen::MatrixXd velocities;          ///< steps x D
  Eigen::MatrixXd quaternions;         ///< steps x 4 (w, x, y, z), or steps x 0
  Eigen::MatrixXd angular_velocities;  ///< steps x 3, or steps x 0
  Eigen::VectorXd gripper;             ///< steps, or empty
};

/// Goal update for a running segment (moving goals); unset parts keep their current goal.
struct SegmentGoal {
  std::optional<Eigen::VectorXd> position;
  std::optional<Eigen::Quaterniond> orientation;
  std::optional<double> gripper;
};

/// A goal change `time` s into a rollout (an object moved while the segment ran).
struct GoalSwitch {
  double time = 0.0;
  SegmentGoal goal;
};

/// New start / goal / timing for a rollout. Unset fields keep the learned demo values.
struct SegmentRolloutOptions {
  double dt = 0.01;
  std::optional<double> tau;       ///< movement duration [s]
  std::optional<double> duration;  ///< how long to integrate [s] (default tau)
  std::optional<Eigen::VectorXd> start_position, goal_position, start_velocity;
  std::optional<Eigen::Quaterniond> start_orientation, goal_orientation;
  std::optional<Eigen::Vector3d> start_angular_velocity;
  std::optional<double> start_gripper, goal_gripper;
  /// Goal filter rate in 1/normalized time (0 = off): the attractor follows goal changes by
  /// dg/dsigma = goal_filter * (g_target - g), making goal switches acceleration-continuous.
  double goal_filter = 0.0;
  /// Goal changes while the rollout runs, each applied (SegmentDmpRunner::setGoal) at the first
  /// step at or after its time, in time order; with goal_filter > 0 the motion stays smooth.
  std::vector<GoalSwitch> goal_switches;
};

struct SegmentDmp {
  DmpParameters params;
  double tau = 1.0;
  std::optional<PositionDmp> position;
  std::optional<OrientationDmp> orientation;
  std::optional<PositionDmp> gripper;  ///< 1-D
  std::vector<std::string> warnings;   ///< e.g. non-unit quaternions were normalized

  /// Learns every part present in the demo with one shared phase and one least-squares
  /// factorization. Throws std::invalid_argument on too few samples, NaN, bad shapes.
  static SegmentDmp learn(const SegmentDemo& demo, const DmpParameters& params = {});

  /// Checks that every part shares params and tau (throws std::invalid_argument otherwise).
  void validate() const;

  SegmentTrajectory rollout(const SegmentRolloutOptions& options = {}) const;

  /// The same skill seen in a frame rotated by `r` (a proper rotation of the world): the 3-D
  /// position's forcing weights, start, goal and start velocity, and the orientation's weights,
  /// start, goal and angular velocity are rotated; the gripper is unchanged. The transformation
  /// system is rotation-covariant, so a rollout of the rotated DMP from rotated start and goal is
  /// the rotated rollout. This lets demos of different headings be compared in a task frame.
  /// Throws std::invalid_argument if r is not a rotation or the position part is not 3-D.
  SegmentDmp rotated(const Eigen::Matrix3d& r) const;
};

/// Steps a SegmentDmp online with any dt, accepting goal changes while it runs (the executor's
/// interface). The phase is evaluated once per step for all parts. Keeps a reference to `dmp`,
/// which must outlive the runner.
class SegmentDmpRunner {
 public:
  SegmentDmpRunner(const SegmentDmp& dmp, const SegmentRolloutOptions& options);

  void setGoal(const SegmentGoal& goal);
  void step(double dt);

  double time() const { return time_; }
  double phase() const { return x_; }
  double tau() const { return tau_; }
  const Eigen::VectorXd& position() const { return y_; }
  Eigen::VectorXd velocity() const { return v_ / tau_; }
  const Eigen::Quaterniond& orientation() const { return orient_.q; }
  Eigen::Vector3d angularVelocity() const { return orient_.eta / tau_; }
  double gripper() const { return grip_y_; }
  const Eigen::VectorXd& filteredGoalPosition() const { return goal_pos_; }

 private:
  void evaluateForcing(double x);  // fills f_pos_, f_ori_, f_grip_ at phase x
  // Each part's start, goal and state: the options' values (checked), else the learned ones.
  void setUpPosition(const SegmentRolloutOptions& o);
  void setUpOrientation(const SegmentRolloutOptions& o);
  void setUpGripper(const SegmentRolloutOptions& o);

  const SegmentDmp& dmp_;
  const GaussianBasis* basis_ = nullptr;
  const CanonicalSystem* canonical_ = nullptr;
  double tau_ = 1.0;
  double goal_filter_ = 0.0;
  double time_ = 0.0;
  double x_ = 1.0;
  double x_end_ = 0.0;  // phase at t = tau
  std::vector<double> act_;
  LinearStep linear_;
  // position
  Eigen::VectorXd y_, v_, start_pos_, goal_pos_, target_goal_pos_, f_pos_, u0_;
  // orientation
  OrientationDmp::State orient_;
  Eigen::Quaterniond start_ori_, goal_ori_, target_goal_ori_;
  Eigen::Vector3d f_ori_ = Eigen::Vector3d::Zero();
  // gripper
  double grip_y_ = 0, grip_v_ = 0, grip_start_ = 0, grip_goal_ = 0, grip_target_goal_ = 0;
  double f_grip_ = 0;
};

}  // namespace lfd
