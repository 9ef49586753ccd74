// Sensory events and confidence zones (paper II-C, eq. 1): changepoints proposed by ClaSP are
// kept only when they fall near an event of a sensor (touch, wrist force/torque, gripper ...).
//
// Event rule (paper: "after having removed the first difference, we detect the sensory events when
// the data goes from a low state to a high state and vice-versa, with a threshold 0.4 x max"):
//   d[t] = x[t] - x[t-1] (t >= 1) of the (optionally median-smoothed) sensor signal; the signal is
//   "active" while |d[t]| exceeds thr = threshold_ratio * max_t |d[t]|. The absolute value means a
//   rising step (sensor low -> high, d > 0) and a falling step (high -> low, d < 0) both count.
//   Events are the samples where the activity switches on AND where it switches off (the beginning
//   and the ending of each sensory event); an activity still on at the end yields no off-event.
// Robustness (real sensors are noisy; the paper's real-data failure mode is too many events):
//   - median_window: running median before differencing; removes spikes but keeps step edges;
//   - noise_floor_sigmas: thr is raised to at least that many robust noise sigmas (1.4826 * MAD)
//     of the raw first difference, so a sensor carrying only noise produces no event at all;
//   - hysteresis: activity switches off below hysteresis * thr (1 = the paper's single threshold);
//   - min_active_samples / merge_gap: drop one-sample blips, merge bursts closer than merge_gap;
//   - difference_lag: level change over a lag instead of the sample-to-sample difference. With a
//     lag L > 1 a step at t0 keeps the lagged difference high from t0 - L/2 to t0 + L/2, so the
//     events are moved back onto the change: the on-event by +L/2, the off-event by -L/2 (a step
//     gives one event at t0, a ramp one at its start and one at its end).
//   - threshold kNoise + noise_block: the threshold is a statistic of the noise measured where the
//     sensor is quiet (see EventThreshold).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

namespace lfd {

/// How the activity threshold is set.
enum class EventThreshold {
  /// The paper: threshold_ratio x the largest difference (raised to the noise floor if any).
  kRatioOfMax,
  /// A statistic of the noise: noise_floor_sigmas x the noise sigma estimated where the sensor is
  /// quiet (noise_block), and at least relative_floor x the largest difference so that a
  /// noise-free sensor's small wobbles are not events. Does not depend on how much of the demo
  /// is busy: a long oscillating contact cannot raise it above the contact onset.
  kNoise,
};

/// "ratio_of_max" (the paper's 0.4 x max) or "noise" (throws std::invalid_argument otherwise).
EventThreshold parse_event_threshold(const std::string& name);
std::string to_string(EventThreshold threshold);

struct SensoryEventConfig {
  EventThreshold threshold = EventThreshold::kRatioOfMax;
  double threshold_ratio = 0.4;        ///< paper's 0.4 x max |first difference|
  double relative_floor = 0.1;         ///< kNoise: threshold >= this x the largest difference
  std::size_t median_window = 5;       ///< odd; 0 or 1 = no smoothing (paper-literal)
  double noise_floor_sigmas = 6.0;     ///< 0 = paper-literal (no noise floor)
  double hysteresis = 0.5;             ///< in (0, 1]; 1 = paper-literal single threshold
  std::size_t min_active_samples = 1;  ///< bursts shorter than this are ignored
  std::size_t merge_gap = 0;           ///< bursts separated by <= merge_gap quiet samples merge
  /// Lag L of the difference (1 = the paper's first difference). With L > 1 the difference is
  /// y[t + L/2] - y[t - L + L/2] of the median-smoothed y: with median_window ~ L it compares the
  /// sensor's level just before and just after t, so a spike (inertia of a starting move) or a
  /// zero-mean vibration (a swinging load, chattering contact) is not an event, while contact
  /// made or lost is. The noise floor then comes from these lagged differences themselves.
  std::size_t difference_lag = 1;
  /// Local noise estimate: the differences are cut into blocks of this many samples, each block's
  /// robust sigma (1.4826 x MAD about its median) is taken, blocks that do not move at all (a
  /// sensor holding a stale value, a quantized sensor at rest) are left out, and the noise sigma
  /// is the 10th percentile of the others: the quiet stretches set it, however long the busy
  /// ones. 0 = one robust sigma over the whole demo.
  std::size_t noise_block = 0;
  /// Events placed on the change (a burst's start taken where it left the off level, lag shifts
  /// undone, a single-edge burst one event); false = where the thresholds are crossed.
  bool place_on_change = true;
};

/// A closed interval of sample indices [begin, end] (eq. 1 uses closed intervals).
struct Interval {
  std::size_t begin = 0;
  std::size_t end = 0;
  bool contains(std::size_t i) const { return begin <= i && i <= end; }
  bool operator==(const Interval& o) const { return begin == o.begin && end == o.end; }
};

/// Event sample indices of one sensor signal (sorted, unique). Index t refers to the sample where
/// the difference x[t] - x[t-1] switches the activity on (or the first quiet sample after it).
std::vector<std::size_t> detect_sensory_events(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                               const SensoryEventConfig& config = {});

/// Eq. (1): union over events s of [max(0, s - min_s/2), min(s + min_s/2, length)], merged into
/// disjoint sorted intervals (touching or overlapping intervals merge). min_s/2 uses integer
/// division. Note the paper's upper clip is len(T), not len(T) - 1; we keep it literally.
std::vector<Interval> confidence_zones(const std::vector<std::size_t>& events, std::size_t min_s,
                                       std::size_t length);

struct ChangepointValidation {
  std::vector<std::size_t> accepted;  ///< candidates inside a zone (sorted)
  std::vector<std::size_t> rejected;  ///< candidates outside every zone (sorted)
  std::vector<Interval> zones;
  std::vector<std::size_t> events;  ///< all sensor events (sorted, unique, all sensors)
  std::vector<std::vector<std::size_t>> events_per_sensor;  ///< per column of `sensors`
};

struct SensorEvents {
  std::vector<std::size_t> all;                      ///< every sensor's events (sorted, unique)
  std::vector<std::vector<std::size_t>> per_sensor;  ///< per column of `sensors`
};

/// Events of every sensor column (rows = samples); they do not depend on min_s. Throws
/// std::invalid_argument on non-finite sensor values or bad config.
SensorEvents detect_sensor_events(const Eigen::MatrixXd& sensors,
                                  const SensoryEventConfig& config = {});

/// Keeps the candidates that lie in a zone. Candidates are a sample index each.
ChangepointValidation validate_with_zones(const std::vector<std::size_t>& candidates,
                                          const std::vector<Interval>& zones);

/// Full paper step: events of every sensor column (rows = samples), zones with min_s, validation.
/// A matrix with zero columns yields no zones, hence every candidate rejected. Throws
/// std::invalid_argument on non-finite sensor values or bad config.
ChangepointValidation validate_changepoints(const std::vector<std::size_t>& candidates,
                                            const Eigen::MatrixXd& sensors, std::size_t min_s,
                                            const SensoryEventConfig& config = {});

}  // namespace lfd
