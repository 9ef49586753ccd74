#include "lfd_core/dmp/dmp_canonical.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lfd {

CanonicalSystem::CanonicalSystem(double alpha) : alpha_(alpha) {
  if (!(alpha > 0.0) || !std::isfinite(alpha)) {
    throw std::invalid_argument("CanonicalSystem: alpha must be a positive finite number, got " +
                                std::to_string(alpha));
  }
}

double CanonicalSystem::phase(double t, double tau) const {
  return std::exp(-alpha_ * t / tau);
}

double CanonicalSystem::stepFactor(double dt, double tau) const {
  return std::exp(-alpha_ * dt / tau);
}

GaussianBasis::GaussianBasis(int num_basis, const CanonicalSystem& canonical, double width_scale) {
  if (num_basis < 2) {
    throw std::invalid_argument("GaussianBasis: need at least 2 basis functions, got " +
                                std::to_string(num_basis));
  }
  if (!(width_scale > 0.0) || !std::isfinite(width_scale)) {
    throw std::invalid_argument("GaussianBasis: width_scale must be positive");
  }
  const int n = num_basis;
  centers_.resize(n);
  widths_.resize(n);
  for (int i = 0; i < n; ++i) {
    centers_[i] = std::exp(-canonical.alpha() * static_cast<double>(i) / (n - 1));
  }
  for (int i = 0; i < n; ++i) {
    const double spacing =
        (i + 1 < n) ? centers_[i] - centers_[i + 1] : centers_[i - 1] - centers_[i];
    widths_[i] = width_scale / (spacing * spacing);
  }
  // psi_i(x) >= exp(-cutoff)  <=>  |x - c_i| <= sqrt(cutoff / h_i).
  std::vector<double> lo(n), hi(n);
  for (int i = 0; i < n; ++i) {
    const double reach = std::sqrt(kCutoffExponent / widths_[i]);
    lo[i] = centers_[i] - reach;
    hi[i] = centers_[i] + reach;
  }
  lo_envelope_.resize(n);
  hi_envelope_.resize(n);
  lo_envelope_[0] = lo[0];
  for (int i = 1; i < n; ++i) lo_envelope_[i] = std::min(lo_envelope_[i - 1], lo[i]);
  hi_envelope_[n - 1] = hi[n - 1];
  for (int i = n - 2; i >= 0; --i) hi_envelope_[i] = std::max(hi_envelope_[i + 1], hi[i]);
  // The active range only changes where x crosses an envelope value, so its largest size is
  // found by probing each envelope value and its immediate neighbours.
  max_active_ = 1;
  auto update = [&](double x) {
    int b, e;
    activeRange(x, &b, &e);
    max_active_ = std::max(max_active_, e - b);
  };
  for (int i = 0; i < n; ++i) {
    for (double v : {lo_envelope_[i], hi_envelope_[i], centers_[i]}) {
      update(v);
      update(std::nextafter(v, 2.0));
      update(std::nextafter(v, -1.0));
    }
  }
}

void GaussianBasis::activeRange(double x, int* begin, int* end) const {
  // lo_envelope_ is non-increasing: the active range starts at the first index whose envelope
  // reaches below x. hi_envelope_ is non-increasing: it ends at the first index whose envelope
  // falls below x.
  const auto b = std::partition_point(lo_envelope_.begin(), lo_envelope_.end(),
                                      [x](double v) { return v > x; });
  const auto e = std::partition_point(hi_envelope_.begin(), hi_envelope_.end(),
                                      [x](double v) { return v >= x; });
  *begin = static_cast<int>(b - lo_envelope_.begin());
  *end = static_cast<int>(e - hi_envelope_.begin());
}

int GaussianBasis::gatedActivations(double x, double* out, int* count) const {
  int begin, end;
  activeRange(x, &begin, &end);
  return gatedActivationsInRange(x, begin, end, out, count);
}

int GaussianBasis::gatedActivations(double x, double* out, int* count, Cursor* cursor) const {
  const int n = size();
  // Same predicates as activeRange(); both envelopes are non-increasing and x only decreases.
  while (cursor->begin < n && lo_envelope_[cursor->begin] > x) ++cursor->begin;
  while (cursor->end < n && hi_envelope_[cursor->end] >= x) ++cursor->end;
  return gatedActivationsInRange(x, cursor->begin, cursor->end, out, count);
}

int GaussianBasis::gatedActivationsInRange(double x, int begin, int end, double* out,
                                           int* count) const {
  if (end <= begin) {
    // Every activation underflows: take the limit, all weight on the nearest end basis.
    const int idx = (x < centers_[size() - 1]) ? size() - 1 : 0;
    out[0] = x;
    *count = 1;
    return idx;
  }
  double sum = 0.0;
  const double* c = centers_.data();
  const double* h = widths_.data();
  for (int i = begin; i < end; ++i) {
    const double d = x - c[i];
    const double psi = std::exp(-h[i] * d * d);
    out[i - begin] = psi;
    sum += psi;
  }
  if (!(sum > 0.0)) {
    const int idx = (x < centers_[size() - 1]) ? size() - 1 : 0;
    out[0] = x;
    *count = 1;
    return idx;
  }
  const double scale = x / sum;
  for (int i = 0; i < end - begin; ++i) out[i] *= scale;
  *count = end - begin;
  return begin;
}

void GaussianBasis::gatedActivationsDense(double x, double* row) const {
  std::fill(row, row + size(), 0.0);
  std::vector<double> buf(static_cast<size_t>(size()));
  int count = 0;
  const int begin = gatedActivations(x, buf.data(), &count);
  for (int i = 0; i < count; ++i) row[begin + i] = buf[i];
}

}  // namespace lfd
