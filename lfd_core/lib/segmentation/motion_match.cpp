// Boundaries placed by the siblings' motion around theirs (see motion_match.hpp).
#include "lfd_core/segmentation/motion_match.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "lfd_core/segmentation/demo_alignment.hpp"

namespace lfd {

namespace {

// Rows [begin, end] of `grid` minus row `at`.
Eigen::MatrixXd relativeRows(const Eigen::MatrixXd& grid, std::size_t begin, std::size_t end,
                             std::size_t at) {
  const auto rows = static_cast<Eigen::Index>(end - begin + 1);
  return grid.middleRows(static_cast<Eigen::Index>(begin), rows).rowwise() -
         grid.row(static_cast<Eigen::Index>(at));
}

// DTW cost per aligned row (the pair's rows together), so that a window clipped at a demo's end
// weighs what a full one weighs.
double costPerRow(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return multivariateDtwCost(a, b) / static_cast<double>(a.rows() + b.rows());
}

}  // namespace

MotionAround motionAround(const Eigen::MatrixXd& grid, std::size_t at, std::size_t half) {
  const auto rows = static_cast<std::size_t>(grid.rows());
  if (at >= rows) throw std::invalid_argument("motionAround: row out of range");
  if (half == 0) throw std::invalid_argument("motionAround: the window needs at least one row");
  return {relativeRows(grid, at > half ? at - half : 0, at, at),
          relativeRows(grid, at, std::min(at + half, rows - 1), at)};
}

std::size_t bestMatchingRow(const Eigen::MatrixXd& grid, const std::vector<MotionAround>& siblings,
                            std::size_t first, std::size_t last, std::size_t half) {
  if (siblings.empty()) throw std::invalid_argument("bestMatchingRow: no sibling to match");
  if (first > last || last >= static_cast<std::size_t>(grid.rows()))
    throw std::invalid_argument("bestMatchingRow: rows to search out of range");
  for (const MotionAround& s : siblings)
    if (s.before.cols() != grid.cols() || s.after.cols() != grid.cols())
      throw std::invalid_argument("bestMatchingRow: the siblings have other features");
  const auto cost = [&](std::size_t row) {
    const MotionAround own = motionAround(grid, row, half);
    double sum = 0.0;
    for (const MotionAround& s : siblings)
      sum += costPerRow(own.before, s.before) + costPerRow(own.after, s.after);
    return sum;
  };
  // Coarse to fine: every stride-th row, then the rows around the best of them. The cost is a
  // sum over windows of 2 x half rows, so it varies slowly from row to row.
  const std::size_t stride = std::max<std::size_t>(1, half / 10);
  std::size_t best = first;
  double best_cost = std::numeric_limits<double>::infinity();
  const auto consider = [&](std::size_t row) {
    const double c = cost(row);
    if (c < best_cost) {
      best_cost = c;
      best = row;
    }
  };
  for (std::size_t row = first; row <= last; row += stride) consider(row);
  const std::size_t coarse = best;
  for (std::size_t row = coarse > first + stride ? coarse - stride : first;
       row <= std::min(last, coarse + stride); ++row)
    consider(row);
  return best;
}

}  // namespace lfd
