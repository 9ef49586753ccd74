// Test support shared by lfd_core's and lfd_dmp's tests: the strokes of a back-and-forth motion
// along one coordinate (a wipe), to check that a mix of demos keeps them.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace lfd_testing {

struct Strokes {
  int reversals = 0;      // turning points between the first and the last sample
  double shortest = 0.0;  // m, the shortest way between two turning points (or the ends)
};

/// A reversal needs `min_way_back` (1 cm) of way back: tremor is no stroke.
inline Strokes countStrokes(const std::vector<double>& x, double min_way_back = 0.01) {
  Strokes out;
  if (x.empty()) return out;
  std::vector<double> turns = {x.front()};
  int direction = 0;
  double extreme = x.front();
  for (const double v : x) {
    if (direction != 0 && direction * (v - extreme) > 0.0) {
      extreme = v;
    } else if (std::abs(v - extreme) > min_way_back) {
      if (direction != 0) turns.push_back(extreme);
      direction = v > extreme ? 1 : -1;
      extreme = v;
    }
  }
  turns.push_back(x.back());
  out.reversals = static_cast<int>(turns.size()) - 2;
  out.shortest = 1e9;
  for (size_t k = 1; k < turns.size(); ++k)
    out.shortest = std::min(out.shortest, std::abs(turns[k] - turns[k - 1]));
  return out;
}

}  // namespace lfd_testing
