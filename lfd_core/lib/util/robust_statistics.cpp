// Robust statistics (see robust_statistics.hpp).
#include "lfd_core/util/robust_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace lfd {

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + mid));
  return m;
}

double robustSigma(std::vector<double> v) {
  const double med = medianOf(v);
  for (double& x : v) x = std::abs(x - med);
  return 1.4826 * medianOf(v);
}

double measurementNoiseSigma(const Eigen::Ref<const Eigen::VectorXd>& signal) {
  const Eigen::Index n = signal.size();
  if (n < 3) return 0.0;
  std::vector<double> second(static_cast<std::size_t>(n - 2));
  for (Eigen::Index i = 2; i < n; ++i)
    second[static_cast<std::size_t>(i - 2)] =
        std::abs(signal[i] - 2.0 * signal[i - 1] + signal[i - 2]);
  return 1.4826 * medianOf(second) / std::sqrt(6.0);
}

}  // namespace lfd
