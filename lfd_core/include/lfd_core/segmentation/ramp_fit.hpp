// Where a level change starts and ends: the continuous flat-ramp-flat curve that fits a window of
// samples best (least squares). A sensory event found by a threshold on a lagged difference is
// only known to within a lag; the fit places it on the change itself: the start of a slow force
// ramp where the force leaves its level (contact made), its end where it settles (contact lost
// when it settles at rest). A step is a ramp of one sample.
#pragma once

#include <cstddef>
#include <vector>

namespace lfd {

struct RampFit {
  std::size_t start = 0;  ///< first sample off the level before (absolute index)
  std::size_t end = 0;    ///< first sample at the level after (start <= end; equal for a step)
  double before = 0.0;    ///< fitted level before
  double after = 0.0;     ///< fitted level after
};

/// Best flat-ramp-flat fit of y[begin, end) (absolute indices, end - begin >= 2; clipped to y).
/// O(m^2) for a window of m samples (prefix sums make each candidate O(1)). Ties keep the
/// shortest ramp. Throws std::invalid_argument for a window of fewer than 2 samples.
RampFit fitRamp(const std::vector<double>& y, std::size_t begin, std::size_t end);

}  // namespace lfd
