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
//   - noise floors: thr is raised to at least noise_floor_excursions quiet excursions (the largest
//     lagged difference within a quiet block) and/or noise_floor_sigmas robust sigmas of the raw
//     first difference, so a sensor carrying only noise or drift produces no event at all;
//   - hysteresis: activity switches off below hysteresis * thr (1 = the paper's single threshold);
//   - min_active_samples / merge_gap: drop one-sample blips, merge bursts closer than merge_gap;
//   - difference_lag: level change over a lag instead of the sample-to-sample difference. A step
//     at t0 keeps the lagged difference high from t0 - L/2 to t0 + L/2; `placement` says where in
//     the burst the events go (where the thresholds are crossed, shifted back by L/2, or fitted
//     where the level starts to change and where it settles);
//   - rest edges: the events where a sensor (all channels of it: it leaves rest with its first
//     channel and is back with its last; a channel whose threshold is its noise floor cannot hold
//     it off rest) leaves its rest level or settles back at it for at least merge_gap (contact
//     made or lost) can be the only ones that make
//     zones (zones_from_rest_edges), and are placed where the samples stop being consistent with
//     rest when that is earlier (rest_edge_sigmas, a CUSUM change time);
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

/// Where an event is placed within the burst of activity that found it.
enum class EventPlacement {
  kThreshold,  ///< where the activity crosses the thresholds (the paper)
  /// Moved back onto the change: a burst starts where the activity left the off level, the lag
  /// shifts are undone (on +L/2, off -L/2), and a burst shorter than half a lag is one event.
  kShift,
  /// Fitted: a flat-ramp-flat curve (ramp_fit.hpp) around each end of the burst says where the
  /// level starts to change and where it settles; a short ramp or a step is one event. Exact on
  /// slow ramps, where a lag shift is off by the ramp's duration.
  kFit,
};

/// "threshold", "shift", "fit" (throws std::invalid_argument otherwise).
EventPlacement parseEventPlacement(const std::string& name);
std::string toString(EventPlacement placement);

/// "ratio_of_max" (the paper's 0.4 x max) or "noise" (throws std::invalid_argument otherwise).
EventThreshold parseEventThreshold(const std::string& name);
std::string toString(EventThreshold threshold);

struct SensoryEventConfig {
  EventThreshold threshold = EventThreshold::kRatioOfMax;
  double threshold_ratio = 0.4;     ///< paper's 0.4 x max |first difference|
  double relative_floor = 0.1;      ///< kNoise: threshold >= this x the largest difference
  std::size_t median_window = 5;    ///< odd; 0 or 1 = no smoothing (paper-literal)
  double noise_floor_sigmas = 6.0;  ///< 0 = paper-literal (no noise floor)
  /// The threshold is also at least this many quiet excursions (0 = off; needs noise_block): the
  /// largest lagged difference within a block, 0 for a block whose raw signal does not move at
  /// all, the 1/15 quantile over the blocks (a busy demo has few quiet seconds). Measured on the
  /// detector's own statistic, so drift, clipped, quantized or correlated noise needs no model (a
  /// sigma of the raw differences does not see a drift).
  double noise_floor_excursions = 0.0;
  double hysteresis = 0.5;             ///< in (0, 1]; 1 = paper-literal single threshold
  std::size_t min_active_samples = 1;  ///< bursts shorter than this are ignored
  std::size_t merge_gap = 0;           ///< bursts separated by <= merge_gap quiet samples merge
  /// Lag L of the difference (1 = the paper's first difference). With L > 1 the difference is
  /// y[t + L/2] - y[t - L + L/2] of the median-smoothed y: with median_window ~ L it compares the
  /// sensor's level just before and just after t, so a spike (inertia of a starting move) or a
  /// zero-mean vibration (a swinging load, chattering contact) is not an event, while contact
  /// made or lost is. The noise floor then comes from these lagged differences themselves.
  std::size_t difference_lag = 1;
  /// Local noise estimates, in blocks of this many samples: the quiet excursion above, and the
  /// sigma of noise_floor_sigmas (each block's robust sigma, 1.4826 x MAD about its median, of
  /// the raw differences, blocks that do not move at all left out, the 10th percentile of the
  /// others). Either way the quiet stretches set it, however long the busy ones. 0 = one robust
  /// sigma over the whole demo, no excursion floor.
  std::size_t noise_block = 0;
  EventPlacement placement = EventPlacement::kShift;
  /// Confidence zones only around SensorEvents::zone_events (rest edges): a force that varies
  /// while in contact, or a ramp reaching its plateau, is no new phase. false = every event.
  bool zones_from_rest_edges = false;
  /// kFit: a rest edge is also sought where the raw samples stop (start) being consistent with
  /// the rest level, by Page's CUSUM change time with the reference rest mean + rest_edge_sigmas
  /// x the rest sigma (both of the raw samples of the first noise_block, at least relative_floor
  /// x the largest difference for a noise-free sensor), within merge_gap of the fitted edge; the
  /// edge is the earlier onset (the later release) of the two. Under noise a weak first contact,
  /// or a weak last one, is statistically clear before the fitted ramp of the main change starts
  /// (after it ends). 0 = the fit alone.
  double rest_edge_sigmas = 0.0;
};

