// Automatic subsequence length for ClaSP: SuSS (ClaSP's default), dominant Fourier period and
// highest autocorrelation, plus the string <-> enum helpers of clasp.hpp.
#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "lfd_core/segmentation/clasp.hpp"

namespace lfd {
namespace {

void requireFinite(const Eigen::Ref<const Eigen::VectorXd>& series, const char* who) {
  if (!series.allFinite())
    throw std::invalid_argument(std::string(who) + ": series has NaN/Inf values");
}

// Mean distance between each window's (mean, std, range) and the whole series' ones, divided by
// sqrt(w) (SuSS score; small = the window summarises the series well). `x` is min-max normalised.
double sussScore(const std::vector<double>& x, std::size_t w, const std::vector<double>& sum,
                 const std::vector<double>& sum_sq, double mean, double std, double range) {
  const std::size_t n = x.size();
  std::deque<std::size_t> max_q, min_q;  // monotonic queues for the rolling extrema
  double total = 0.0;
  std::size_t count = 0;
  const double wd = static_cast<double>(w);
  for (std::size_t i = 0; i < n; ++i) {
    while (!max_q.empty() && x[max_q.back()] <= x[i]) max_q.pop_back();
    max_q.push_back(i);
    while (!min_q.empty() && x[min_q.back()] >= x[i]) min_q.pop_back();
    min_q.push_back(i);
    if (i + 1 < w) continue;
    const std::size_t start = i + 1 - w;
    while (max_q.front() < start) max_q.pop_front();
    while (min_q.front() < start) min_q.pop_front();
    const double mu = (sum[i + 1] - sum[start]) / wd;
    const double sd = std::sqrt(std::max(0.0, (sum_sq[i + 1] - sum_sq[start]) / wd - mu * mu));
    const double rg = x[max_q.front()] - x[min_q.front()];
    const double dm = mu - mean, ds = sd - std, dr = rg - range;
    total += std::sqrt(dm * dm + ds * ds + dr * dr) / std::sqrt(wd);
    ++count;
  }
  return count ? total / static_cast<double>(count) : 0.0;
}

}  // namespace

WindowSelection parseWindowSelection(const std::string& name) {
  if (name == "suss") return WindowSelection::kSuss;
  if (name == "fft" || name == "dominant_fourier") return WindowSelection::kDominantFourier;
  if (name == "acf" || name == "autocorrelation") return WindowSelection::kAutocorrelation;
  throw std::invalid_argument("unknown window selection '" + name + "' (suss, fft, acf)");
}

ClaspDistance parseClaspDistance(const std::string& name) {
  if (name == "znorm_euclidean" || name == "znormed_euclidean_distance")
    return ClaspDistance::kZNormalizedEuclidean;
  if (name == "euclidean" || name == "euclidean_distance") return ClaspDistance::kEuclidean;
  throw std::invalid_argument("unknown ClaSP distance '" + name + "' (znorm_euclidean, euclidean)");
}

ClaspScore parseClaspScore(const std::string& name) {
  if (name == "roc_auc") return ClaspScore::kRocAuc;
  if (name == "f1" || name == "macro_f1") return ClaspScore::kMacroF1;
  throw std::invalid_argument("unknown ClaSP score '" + name + "' (roc_auc, f1)");
}

std::string toString(WindowSelection selection) {
  switch (selection) {
    case WindowSelection::kSuss:
      return "suss";
    case WindowSelection::kDominantFourier:
      return "fft";
    case WindowSelection::kAutocorrelation:
      return "acf";
  }
  return "?";
}

std::string toString(ClaspDistance distance) {
  return distance == ClaspDistance::kEuclidean ? "euclidean" : "znorm_euclidean";
}

std::string toString(ClaspScore score) {
  return score == ClaspScore::kMacroF1 ? "f1" : "roc_auc";
}

std::size_t sussWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t lbound,
                           double threshold) {
  requireFinite(series, "SuSS");
  const std::size_t n = static_cast<std::size_t>(series.size());
  lbound = std::max<std::size_t>(lbound, 2);
  if (n < 2 * lbound) return std::max<std::size_t>(2, n / 2);
  const double lo = series.minCoeff(), hi = series.maxCoeff();
  if (hi - lo <= 0.0) return lbound;  // constant: nothing to summarise

  std::vector<double> x(n), sum(n + 1, 0.0), sum_sq(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = (series[static_cast<Eigen::Index>(i)] - lo) / (hi - lo);
    sum[i + 1] = sum[i] + x[i];
    sum_sq[i + 1] = sum_sq[i] + x[i] * x[i];
  }
  const double mean = sum[n] / static_cast<double>(n);
  const double std = std::sqrt(std::max(0.0, sum_sq[n] / static_cast<double>(n) - mean * mean));
  const double range = 1.0;
  const auto raw = [&](std::size_t w) { return sussScore(x, w, sum, sum_sq, mean, std, range); };
  const double max_score = raw(1);
  const double min_score = raw(n - 1);
  if (max_score == min_score) return lbound;
  // Normalised similarity in [0, 1]: 1 = the window's statistics equal the global ones.
  const auto score = [&](std::size_t w) {
    return 1.0 - (raw(w) - min_score) / (max_score - min_score);
  };

  const std::size_t cap = n / 2;
  // Exponential search for the first power of two above the threshold, then binary search.
  std::size_t exp_w = 1;
  while (exp_w < lbound) exp_w *= 2;
  while (exp_w < cap && score(exp_w) <= threshold) exp_w *= 2;
  std::size_t low = std::max(lbound, exp_w / 2);
  std::size_t high = std::min(exp_w + 1, cap);
  while (low <= high) {
    const std::size_t mid = (low + high) / 2;
    const double s = score(mid);
    if (s < threshold) {
      low = mid + 1;
    } else if (s > threshold) {
      if (mid == 0) break;
      high = mid - 1;
    } else {
      low = mid;
      break;
    }
  }
  return std::clamp(low, lbound, std::max(lbound, cap));
}

