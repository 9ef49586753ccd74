// Generalization of one segment to a new goal from the DMPs learned on several demonstrations
// (paper: "we interpolate the new goal with all the precedently learned goals to find a new DMP").
//
// Method: locally weighted linear regression (LWR) of every learned quantity of the motion (forcing
// weights of position and orientation, start velocities) over the task parameters of the demos
// (default: the goal position), evaluated at the query. Gaussian kernel over the parameter
// distance, bandwidth = median pairwise distance of the demos' parameters (from the data).
// Why LWR and not a plain kernel average (Nadaraya-Watson): in the Hoffmann formulation the weights
// near the end of the movement carry (g - y0), which varies linearly with the goal; a kernel
// average is biased toward the nearest demos (it cannot reproduce a linear trend), LWR reproduces
// linear trends exactly and still adapts locally when the relation is non-linear. The result is an
// affine combination of the demos (coefficients sum to 1), so it is cheap and easy to inspect. A
// small ridge on the local slope keeps it defined with fewer demos than parameter dimensions
// (2 demos in 3-D: interpolation along the line between them). Duration, the default goal
// orientation and the whole gripper DMP use the (non-negative) kernel weights: the gripper's shape
// does not follow the goal, and a convex mix cannot open the gripper where no demo does.
#pragma once

#include "lfd_core/dmp/segment_dmp.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace lfd {

struct GeneralizationOptions {
  double bandwidth = 0.0;     ///< kernel bandwidth in parameter units; 0 = from the data
  double slope_ridge = 1e-3;  ///< ridge on the local linear terms (relative to the kernel mass)
  /// More than one: the ridge is chosen among these by leave-one-out cross-validation (each demo's
  /// motion predicted from the others at its own parameters, position RMS) with the one-standard-
  /// error rule: the largest ridge within one standard error of the best mean. Needs >= 3 demos,
  /// else slope_ridge. A large ridge tends to the kernel average: the data decide how much of a
  /// linear trend the demos support over their noise.
  std::vector<double> slope_ridge_candidates;
  bool local_linear = true;   ///< false: plain kernel (Nadaraya-Watson) average
  double range_margin = 0.1;  ///< outside = hull distance > margin * demo parameter diameter
};

struct GeneralizationResult {
  SegmentDmp dmp;                   ///< the interpolated DMP (start/goal: interpolated values)
  Eigen::VectorXd coefficients;     ///< affine combination of the demos (sums to 1)
  Eigen::VectorXd kernel_weights;   ///< normalized Gaussian kernel weights (sum to 1)
  double bandwidth = 0.0;           ///< bandwidth used
  double hull_distance = 0.0;       ///< distance from the query to the demos' convex hull
  double margin = 0.0;              ///< allowed hull distance before flagging
  bool outside_demo_range = false;  ///< query not covered by the demos (extrapolation)
  std::string warning;              ///< human-readable explanation when flagged
  double slope_ridge = 0.0;         ///< the ridge used (local linear only)
  /// Leave-one-out position RMS (m) of each slope_ridge_candidates entry; empty without selection.
  std::vector<double> loo_rms;
};

/// Default task parameters of a learned demo segment: its goal position (throws if none).
Eigen::VectorXd goalParameters(const SegmentDmp& dmp);

/// Distance from q to the convex hull of the columns of `points` (d x J), by projected gradient on
/// the simplex (exact up to ~1e-9 relative for the small J of demonstration sets).
double convexHullDistance(const Eigen::MatrixXd& points, const Eigen::VectorXd& q);

/// Leave-one-out error of the local linear fit with `slope_ridge` over the demos: each demo's
/// position DMP predicted from the others at its own parameters and rolled out over its own start,
/// goal and duration, against its own rollout; the mean position RMS (m). bandwidth > 0. Needs >= 3
/// demos with a position DMP (throws std::invalid_argument otherwise).
double leaveOneOutRms(const std::vector<SegmentDmp>& demos,
                      const std::vector<Eigen::VectorXd>& params, double bandwidth,
                      double slope_ridge);

/// demos and params are parallel (same length >= 1); every demo must have the same parts,
/// dimensions and DMP parameters. Throws std::invalid_argument otherwise or on NaN.
GeneralizationResult generalizeSegment(const std::vector<SegmentDmp>& demos,
                                       const std::vector<Eigen::VectorXd>& params,
                                       const Eigen::VectorXd& query,
                                       const GeneralizationOptions& options = {});

}  // namespace lfd
