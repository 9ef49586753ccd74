#include "lfd_core/segmentation/time_series.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lfd {

int FeatureMatrix::indexOf(const std::string& name) const {
  auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

int FeatureMatrix::require(const std::string& name) const {
  const int index = indexOf(name);
  if (index < 0) throw std::invalid_argument("feature '" + name + "' not found");
  return index;
}

double FeatureMatrix::timeAt(Eigen::Index row) const {
  return time.empty() ? static_cast<double>(row) : time.at(static_cast<size_t>(row));
}

std::vector<double> FeatureMatrix::clock() const {
  std::vector<double> t(static_cast<size_t>(rows()));
  for (Eigen::Index i = 0; i < rows(); ++i) t[static_cast<size_t>(i)] = timeAt(i);
  return t;
}

FeatureMatrix FeatureMatrix::select(const std::vector<std::string>& features) const {
  FeatureMatrix out;
  out.time = time;
  out.names = features;
  out.data.resize(rows(), static_cast<Eigen::Index>(features.size()));
  for (size_t c = 0; c < features.size(); ++c) out.data.col(c) = data.col(require(features[c]));
  return out;
}

void FeatureMatrix::validateShape() const {
  if (static_cast<Eigen::Index>(names.size()) != cols()) {
    throw std::invalid_argument("feature matrix has " + std::to_string(cols()) + " columns but " +
                                std::to_string(names.size()) + " names");
  }
  if (!time.empty() && static_cast<Eigen::Index>(time.size()) != rows()) {
    throw std::invalid_argument("feature matrix has " + std::to_string(rows()) + " rows but " +
                                std::to_string(time.size()) + " timestamps");
  }
}

namespace {

void checkStream(const Stream& s) {
  if (s.time.size() != s.values.size()) {
    throw std::invalid_argument("stream '" + s.name + "': " + std::to_string(s.time.size()) +
                                " timestamps but " + std::to_string(s.values.size()) + " values");
  }
  if (s.time.empty()) throw std::invalid_argument("stream '" + s.name + "' has no samples");
  for (size_t k = 0; k < s.time.size(); ++k) {
    if (!std::isfinite(s.time[k]) || !std::isfinite(s.values[k])) {
      std::ostringstream msg;
      const double bad = std::isfinite(s.time[k]) ? s.values[k] : s.time[k];
      msg << "stream '" << s.name << "' has " << (std::isnan(bad) ? "NaN" : "Inf") << " in "
          << (std::isfinite(s.time[k]) ? "its value" : "its timestamp") << " at sample " << k;
      throw std::invalid_argument(msg.str());
    }
    if (k > 0 && s.time[k] < s.time[k - 1]) {
      std::ostringstream msg;
      msg << "stream '" << s.name << "' has decreasing timestamps at index " << k;
      throw std::invalid_argument(msg.str());
    }
  }
}

// A stream sampled faster than the clock is averaged over each clock sample's period (centred on
// it) instead of read at one instant: the samples between two ticks carry what a point reading
// drops, e.g. a touch pad at 200 Hz read at 50 Hz keeps half its noise (sigma / sqrt(4)) and a
// weak contact stays visible. Where a period holds fewer than two samples (a stream at or below
// the clock's rate) the interpolated value stays. Discrete (zero-order-hold) streams are not
// averaged: a mean of two flag values is no flag value.
void averageWithinPeriods(const Stream& s, const std::vector<double>& clock, double period,
                          std::vector<double>* values) {
  size_t first = 0;  // first sample of the current period; clock and samples both increase
  for (size_t k = 0; k < clock.size(); ++k) {
    const double from = clock[k] - 0.5 * period, to = clock[k] + 0.5 * period;
    while (first < s.time.size() && s.time[first] < from) ++first;
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = first; i < s.time.size() && s.time[i] < to; ++i, ++count) sum += s.values[i];
    if (count >= 2) (*values)[k] = sum / static_cast<double>(count);
  }
}

}  // namespace

std::vector<double> interpolate(const Stream& s, const std::vector<double>& query) {
  checkStream(s);
  std::vector<double> out(query.size());
  size_t k = 0;  // queries are usually sorted: walk forward, fall back to binary search
  for (size_t q = 0; q < query.size(); ++q) {
    const double t = query[q];
    if (k >= s.time.size() || (k > 0 && s.time[k - 1] > t)) {
      k = std::upper_bound(s.time.begin(), s.time.end(), t) - s.time.begin();
    }
    while (k < s.time.size() && s.time[k] <= t) ++k;
    // now s.time[k-1] <= t < s.time[k]
    if (k == 0) {
      out[q] = s.values.front();
    } else if (k == s.time.size()) {
      out[q] = s.values.back();
    } else if (s.interpolation == Interpolation::kZeroOrderHold) {
      out[q] = s.values[k - 1];
    } else {
      const double t0 = s.time[k - 1], t1 = s.time[k];
      const double w = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
      out[q] = s.values[k - 1] + w * (s.values[k] - s.values[k - 1]);
    }
  }
  return out;
}

