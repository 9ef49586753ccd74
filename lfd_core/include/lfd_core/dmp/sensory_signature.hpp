// The sensations each skill's demonstrations always showed, and a monitor that compares a
// reproduction with them (the paper's multisensory idea turned around: the signals that
// cut the demonstrations into skills also tell whether a skill is going as demonstrated).
//
// A signature holds, per segment and per sensor channel, the level the demonstrations showed along
// the segment's phase (0 at its start, 1 at its end) and how far they strayed from it. A reading is
// judged by its distance to the expected level, in units of that spread, with a slack in phase
// (demonstrations do the same thing at slightly different moments of a segment). A deviation must
// last `persistence` seconds before it counts, so that one noisy sample raises no alarm. Each
// channel's alarm threshold is a statistic of the demonstrations themselves: every demonstration is
// judged by the signature of the others (leave one out), and the threshold sits a margin above the
// worst of those nominal scores. Nothing is written per task or per sensor.
#pragma once

#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lfd_core/segmentation/time_series.hpp"

namespace lfd {

struct SignatureOptions {
  std::size_t phase_bins = 50;        ///< resolution of the expected level along a segment
  double phase_slack = 0.1;           ///< fraction of a segment: timing differences tolerated ...
  double time_slack = 0.5;            ///< ... and at least this many s (a boundary's placement)
  double persistence = 0.1;           ///< s a deviation must last (one noisy sample is no alarm)
  double min_spread_fraction = 0.05;  ///< spread >= this x the channel's range over the task
  double noise_sigmas = 3.0;          ///< spread >= this x the channel's measurement noise
  double threshold_margin = 1.5;      ///< alarm at margin x the worst leave-one-out score ...
  double min_threshold = 3.0;         ///< ... and never below this many spreads
  /// A channel is at rest within this fraction of its range over the task (at least noise_sigmas
  /// x its noise) of its rest level, both means over `persistence` (the rest level: the run's
  /// first such mean); a sensor (the channels of one source) when all its channels are. Where every
  /// demonstration's sensor was beyond twice that band (a contact all of them held, on whichever
  /// channel), a sensor at rest is a missing contact whatever the level's spread: the object is not
  /// there. 0 = off: a contact sensor's check, which the learner turns on for its monitored
  /// topics (learner.yaml signature/rest_band_fraction); off in the signature CLI, whose channels
  /// may follow the motion (PR2's tracking errors: 6 -> 5 of 9 at 0.05).
  double rest_band_fraction = 0.0;
};

/// Throws std::invalid_argument naming the option that is out of range (phase_bins in [2, 1000],
/// the others finite and >= 0, threshold_margin and min_threshold > 0).
void checkSignatureOptions(const SignatureOptions& options);

/// One channel's expectation along one segment.
struct ChannelSignature {
  Eigen::VectorXd mean;        ///< expected level per phase bin
  Eigen::VectorXd spread;      ///< its spread per bin (same units), floors applied
  double threshold = 0.0;      ///< alarm above this deviation (in spreads)
  double nominal_score = 0.0;  ///< the worst leave-one-out score of the demonstrations
  /// Per phase bin, how far from rest the channel's sensor was in the demonstration that was
  /// nearest to rest, in rest bands (its channel farthest from its first reading; empty: no
  /// missing-contact check, e.g. a library learned before it existed).
  Eigen::VectorXd held;
};

struct SegmentSignature {
  double duration_mean = 0.0;              ///< s
  double duration_spread = 0.0;            ///< s (std over the demonstrations)
  std::vector<ChannelSignature> channels;  ///< in SensorySignature::channels order
};

struct SensorySignature {
  std::vector<std::string> channels;  ///< feature names, e.g. /wrench/wrench/force/z
  std::vector<std::string> sources;   ///< per channel, where it is read live (a topic); optional
  std::vector<SegmentSignature> segments;
  /// Per channel, how near its rest level a reading is at rest (rest_band_fraction); empty or 0:
  /// no missing-contact check.
  std::vector<double> rest_bands;
  SignatureOptions options;
  std::size_t demonstrations = 0;
};

/// A demonstration or a run: its features (with a clock) and its boundaries (s from its first
/// sample), one fewer than its segments.
struct SegmentedRecording {
  FeatureMatrix features;
  std::vector<double> boundaries;
};

/// Learns the signature of `channels` from >= 2 demonstrations with the same number of boundaries.
/// `sources`: per channel, where it is read (its sensor: the channels of one source are judged
/// together for a missing contact); empty: every channel a sensor of its own. Throws
/// std::invalid_argument for fewer demos, a differing boundary count, boundaries out of order or
/// outside the recording, a missing channel, a recording without a clock, or sources that are not
/// one per channel.
SensorySignature learnSignature(const std::vector<SegmentedRecording>& demos,
                                const std::vector<std::string>& channels,
                                const SignatureOptions& options = {},
                                const std::vector<std::string>& sources = {});

/// Per channel, the index of its sensor: channels with the same source share one (sources empty:
/// one per channel).
std::vector<std::size_t> sensorOf(const SensorySignature& signature);

/// The phase slack of one segment: options.phase_slack, at least options.time_slack over the
/// segment's mean duration (a boundary placed 0.3 s off shifts every event near it by 0.3 s).
double segmentSlack(const SignatureOptions& options, const SegmentSignature& segment);

/// A reading of one channel, and whether every channel of its sensor is at rest (RestTracker;
/// false when that is unknown or the check is off).
struct Reading {
  double value = 0.0;
  bool sensor_at_rest = false;
};

/// How far one channel's reading at `phase` of `segment` is from what the demonstrations showed
/// within the slack around it, in spreads. The slack reaches into the neighbouring segments: a
/// boundary sits at a sensory event, so an event a little late in a run shows the previous
/// segment's level just after the boundary. A sensor at rest where every demonstration held a
/// contact throughout the slack is twice the channel's threshold (a clear alarm once it lasts).
double deviationAt(const std::vector<SegmentSignature>& segments, const SignatureOptions& options,
                   std::size_t segment, std::size_t channel, double phase, const Reading& reading);

/// Which sensors are at rest: each channel's mean over the last `window` s within its rest band of
/// the run's rest level, the first such mean (a noisy pad's single readings stray beyond the band,
/// its mean over 0.1 s does not). Nothing is at rest until the first window is complete.
class RestTracker {
 public:
  RestTracker(std::vector<double> rest_bands, std::vector<std::size_t> sensor_of, double window);
  /// After a reading of every channel at `time` s: per sensor, whether it is at rest.
  const std::vector<bool>& push(double time, const Eigen::VectorXd& values);
  /// A new run: its next readings make its rest level.
  void restart();

