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
  if (!(c.relative_floor >= 0.0 && c.relative_floor <= 1.0))
    throw std::invalid_argument("sensory events: relative_floor must be in [0, 1]");
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

double median_of(std::vector<double> v);

// Robust sigma (1.4826 x MAD about the median) of v.
double robust_sigma(std::vector<double> v) {
  const double med = median_of(v);
  for (double& x : v) x = std::abs(x - med);
  return 1.4826 * median_of(v);
}

// SensoryEventConfig::noise_block: the quiet blocks' sigma (10th percentile of the blocks that
// move at all); block 0 = one sigma over everything.
double noise_sigma(const std::vector<double>& d, std::size_t block) {
  if (block == 0 || d.size() < 2 * block) return robust_sigma(d);
  std::vector<double> sigmas;
  for (std::size_t b = 0; b + block <= d.size(); b += block) {
    const double s = robust_sigma(std::vector<double>(d.begin() + b, d.begin() + b + block));
    if (s > 0.0) sigmas.push_back(s);
  }
  if (sigmas.empty()) return 0.0;
  const std::size_t k = sigmas.size() / 10;
  std::nth_element(sigmas.begin(), sigmas.begin() + static_cast<std::ptrdiff_t>(k), sigmas.end());
  return sigmas[k];
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

EventThreshold parse_event_threshold(const std::string& name) {
  if (name == "ratio_of_max") return EventThreshold::kRatioOfMax;
  if (name == "noise") return EventThreshold::kNoise;
  throw std::invalid_argument("unknown event threshold '" + name + "' (ratio_of_max, noise)");
}

std::string to_string(EventThreshold threshold) {
  return threshold == EventThreshold::kNoise ? "noise" : "ratio_of_max";
}

std::vector<std::size_t> detect_sensory_events(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                               const SensoryEventConfig& config) {
  check_config(config);
  if (!signal.allFinite()) throw std::invalid_argument("sensory events: signal has NaN/Inf values");
  const std::size_t n = static_cast<std::size_t>(signal.size());
  if (n < 2) return {};
  const std::vector<double> y = running_median(signal, config.median_window);
  const std::size_t lag = config.difference_lag, ahead = lag / 2, behind = lag - ahead;
  // Only differences of fully smoothed samples: the median's window shrinks at the ends, where a
  // single noisy sample would otherwise look like a level change.
  const std::size_t edge = config.median_window > 1 ? config.median_window / 2 : 0;
  std::vector<double> mag(n, 0.0);
  for (std::size_t t = behind + edge; t + ahead + edge < n; ++t)
    mag[t] = std::abs(y[t + ahead] - y[t - behind]);
  const double peak = *std::max_element(mag.begin(), mag.end());
  if (!(peak > 0.0)) return {};
  // The noise is measured on the RAW first differences (nearly independent samples, so a block of
  // a second gives a fair estimate; a running median leaves plateaus whose differences are mostly
  // 0, and lagged differences of a smoothed signal are so correlated that a block holds only a few
  // independent values). For white noise of sigma s the raw differences have sigma sqrt(2) s and
  // the lagged differences of a median of w samples sqrt(2) * 1.2533 s / sqrt(w): the floor is
  // scaled by 1.2533 / sqrt(w). Correlated noise is underestimated by the raw differences, which
  // is why the floor is a generous number of sigmas.
  std::vector<double> diffs;
  for (std::size_t t = 1; t < n; ++t)
    diffs.push_back(signal[static_cast<Eigen::Index>(t)] -
                    signal[static_cast<Eigen::Index>(t - 1)]);
  const double smoothing = lag > 1 && config.median_window > 1
                               ? 1.2533 / std::sqrt(static_cast<double>(config.median_window))
                               : 1.0;
  const double sigma =
      config.noise_floor_sigmas > 0.0 ? smoothing * noise_sigma(diffs, config.noise_block) : 0.0;
  const double noise_floor = config.noise_floor_sigmas * sigma;
  const double on = config.threshold == EventThreshold::kNoise
                        ? std::max(noise_floor, config.relative_floor * peak)
                        : std::max(noise_floor, config.threshold_ratio * peak);
  const double off = config.hysteresis * on;

  struct Burst {
    std::size_t begin, end;  // end = first quiet sample, or n if still active at the end
  };
  std::vector<Burst> bursts;
  bool active = false;
  for (std::size_t t = 1; t < n; ++t) {
    if (!active && mag[t] > on) {
      // The activity began where it left the off level, not where it crossed the on level: a
      // force that builds up slowly crosses `on` late (symmetric to the off-event below).
      std::size_t begin = t;
      const std::size_t floor_at = bursts.empty() ? 1 : bursts.back().end + 1;
      while (config.place_on_change && begin > floor_at && mag[begin - 1] > off) --begin;
      bursts.push_back({begin, n});
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
  // With a lag the activity starts L/2 before the change and ends L/2 after it: move the events
  // back onto the change (see the header).
  const bool shift = config.place_on_change && lag > 1;
  const std::size_t on_shift = shift ? ahead : 0, off_shift = shift ? behind : 0;
  std::vector<std::size_t> events;
  for (const Burst& b : merged) {
    if (b.end != n && b.end - b.begin < config.min_active_samples) continue;
    const std::size_t begin = std::min(b.begin + on_shift, n - 1);
    events.push_back(begin);
    // A burst that spans less than half a lag after the shifts is a single edge (a step): one
    // event.
    if (b.end != n && b.end - off_shift >= begin + (shift ? ahead : 1))
      events.push_back(b.end - off_shift);
  }
  std::sort(events.begin(), events.end());
  events.erase(std::unique(events.begin(), events.end()), events.end());
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