std::size_t dominantFourierWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series,
                                      std::size_t lbound) {
  requireFinite(series, "dominant Fourier period");
  const std::size_t n = static_cast<std::size_t>(series.size());
  lbound = std::max<std::size_t>(lbound, 2);
  if (n < 4 * lbound) return std::max<std::size_t>(2, n / 4);
  std::vector<double> x(n);
  const double mean = series.mean();
  for (std::size_t i = 0; i < n; ++i) x[i] = series[static_cast<Eigen::Index>(i)] - mean;
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, x);
  std::size_t best = lbound;
  double best_mag = -1.0;
  for (std::size_t f = 1; f <= n / 2; ++f) {
    const std::size_t period = n / f;
    if (period < lbound || period > n / 4) continue;
    const double mag = std::abs(spectrum[f]);
    if (mag > best_mag) {
      best_mag = mag;
      best = period;
    }
  }
  return best;
}

std::size_t autocorrelationWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series,
                                      std::size_t lbound) {
  requireFinite(series, "autocorrelation period");
  const std::size_t n = static_cast<std::size_t>(series.size());
  lbound = std::max<std::size_t>(lbound, 2);
  if (n < 4 * lbound) return std::max<std::size_t>(2, n / 4);
  // Autocovariance through the power spectrum of the zero-padded series (Wiener-Khinchin).
  std::size_t padded = 1;
  while (padded < 2 * n) padded *= 2;
  std::vector<double> x(padded, 0.0);
  const double mean = series.mean();
  for (std::size_t i = 0; i < n; ++i) x[i] = series[static_cast<Eigen::Index>(i)] - mean;
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, x);
  for (auto& c : spectrum) c = std::complex<double>(std::norm(c), 0.0);
  std::vector<double> acov;
  fft.inv(acov, spectrum);
  if (acov[0] <= 0.0) return lbound;
  const std::size_t max_lag = n / 4;
  std::size_t best = lbound;
  double best_corr = -2.0;
  for (std::size_t lag = std::max<std::size_t>(lbound, 1); lag < max_lag; ++lag) {
    const double v = acov[lag];
    if (v > acov[lag - 1] && v >= acov[lag + 1] && v / acov[0] > best_corr) {
      best_corr = v / acov[0];
      best = lag;
    }
  }
  return best;
}

std::size_t selectWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series,
                             WindowSelection selection, std::size_t lbound) {
  const std::size_t n = static_cast<std::size_t>(series.size());
  if (n < 6)
    throw std::invalid_argument("window selection: series of " + std::to_string(n) +
                                " samples is too short for ClaSP (need >= 6)");
  std::size_t w = 0;
  switch (selection) {
    case WindowSelection::kSuss:
      w = sussWindowSize(series, lbound);
      break;
    // A period covers one full cycle; ClaSP (claspy) uses half of it as the subsequence length.
    case WindowSelection::kDominantFourier:
      w = dominantFourierWindowSize(series, 2 * lbound) / 2;
      break;
    case WindowSelection::kAutocorrelation:
      w = autocorrelationWindowSize(series, 2 * lbound) / 2;
      break;
  }
  return std::clamp<std::size_t>(w, 2, n / 3);
}

}  // namespace lfd
