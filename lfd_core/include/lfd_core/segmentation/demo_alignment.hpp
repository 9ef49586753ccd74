// Demonstrations of one task aligned on a common time axis, that of one reference demonstration
// (the medoid: the least DTW cost to all others), by multivariate DTW of their state features on
// a coarse uniform grid. The joint segmentation (joint_segmentation.hpp) carries each demo's
// boundary evidence onto the reference's axis this way, and each agreed boundary back.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

namespace lfd {

/// One demonstration's features (rows = samples, already scaled alike across demos) on a grid of
/// `step` seconds from its first sample: row k holds the features at time[0] + k * step
/// (linear interpolation). Throws std::invalid_argument on a size mismatch or step <= 0.
Eigen::MatrixXd onUniformGrid(const Eigen::MatrixXd& features, const std::vector<double>& time,
                              double step);

/// Summed squared Euclidean distance along the best monotone warping path. `band` (< 1): the
/// path stays within band x the longer length of the diagonal joining the corners (a slanted
/// Sakoe-Chiba band); >= 1 = unconstrained.
double multivariateDtwCost(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double band = 1.0);

/// For every row of `a`, the mean row of `b` it is warped to by multivariate DTW (fractional).
std::vector<double> multivariateDtwMap(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                       double band = 1.0);

struct DemoAlignment {
  std::size_t reference = 0;  ///< the demonstration whose time axis is the common one
  /// Per demo, per grid row: the reference grid row it aligns to (the reference maps to itself).
  std::vector<std::vector<double>> to_reference;
  /// Per demo, per reference grid row: the demo's grid row aligned to it.
  std::vector<std::vector<double>> from_reference;
  std::vector<double> mean_cost;  ///< per demo, DTW cost to the reference per aligned row
};

/// The demos' indices, least summed DTW cost to all the others first (the medoid; ties keep the
/// input order). Costs are per aligned row (normalized by the pair's lengths).
/// Throws std::invalid_argument on no demos, an empty one or differing feature counts.
std::vector<std::size_t> byDtwCostToOthers(const std::vector<Eigen::MatrixXd>& gridded, int threads,
                                           double band = 1.0);

/// Per demo, which columns of its grid say something (true) and which it cannot fill (a dead
/// sensor's, a periodic phase it lacks); empty = every column of every demo.
using ColumnMasks = std::vector<std::vector<bool>>;

/// Demos a's and b's grids on the columns both can fill (`masks` as above): a column one demo
/// cannot fill pulls the other's motion onto the wrong part of it. Throws std::invalid_argument
/// when a mask's size differs from its grid's columns.
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> sharedColumns(
    const std::vector<Eigen::MatrixXd>& gridded, const ColumnMasks& masks, std::size_t a,
    std::size_t b);

/// Aligns gridded demos (onUniformGrid) to demo `reference`, each on the columns it shares with
/// it (sharedColumns); `threads` <= 0 = all cores; `band` as for multivariateDtwCost. Throws
/// std::invalid_argument as above, or on a reference out of range.
DemoAlignment alignTo(const std::vector<Eigen::MatrixXd>& gridded, std::size_t reference,
                      int threads, double band = 1.0, const ColumnMasks& masks = {});

/// alignTo the medoid (byDtwCostToOthers' first).
DemoAlignment alignToMedoid(const std::vector<Eigen::MatrixXd>& gridded, int threads,
                            double band = 1.0);

/// The same map, with the alignment held at anchor pairs: row a_anchors[k] of `a` is matched to
/// row b_anchors[k] of `b` and DTW runs between consecutive anchors only (both increasing, inside
/// the series). Agreed boundaries hold a long alignment on track where the features alone are
/// ambiguous (a pause matches any other pause).
std::vector<double> anchoredDtwMap(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                   const std::vector<std::size_t>& a_anchors,
                                   const std::vector<std::size_t>& b_anchors, double band = 1.0);

/// Linear interpolation of a per-row map at a fractional row (clamped to its ends).
double mapRow(const std::vector<double>& map, double row);

}  // namespace lfd