FeatureMatrix resample(const std::vector<Stream>& streams, double rate_hz) {
  if (streams.empty()) throw std::invalid_argument("resample: no streams");
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) {
    throw std::invalid_argument("resample: rate must be positive, got " + std::to_string(rate_hz));
  }
  double start = -INFINITY, end = INFINITY;
  for (const Stream& s : streams) {
    checkStream(s);
    start = std::max(start, s.time.front());
    end = std::min(end, s.time.back());
  }
  if (end < start) {
    throw std::invalid_argument("resample: the streams do not overlap in time (latest start " +
                                std::to_string(start) + " s > earliest end " + std::to_string(end) +
                                " s)");
  }
  const double period = 1.0 / rate_hz;
  const size_t samples = static_cast<size_t>(std::floor((end - start) / period + 1e-9)) + 1;
  FeatureMatrix out;
  out.time.resize(samples);
  for (size_t k = 0; k < samples; ++k) out.time[k] = start + k * period;
  out.data.resize(static_cast<Eigen::Index>(samples), static_cast<Eigen::Index>(streams.size()));
  for (size_t c = 0; c < streams.size(); ++c) {
    out.names.push_back(streams[c].name);
    std::vector<double> v = interpolate(streams[c], out.time);
    if (streams[c].interpolation == Interpolation::kLinear)
      averageWithinPeriods(streams[c], out.time, period, &v);
    out.data.col(c) = Eigen::Map<const Eigen::VectorXd>(v.data(), v.size());
  }
  return out;
}

FeatureMatrix resample(const FeatureMatrix& matrix, double rate_hz) {
  matrix.validateShape();
  if (matrix.time.empty()) throw std::invalid_argument("resample: the matrix has no clock");
  std::vector<Stream> streams(static_cast<std::size_t>(matrix.cols()));
  for (Eigen::Index c = 0; c < matrix.cols(); ++c) {
    Stream& s = streams[static_cast<std::size_t>(c)];
    s.name = matrix.names[static_cast<std::size_t>(c)];
    s.time = matrix.time;
    s.values.assign(matrix.data.col(c).data(), matrix.data.col(c).data() + matrix.rows());
  }
  return resample(streams, rate_hz);
}

bool normalizeMinMax(Eigen::Ref<Eigen::VectorXd> x, double eps) {
  if (x.size() == 0) return true;
  const double lo = x.minCoeff(), hi = x.maxCoeff();
  const double range = hi - lo;
  if (!(range > eps * (1.0 + std::max(std::abs(hi), std::abs(lo))))) {
    x.setZero();
    return true;
  }
  x = (x.array() - lo) / range;
  return false;
}

NormalizationInfo normalizeMinMax(Eigen::MatrixXd& data, double eps) {
  NormalizationInfo info;
  for (Eigen::Index c = 0; c < data.cols(); ++c) {
    const double lo = data.rows() ? data.col(c).minCoeff() : 0.0;
    const double hi = data.rows() ? data.col(c).maxCoeff() : 0.0;
    const bool constant = normalizeMinMax(data.col(c), eps);
    info.offset.push_back(lo);
    info.scale.push_back(constant ? 1.0 : hi - lo);
    info.constant.push_back(constant);
  }
  return info;
}

NormalizationInfo zNormalize(Eigen::MatrixXd& data, double eps) {
  NormalizationInfo info;
  for (Eigen::Index c = 0; c < data.cols(); ++c) {
    auto col = data.col(c);
    const double mean = data.rows() ? col.mean() : 0.0;
    const double var = data.rows() ? (col.array() - mean).square().mean() : 0.0;
    const double sd = std::sqrt(var);
    const bool constant = !(sd > eps * (1.0 + std::abs(mean)));
    if (constant) {
      col.setZero();
    } else {
      col = (col.array() - mean) / sd;
    }
    info.offset.push_back(mean);
    info.scale.push_back(constant ? 1.0 : sd);
    info.constant.push_back(constant);
  }
  return info;
}

void checkFinite(const FeatureMatrix& m, const std::string& context) {
  m.validateShape();
  const std::string prefix = context.empty() ? "" : context + ": ";
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      const double v = m.data(r, c);
      if (!std::isfinite(v)) {
        std::ostringstream msg;
        msg << prefix << "feature '" << m.names[c] << "' has " << (std::isnan(v) ? "NaN" : "Inf")
            << " at sample " << r << " (t=" << m.timeAt(r) << " s)";
        throw std::invalid_argument(msg.str());
      }
    }
  }
  for (size_t r = 0; r < m.time.size(); ++r) {
    if (!std::isfinite(m.time[r]) || (r > 0 && m.time[r] < m.time[r - 1])) {
      throw std::invalid_argument(
          prefix + "timestamps are not finite and non-decreasing at sample " + std::to_string(r));
    }
  }
}

}  // namespace lfd
