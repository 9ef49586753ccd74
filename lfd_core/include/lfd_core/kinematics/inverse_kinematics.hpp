// Damped-least-squares inverse kinematics for a KinematicChain.
//
// Each iteration solves  dq = Jw^T (Jw Jw^T + lambda^2 I)^-1 ew  + (I - J# J) z
// where Jw, ew are the Jacobian and pose error scaled by per-axis weights (a zero weight frees that
// axis, e.g. position-only IK), lambda grows smoothly as the smallest weighted singular value falls
// below a threshold (Nakamura/Chiaverini adaptive damping) and, far from the goal, with the error
// (Levenberg-Marquardt style). The secondary term z pulls toward a preferred posture and away from
// joint limits inside the null space (weighted by optional per-joint motion costs). Joints are
// clamped to their limits; a joint that hits a limit is frozen for the rest of that iteration's
// step (small active set) so the others can compensate. All workspace is preallocated: solve() does
// not allocate.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <string>

#include "lfd_core/kinematics/kinematic_chain.hpp"

namespace lfd {

struct IkOptions {
  int max_iterations = 100;
  double position_tolerance = 1e-5;     // m, norm of the weighted-axis position error
  double orientation_tolerance = 1e-4;  // rad, norm of the weighted-axis rotation error
  // Weights of (x, y, z, rx, ry, rz) in the base frame; 0 ignores that axis.
  Eigen::Matrix<double, 6, 1> weights = Eigen::Matrix<double, 6, 1>::Ones();
  double singular_threshold = 0.02;  // weighted singular value below which damping starts
  double max_damping = 0.02;         // lambda at an exact singularity
  double error_damping = 1e-2;       // lambda^2 contribution per unit of squared weighted error
  double max_step = 0.25;            // rad (or m) largest joint change per iteration
  double posture_gain = 0.05;        // null-space pull toward the preferred posture
  double limit_gain = 1.0;           // null-space push away from joint limits
  double limit_zone = 0.15;          // fraction of a joint's range where the limit push acts
  // Optional per-joint motion cost (size dof(), > 0): a joint with cost c moves as if its motion
  // were scaled by 1/sqrt(c), e.g. to keep a humanoid's waist quieter than its arm. Empty = all 1.
  Eigen::VectorXd joint_costs;
  double polish_factor = 100.0;  // secondary task off once errors < factor * tolerance
  int restarts = 8;              // extra deterministic seeds tried by reach()
};

struct IkResult {
  Eigen::VectorXd q;  // best joint vector found (always within limits)
  bool converged = false;
  int iterations = 0;
  double position_error = 0.0;     // m, weighted axes only
  double orientation_error = 0.0;  // rad, weighted axes only
  // Why no usable answer exists (empty when q is the best effort): e.g. a target so far away
  // that its pose error overflows. Errors are then infinite and q is the clamped seed.
  std::string failure;
};

class InverseKinematics {
 public:
  explicit InverseKinematics(const KinematicChain& chain, const IkOptions& options = IkOptions());

  const KinematicChain& chain() const { return chain_; }
  const IkOptions& options() const { return options_; }
  void setOptions(const IkOptions& options);
  // Posture the null-space term pulls toward (defaults to the middle of each joint range).
  void setPreferredPosture(const Eigen::Ref<const Eigen::VectorXd>& q);
  const Eigen::VectorXd& preferredPosture() const { return preferred_; }

  // Solves from `seed` (warm start). `result.q` is reused, so repeated calls do not allocate.
  // Returns result.converged. Throws std::invalid_argument when seed has the wrong size.
  bool solve(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& seed,
             IkResult& result);
  IkResult solve(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& seed);

  // Reachability query: tries the seed, the preferred posture and options().restarts further
  // deterministic seeds; returns the first converged result (or the best one, converged = false).
  // Never returns an empty q: when no attempt has a finite error, `failure` says why. Throws
  // std::invalid_argument for a non-finite target or seed.
  IkResult reach(const Eigen::Isometry3d& target, const Eigen::Ref<const Eigen::VectorXd>& seed);

  // Weighted pose error (target relative to current) as a 6-vector (position, rotation vector).
  static Eigen::Matrix<double, 6, 1> poseError(const Eigen::Isometry3d& target,
                                               const Eigen::Isometry3d& current);

 private:
  void checkSolveInputs(const Eigen::Isometry3d& target,
                        const Eigen::Ref<const Eigen::VectorXd>& seed) const;
  // z_ = the secondary (posture and limit) task, or zero while polishing close to the goal.
  void setNullSpaceTask(const IkResult& progress);
  void secondaryTask(const Eigen::VectorXd& q);
  // One damped least-squares step into dq_ (joint units, at most max_step) for the weighted task
  // error `ew` with the joints in frozen_ held still.
  void dampedStep(const Eigen::Matrix<double, 6, 1>& ew, int unweighted_axes, double eps2,
                  double lambda_max2);
  // Freezes the joints already at a limit that dq_ pushes further; true if one was.
  bool freezeJointsPushedPastLimits();

  KinematicChain chain_;  // own copy: the solver never dangles
  IkOptions options_;
  Eigen::VectorXd preferred_, range_;
  // Workspace.
  Matrix6Xd jac_, jac_w_;
  Eigen::VectorXd q_, dq_, z_, tmp_n_, inv_sqrt_cost_;
  Eigen::Matrix<bool, Eigen::Dynamic, 1> frozen_;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen_;
};

}  // namespace lfd
