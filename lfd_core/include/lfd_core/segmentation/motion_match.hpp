// Placing a boundary in one demonstration by the motion its siblings show around theirs. Where a
// demo's contact sensor did not measure (stale or dead: stale_readings.hpp), its siblings still
// felt the touch, and their motion around it says what the touch looks like without a sensor:
// a descent that ends, a stroke that begins. The boundary goes where the demo's motion before
// and after it best matches the siblings' before and after theirs, each side warped by DTW on its
// own (demos move at their own speed), with every window taken relative to the motion's point at
// the boundary (demos reach to different places).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace lfd {

/// One demo's motion on either side of a boundary: rows on a uniform grid, minus the row at the
/// boundary. `before` ends at the boundary's row, `after` starts at it.
struct MotionAround {
  Eigen::MatrixXd before, after;
};

/// The motion of `grid` (rows = instants on a uniform grid, columns = features) within `half`
/// rows on either side of row `at` (clipped at the ends). Throws std::invalid_argument for `at`
/// out of range or half == 0.
MotionAround motionAround(const Eigen::MatrixXd& grid, std::size_t at, std::size_t half);

/// The row of `grid` in [first, last] whose motion around it (motionAround, `half` rows) matches
/// the siblings' best: the least summed DTW cost per aligned row, before and after, over the
/// siblings (searched every half / 10 rows, then row by row around the best). Throws
/// std::invalid_argument for no siblings, first > last, last out of range, or a
/// column count that differs from the siblings'.
std::size_t bestMatchingRow(const Eigen::MatrixXd& grid, const std::vector<MotionAround>& siblings,
                            std::size_t first, std::size_t last, std::size_t half);

}  // namespace lfd
