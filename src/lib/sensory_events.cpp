// Sensory events, confidence zones (paper eq. 1) and changepoint validation. The rule and the
// robustness options are documented in sensory_events.hpp.
#include "lfd_core/sensory_events.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

void check_config(const SensoryEventConfig& c) {
  if (!(c.threshold_ratio > 0.0 && c.threshold_ratio <= 1.0))
    throw std::invalid_argument("sensory events: threshold_ratio must be in (0, 1], got " +
                                std::to_string(c.threshold_ratio));
  if (!(c.hysteresis > 0.0 && c.hysteresis <= 1.0))
    throw std::invalid_argument("sensory events: hysteresis must be in (0, 1], got " +
                                std::to_string(c.hysteresis));
  if (!(c.noise_floor_sigmas >= 0.0))
    throw std::invalid_argument("sensory events: noise_floor_sigmas must be >= 0");
  if (c.difference_lag < 1)
    throw std::invalid_argument("sensory events: difference_lag must be >= 1");
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + mid));
  return m;
}

// Running median with a window shrunk symmetrically at the ends (so edges are not invented).
std::vector<double> running_median(const Eigen::Ref<const Eigen::VectorXd>& x, std::size_t window) {
  const std::size_t n = static_cast<std::size_t>(x.size());
  std::vector<double> out(n);
  if (window < 2) {
    for (std::size_t i = 0; i < n; ++i) out[i] = x[static_cast<Eigen::Index>(i)];
    return out;
  }
  const std::size_t half = window / 2;
  std::vector<double> buf;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t h = std::min({half, i, n - 1 - i});
    buf.assign(x.data() + (i - h), x.data() + (i + h + 1));
    std::nth_element(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(h), buf.end());
    out[i] = buf[h];
  }
  return out;
}

}  // namespace

std::vector<std::size_t> detect_sensory_events(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                               const SensoryEventConfig& config) {
  check_config(config);
  if (!signal.allFinite()) throw std::invalid_argument("sensory events: signal has NaN/Inf values");
  const std::size_t n = static_cast<std::size_t>(signal.size());
  if (n < 2) return {};
  const std::vector<double> y = running_median(signal, config.median_window);
  const std::size_t lag = config.difference_lag, ahead = lag / 2, behind = lag - ahead;
  std::vector<double> mag(n, 0.0);
  for (std::size_t t = behind; t + ahead < n; ++t) mag[t] = std::abs(y[t + ahead] - y[t - behind]);
  const double peak = *std::max_element(mag.begin(), mag.end());
  if (!(peak > 0.0)) return {};
  double on = config.threshold_ratio * peak;
  if (config.noise_floor_sigmas > 0.0 && lag > 1) {
    // Lagged differences of a smoothed signal are noise-dominated wherever nothing happens, so
    // their own robust spread is the noise level.
    std::vector<double> lagged(mag.begin() + static_cast<std::ptrdiff_t>(behind),
                               mag.end() - static_cast<std::ptrdiff_t>(ahead));
    on = std::max(on, config.noise_floor_sigmas * 1.4826 * median_of(lagged));
  } else if (config.noise_floor_sigmas > 0.0) {
    // Noise level of the RAW differences: a running median leaves plateaus whose differences are
    // mostly 0, which would make the robust sigma of the smoothed differences meaningless.
    std::vector<double> raw(n - 1);
    for (std::size_t t = 1; t < n; ++t)
      raw[t - 1] = signal[static_cast<Eigen::Index>(t)] - signal[static_cast<Eigen::Index>(t - 1)];
    const double med = median_of(raw);
    for (double& v : raw) v = std::abs(v - med);
    on = std::max(on, config.noise_floor_sigmas * 1.4826 * median_of(raw));
  }
  const double off = config.hysteresis * on;

  struct Burst {
    std::size_t begin, end;  // end = first quiet sample, or n if still active at the end
  };
  std::vector<Burst> bursts;
  bool active = false;
  for (std::size_t t = 1; t < n; ++t) {
    if (!active && mag[t] > on) {
      bursts.push_back({t, n});
      active = true;
    } else if (active && mag[t] <= off) {
      bursts.back().end = t;
      active = false;
    }
  }
  std::vector<Burst> merged;
  for (const Burst& b : bursts) {
    if (!merged.empty() && merged.back().end != n &&
        b.begin - merged.back().end <= config.merge_gap)
      merged.back().end = b.end;
    else
      merged.push_back(b);
  }
  std::vector<std::size_t> events;
  for (const Burst& b : merged) {
    if (b.end != n && b.end - b.begin < config.min_active_samples) continue;
    events.push_back(b.begin);
    if (b.end != n) events.push_back(b.end);
  }
  return events;
}

std::vector<Interval> confidence_zones(const std::vector<std::size_t>& events, std::size_t min_s,
                                       std::size_t length) {
  const std::size_t half = min_s / 2;
  std::vector<Interval> raw;
  raw.reserve(events.size());
  for (std::size_t s : events) raw.push_back({s > half ? s - half : 0, std::min(s + half, length)});
  std::sort(raw.begin(), raw.end(),
            [](const Interval& a, const Interval& b) { return a.begin < b.begin; });
  std::vector<Interval> zones;
  for (const Interval& z : raw) {
    // Integer intervals that overlap or touch ([0,5] and [6,9]) form one contiguous zone.
    if (!zones.empty() && z.begin <= zones.back().end + 1)
      zones.back().end = std::max(zones.back().end, z.end);
    else
      zones.push_back(z);
  }
  return zones;
}

ChangepointValidation validate_with_zones(const std::vector<std::size_t>& candidates,
                                          const std::vector<Interval>& zones) {
  ChangepointValidation out;
  out.zones = zones;
  std::vector<std::size_t> sorted = candidates;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t c : sorted) {
    const bool inside =
        std::any_of(zones.begin(), zones.end(), [c](const Interval& z) { return z.contains(c); });
    (inside ? out.accepted : out.rejected).push_back(c);
  }
  return out;
}

SensorEvents detect_sensor_events(const Eigen::MatrixXd& sensors,
                                  const SensoryEventConfig& config) {
  check_config(config);
  SensorEvents out;
  for (Eigen::Index c = 0; c < sensors.cols(); ++c) {
    if (!sensors.col(c).allFinite())
      throw std::invalid_argument("sensory events: sensor column " + std::to_string(c) +
                                  " has NaN/Inf values");
    out.per_sensor.push_back(detect_sensory_events(sensors.col(c), config));
    out.all.insert(out.all.end(), out.per_sensor.back().begin(), out.per_sensor.back().end());
  }
  std::sort(out.all.begin(), out.all.end());
  out.all.erase(std::unique(out.all.begin(), out.all.end()), out.all.end());
  return out;
}

ChangepointValidation validate_changepoints(const std::vector<std::size_t>& candidates,
                                            const Eigen::MatrixXd& sensors, std::size_t min_s,
                                            const SensoryEventConfig& config) {
  SensorEvents events = detect_sensor_events(sensors, config);
  ChangepointValidation out = validate_with_zones(
      candidates, confidence_zones(events.all, min_s, static_cast<std::size_t>(sensors.rows())));
  out.events = std::move(events.all);
  out.events_per_sensor = std::move(events.per_sensor);
  return out;
}

}  // namespace lfd
