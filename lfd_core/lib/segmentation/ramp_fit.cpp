// Flat-ramp-flat least-squares fit (see ramp_fit.hpp). With the ramp r(t) = 0 up to t0, rising
// linearly to 1 at t1 and 1 after, the fit y = a + h r(t) is a simple regression on r: the best
// (t0, t1) maximises cov(r, y)^2 / var(r). Every sum over r is closed-form or a prefix sum of y
// and t y, so each candidate costs O(1).
#include "lfd_core/segmentation/ramp_fit.hpp"

#include <algorithm>
#include <stdexcept>

namespace lfd {

RampFit fitRamp(const std::vector<double>& y, std::size_t begin, std::size_t end) {
  end = std::min(end, y.size());
  if (begin >= end || end - begin < 2)
    throw std::invalid_argument("fitRamp: the window needs at least 2 samples");
  const std::size_t m = end - begin;
  std::vector<double> py(m + 1, 0.0), pty(m + 1, 0.0);  // prefix sums of y and t * y
  for (std::size_t t = 0; t < m; ++t) {
    const double v = y[begin + t];
    py[t + 1] = py[t] + v;
    pty[t + 1] = pty[t] + static_cast<double>(t) * v;
  }
  const double n = static_cast<double>(m), sy = py[m];
  double best = -1.0;
  RampFit fit;
  for (std::size_t d = 1; d < m; ++d) {  // ramp length t1 - t0, shortest first
    const double dd = static_cast<double>(d);
    // Inside the ramp (t0 < t < t1) r = (t - t0) / d: sum r = (d-1)/2, sum r^2 = (d-1)(2d-1)/(6d).
    const double ramp_r = (dd - 1.0) / 2.0, ramp_rr = (dd - 1.0) * (2.0 * dd - 1.0) / (6.0 * dd);
    for (std::size_t t0 = 0; t0 + d < m; ++t0) {
      const std::size_t t1 = t0 + d;
      const double tail = static_cast<double>(m - t1);
      const double sr = ramp_r + tail, srr = ramp_rr + tail;
      const double inside_y = py[t1] - py[t0 + 1];
      const double inside_ty = pty[t1] - pty[t0 + 1];
      const double sry = (inside_ty - static_cast<double>(t0) * inside_y) / dd + (py[m] - py[t1]);
      const double var = srr - sr * sr / n, cov = sry - sr * sy / n;
      if (!(var > 0.0)) continue;
      const double explained = cov * cov / var;
      if (explained > best) {
        best = explained;
        const double h = cov / var;
        fit = {begin + t0 + 1, begin + t1, (sy - h * sr) / n, (sy - h * sr) / n + h};
      }
    }
  }
  if (best < 0.0) fit = {begin + 1, begin + 1, y[begin], y[begin]};  // constant window
  return fit;
}

}  // namespace lfd
