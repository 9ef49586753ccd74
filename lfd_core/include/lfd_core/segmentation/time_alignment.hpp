// Time alignment of the demonstrations of one segment, before they are learned and mixed.
//
// Why: generalization mixes the demos' DMPs by their forcing weights, which are functions of the
// phase, i.e. of how far through its duration a demo is. Demos whose sub-motions come at different
// fractions of their duration (a teleoperator's three wipe strokes, one after a hesitation, one
// faster) then mix into another motion: the strokes of one demo cancel the returns of another,
// and three 16 cm strokes averaged into one of a third the length. Re-timed onto one common
// timing, the same sub-motion has the same phase in every demo and the mix keeps it.
//
// Method: every demo's path (hand position and gripper opening relative to their start, in units
// of the path's length, turned about z onto a reference demo's when the position is 3-D: demos of
// one segment differ in where, in which heading and how far they go; z is up) is compared with
// dynamic time warping (DTW) to a reference, the medoid (least summed DTW distance to the others).
// Each DTW path gives a warp, the demo's progress (fraction of its duration) at each progress of
// the reference, smoothed and monotone. The common timing is the mean of all warps, the
// reference's own included, so that no demo's timing is preferred (a hesitation of one demo
// becomes a small slow-down, not a pause of the others). Each demo is then resampled at its own
// time stamps from the progress the common timing gives it: it keeps its duration, start, end and
// path; only when it gets where changes.
#pragma once

#include "lfd_core/dmp/segment_dmp.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

namespace lfd {

struct TimeAlignmentOptions {
  double sample_seconds = 0.05;  ///< s between the samples DTW compares (each demo resampled)
  double warp_sigma = 0.1;       ///< s: Gaussian smoothing of each warp (DTW's path is a staircase)
  bool yaw_invariant = true;     ///< 3-D positions: compare demos turned about z onto the reference
};

struct TimeAlignment {
  std::vector<SegmentDemo> demos;  ///< re-timed, each with its input time stamps
  std::size_t reference = 0;       ///< the medoid demo the others were warped to
  std::vector<double> yaw;         ///< rad about z that turns each demo onto the reference
  Eigen::VectorXd progress;        ///< common progress grid, 0..1
  /// per demo: its own progress at each common progress (the re-timing applied); identity = none
  std::vector<Eigen::VectorXd> warps;
};

/// Multivariate DTW path between the rows of a (n x D) and b (m x D), squared Euclidean local
/// cost, steps as lfd::dtw (ties: diagonal). Returns the summed cost; `path` gets (i, j) pairs
/// from (0, 0) to (n - 1, m - 1) when not null. `band` < 1: the path stays within band x the
/// longer length of the straight line joining the corners (a slanted Sakoe-Chiba band); >= 1:
/// unconstrained.
double dtwRows(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
               std::vector<std::pair<int, int>>* path = nullptr, double band = 1.0);

/// Throws std::invalid_argument, its message starting with `where`, unless sample_seconds is finite
/// and > 0 and warp_sigma finite and >= 0: the one rule for options from a config or a library.
void checkTimeAlignmentOptions(const TimeAlignmentOptions& options, const std::string& where = "");

/// Re-times the demos of one segment onto one common timing (above). The demos need positions
/// (the compared path; a gripper in all of them or in none); time stamps strictly increasing. One
/// demo, or demos without positions, are returned unchanged. Throws std::invalid_argument on bad
/// options or shapes.
TimeAlignment alignDemoTiming(const std::vector<SegmentDemo>& demos,
                              const TimeAlignmentOptions& options = {});

}  // namespace lfd