 private:
  std::vector<double> rest_bands_;
  std::vector<std::size_t> sensor_of_;
  double window_;
  std::deque<std::pair<double, Eigen::VectorXd>> recent_;
  Eigen::VectorXd sum_, rest_;  ///< rest_ empty until the first window is complete
  double first_time_ = 0.0;
  std::vector<bool> at_rest_;
};

/// A deviation that lasted: which segment and channel, when, expected versus measured.
struct Deviation {
  std::size_t segment = 0;
  std::size_t channel = 0;
  std::string channel_name;
  double time = 0.0;   ///< s (the recording's or the run's clock)
  double phase = 0.0;  ///< in the segment, 0..1
  double expected = 0.0;
  double measured = 0.0;
  double score = 0.0;  ///< sustained deviation / threshold: > 1 is an alarm
};

/// The smallest deviation over the last `persistence` s, once the readings span that long (0
/// before): a sliding-window minimum, so that a deviation counts only when it lasts.
class SustainedDeviation {
 public:
  explicit SustainedDeviation(double persistence) : persistence_(persistence) {}
  double push(double time, double deviation);
  void reset();

 private:
  double persistence_;
  std::deque<std::pair<double, double>> window_;  ///< (time, deviation), deviation increasing
  double first_time_ = 0.0;
  bool started_ = false;
};

/// Live monitoring: feed every reading as it comes; an alarm is a Deviation with score > 1.
class SignatureMonitor {
 public:
  explicit SignatureMonitor(const SensorySignature& signature);

  /// Judges one reading of every channel (signature order) at `phase` of `segment`, at `time` s.
  /// Returns the channel whose sustained deviation is largest relative to its threshold (score
  /// 0 until a deviation has lasted `persistence`). Throws std::invalid_argument for a segment out
  /// of range or a wrong number of values.
  Deviation observe(std::size_t segment, double phase, double time, const Eigen::VectorXd& values);

  /// Forgets the recent readings (a new segment).
  void reset();
  /// A new run (or a restart after a recovery): forgets the recent readings and the rest levels;
  /// the next readings make the run's rest (RestTracker).
  void start();

 private:
  const SensorySignature& signature_;
  std::vector<SustainedDeviation> recent_;
  std::vector<std::size_t> sensor_of_;  ///< per channel, its sensor (sensorOf)
  RestTracker rest_;
  std::size_t segment_ = 0;
};

/// Per segment and channel, the highest sustained deviation of a whole segmented run (offline
/// scoring with the live monitor's rule). scores[s][c] / threshold = the anomaly score; the
/// Deviation of each segment's worst channel is in `worst` when given.
std::vector<std::vector<double>> scoreRecording(const SensorySignature& signature,
                                                const SegmentedRecording& run,
                                                std::vector<Deviation>* worst = nullptr);

}  // namespace lfd