/// One sensory event, with what a zone needs to weigh it.
struct SensoryEvent {
  std::size_t index = 0;
  /// The signal leaves its rest level here, or settles back at it (kFit only): contact made or
  /// lost, a motion started from rest or ended at rest. The rest level is the sensor's level at
  /// the start of the demonstration, "at" meaning within the activity threshold of it. A change
  /// between two other levels (a force ramp reaching its plateau, a contact that weakens) is not.
  bool rest_edge = false;
  /// Largest lagged difference of its burst over the activity threshold (>= 1).
  double strength = 1.0;
  /// The level after the event is farther from the rest level than before it (a contact made, a
  /// press deepening); false when it comes back towards rest (a force easing off, a release).
  /// Over a sensor's channels: the strongest channel's. kFit only (true otherwise).
  bool away_from_rest = true;
  /// The start or the end of one level change whose other end is an event too (a ramp longer
  /// than half a lag that goes one way throughout: a torque dying out as a turn slows). kFit
  /// only; over a sensor's channels, only when every event at this sample is.
  bool ramp_end = false;
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
std::vector<std::size_t> detectSensoryEvents(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                             const SensoryEventConfig& config = {});

/// The same events with their rest-edge flag and strength (sorted by index, unique).
std::vector<SensoryEvent> detectSensoryEventDetails(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                                    const SensoryEventConfig& config = {});

/// Eq. (1): union over events s of [max(0, s - min_s/2), min(s + min_s/2, length)], merged into
/// disjoint sorted intervals (touching or overlapping intervals merge). min_s/2 uses integer
/// division. Note the paper's upper clip is len(T), not len(T) - 1; we keep it literally.
std::vector<Interval> confidenceZones(const std::vector<std::size_t>& events, std::size_t min_s,
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
  std::vector<SensoryEvent> details;  ///< every sensor's events (sorted by index, unique)
  /// The events that mark a sensory interaction (sorted, unique): each sensor's rest edges, or
  /// all its events when it has none (a sensor that never rests, or kThreshold/kShift placement).
  std::vector<std::size_t> zone_events;
};

/// Events of every sensor column (rows = samples); they do not depend on min_s. `groups` gives
/// each column's sensor (empty = every column its own): the channels of one sensor are at rest
/// only together, so a rest edge is where the whole sensor leaves or regains rest. Throws
/// std::invalid_argument on non-finite sensor values, bad config or a wrong number of groups.
SensorEvents detectSensorEvents(const Eigen::MatrixXd& sensors,
                                const SensoryEventConfig& config = {},
                                const std::vector<std::size_t>& groups = {});

/// Keeps the candidates that lie in a zone. Candidates are a sample index each.
ChangepointValidation validateWithZones(const std::vector<std::size_t>& candidates,
                                        const std::vector<Interval>& zones);

/// Full paper step: events of every sensor column (rows = samples), zones with min_s, validation.
/// A matrix with zero columns yields no zones, hence every candidate rejected. Throws
/// std::invalid_argument on non-finite sensor values or bad config.
ChangepointValidation validateChangepoints(const std::vector<std::size_t>& candidates,
                                           const Eigen::MatrixXd& sensors, std::size_t min_s,
                                           const SensoryEventConfig& config = {});

}  // namespace lfd
