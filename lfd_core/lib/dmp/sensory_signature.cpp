#include "lfd_core/dmp/sensory_signature.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace lfd {
namespace {

// Segment edges of a recording, in s from its first sample: 0, its boundaries, its end.
std::vector<double> segmentEdges(const SegmentedRecording& r) {
  std::vector<double> edges{0.0};
  edges.insert(edges.end(), r.boundaries.begin(), r.boundaries.end());
  edges.push_back(r.features.timeAt(r.features.rows() - 1) - r.features.timeAt(0));
  return edges;
}

void checkRecording(const SegmentedRecording& r, std::size_t boundaries,
                    const std::vector<std::string>& channels, const std::string& what) {
  if (r.features.time.empty() || r.features.rows() < 2)
    throw std::invalid_argument(what + " has no clock or fewer than 2 samples");
  if (r.boundaries.size() != boundaries)
    throw std::invalid_argument(what + " has " + std::to_string(r.boundaries.size()) +
                                " boundaries, the others " + std::to_string(boundaries));
  const std::vector<double> edges = segmentEdges(r);
  for (std::size_t k = 1; k < edges.size(); ++k)
    if (!(edges[k] > edges[k - 1]))
      throw std::invalid_argument(what + ": boundaries must increase within (0, " +
                                  std::to_string(edges.back()) + ") s");
  for (const std::string& c : channels) r.features.require(c);
}

// The channel's profile over one segment: the mean of the samples in each phase bin, linearly
// interpolated at the bin's centre where a bin holds no sample (a short segment, a slow sensor).
Eigen::VectorXd phaseProfile(const SegmentedRecording& r, int column, double start, double end,
                             std::size_t bins) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(bins));
  Eigen::VectorXd count = sum;
  std::vector<double> phases, values;
  const double t0 = r.features.timeAt(0);
  for (Eigen::Index i = 0; i < r.features.rows(); ++i) {
    const double phase = (r.features.timeAt(i) - t0 - start) / (end - start);
    if (phase < 0.0 || phase > 1.0) continue;
    const auto b = std::min<Eigen::Index>(static_cast<Eigen::Index>(phase * bins),
                                          static_cast<Eigen::Index>(bins) - 1);
    sum[b] += r.features.data(i, column);
    count[b] += 1.0;
    phases.push_back(phase);
    values.push_back(r.features.data(i, column));
  }
  Eigen::VectorXd out(static_cast<Eigen::Index>(bins));
  for (Eigen::Index b = 0; b < out.size(); ++b) {
    if (count[b] > 0) {
      out[b] = sum[b] / count[b];
      continue;
    }
    const double centre = (static_cast<double>(b) + 0.5) / static_cast<double>(bins);
    const auto after = std::upper_bound(phases.begin(), phases.end(), centre);
    if (after == phases.begin())
      out[b] = values.front();
    else if (after == phases.end())
      out[b] = values.back();
    else {
      const std::size_t k = static_cast<std::size_t>(after - phases.begin());
      const double w = (centre - phases[k - 1]) / (phases[k] - phases[k - 1]);
      out[b] = (1.0 - w) * values[k - 1] + w * values[k];
    }
  }
  return out;
}

// A channel's measurement noise: the robust sigma of its sample-to-sample differences (median
// absolute deviation), the median over the demonstrations.
double noiseSigma(const std::vector<SegmentedRecording>& demos, int column) {
  std::vector<double> sigmas;
  for (const SegmentedRecording& r : demos) {
    std::vector<double> diff;
    for (Eigen::Index i = 1; i < r.features.rows(); ++i)
      diff.push_back(std::abs(r.features.data(i, column) - r.features.data(i - 1, column)));
    std::nth_element(diff.begin(), diff.begin() + static_cast<long>(diff.size() / 2), diff.end());
    sigmas.push_back(1.4826 * diff[diff.size() / 2] / std::sqrt(2.0));
  }
  std::nth_element(sigmas.begin(), sigmas.begin() + static_cast<long>(sigmas.size() / 2),
                   sigmas.end());
  return sigmas[sigmas.size() / 2];
}

double taskRange(const std::vector<SegmentedRecording>& demos, int column) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const SegmentedRecording& r : demos) {
    lo = std::min(lo, r.features.data.col(column).minCoeff());
    hi = std::max(hi, r.features.data.col(column).maxCoeff());
  }
  return hi - lo;
}

std::size_t slackBins(const SignatureOptions& o, const SegmentSignature& segment) {
  return static_cast<std::size_t>(
      std::ceil(segmentSlack(o, segment) * static_cast<double>(o.phase_bins)));
}

// Mean and spread per bin from the profiles of the demonstrations; the variance is pooled over
// the bins within the phase slack (a handful of demos gives a poor variance per bin).
ChannelSignature expectation(const std::vector<Eigen::VectorXd>& profiles, double floor,
                             std::size_t slack) {
  const Eigen::Index bins = profiles.front().size();
  ChannelSignature c;
  c.mean = Eigen::VectorXd::Zero(bins);
  for (const Eigen::VectorXd& p : profiles) c.mean += p / static_cast<double>(profiles.size());
  Eigen::VectorXd var = Eigen::VectorXd::Zero(bins);
  if (profiles.size() > 1)
    for (const Eigen::VectorXd& p : profiles)
      var += (p - c.mean).array().square().matrix() / static_cast<double>(profiles.size() - 1);
  c.spread.resize(bins);
  for (Eigen::Index b = 0; b < bins; ++b) {
    const Eigen::Index lo = std::max<Eigen::Index>(0, b - static_cast<Eigen::Index>(slack));
    const Eigen::Index hi = std::min<Eigen::Index>(bins - 1, b + static_cast<Eigen::Index>(slack));
    c.spread[b] = std::max(floor, std::sqrt(var.segment(lo, hi - lo + 1).mean()));
  }
  return c;
}

struct ChannelFloors {
  std::vector<int> columns;
  std::vector<double> floors;
  std::vector<double> rest_bands;  // SignatureOptions::rest_band_fraction
};

ChannelFloors channelFloors(const std::vector<SegmentedRecording>& demos,
                            const std::vector<std::string>& channels, const SignatureOptions& o) {
  ChannelFloors f;
  for (const std::string& name : channels) {
    const int column = demos.front().features.require(name);
    f.columns.push_back(column);
    const double range = taskRange(demos, column),
                 noise = o.noise_sigmas * noiseSigma(demos, column);
    const double floor = std::max(o.min_spread_fraction * range, noise);
    // A channel that never changed: any change is a deviation, measured against a tiny unit.
    f.floors.push_back(std::max(floor, 1e-9));
    // (a constant channel: any change leaves rest)
    f.rest_bands.push_back(
        o.rest_band_fraction > 0 ? std::max({o.rest_band_fraction * range, noise, 1e-9}) : 0.0);
  }
  return f;
}

// Expected levels of every segment and channel from `demos` (thresholds not yet set).
std::vector<SegmentSignature> expectations(const std::vector<SegmentedRecording>& demos,
                                           const ChannelFloors& floors, const SignatureOptions& o) {
  const std::size_t segments = demos.front().boundaries.size() + 1;
  std::vector<SegmentSignature> out(segments);
  for (std::size_t s = 0; s < segments; ++s) {
    std::vector<double> durations;
    for (const SegmentedRecording& r : demos) {
      const std::vector<double> e = segmentEdges(r);
      durations.push_back(e[s + 1] - e[s]);
    }
    Eigen::Map<Eigen::VectorXd> d(durations.data(), static_cast<Eigen::Index>(durations.size()));
    out[s].duration_mean = d.mean();
    out[s].duration_spread = std::sqrt((d.array() - d.mean()).square().mean());
    for (std::size_t c = 0; c < floors.columns.size(); ++c) {
      std::vector<Eigen::VectorXd> profiles;
      for (const SegmentedRecording& r : demos) {
        const std::vector<double> e = segmentEdges(r);
        profiles.push_back(phaseProfile(r, floors.columns[c], e[s], e[s + 1], o.phase_bins));
      }
      out[s].channels.push_back(expectation(profiles, floors.floors[c], slackBins(o, out[s])));
    }
  }
  return out;
}

// A channel's rest level: its mean over the recording's first `window` s (RestTracker's).
double restLevel(const SegmentedRecording& r, int column, double window) {
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index i = 0; i < r.features.rows(); ++i) {
    if (count > 0 && r.features.timeAt(i) - r.features.timeAt(0) > window) break;
    sum += r.features.data(i, column);
    ++count;
  }
  return sum / count;
}

// Each channel's `held`: per bin, the least contact any demonstration's sensor showed, in rest
// bands: the largest distance of the sensor's channels from their rest level (which pad or axis
// feels the contact may differ between demonstrations, that one does not).
void setHeld(const std::vector<SegmentedRecording>& demos, const ChannelFloors& floors,
             const std::vector<std::size_t>& sensor_of, const SignatureOptions& o,
             std::vector<SegmentSignature>* segments) {
  const std::size_t sensors = *std::max_element(sensor_of.begin(), sensor_of.end()) + 1;
  const auto bins = static_cast<Eigen::Index>(o.phase_bins);
  for (std::size_t s = 0; s < segments->size(); ++s) {
    std::vector<Eigen::VectorXd> held(
        sensors, Eigen::VectorXd::Constant(bins, std::numeric_limits<double>::infinity()));
    for (const SegmentedRecording& r : demos) {
      const std::vector<double> e = segmentEdges(r);
      std::vector<Eigen::VectorXd> contact(sensors, Eigen::VectorXd::Zero(bins));
      for (std::size_t c = 0; c < sensor_of.size(); ++c) {
        const int column = floors.columns[c];
        const Eigen::VectorXd p = phaseProfile(r, column, e[s], e[s + 1], o.phase_bins);
        contact[sensor_of[c]] = contact[sensor_of[c]].cwiseMax(
            ((p.array() - restLevel(r, column, o.persistence)).abs() / floors.rest_bands[c])
                .matrix());
      }
      for (std::size_t g = 0; g < sensors; ++g) held[g] = held[g].cwiseMin(contact[g]);
    }
    for (std::size_t c = 0; c < sensor_of.size(); ++c)
      (*segments)[s].channels[c].held = held[sensor_of[c]];
  }
}

// Per sample of `run` and per sensor, whether it is at rest (RestTracker; no entry without bands).
std::vector<std::vector<bool>> sensorsAtRest(const SegmentedRecording& run,
                                             const std::vector<std::string>& channels,
                                             const std::vector<double>& rest_bands,
                                             const std::vector<std::size_t>& sensor_of,
                                             double window) {
  std::vector<std::vector<bool>> out(static_cast<std::size_t>(run.features.rows()));
  if (rest_bands.empty()) return out;
  std::vector<int> columns;
  for (const std::string& c : channels) columns.push_back(run.features.require(c));
  RestTracker tracker(rest_bands, sensor_of, window);
  Eigen::VectorXd values(static_cast<Eigen::Index>(columns.size()));
  for (Eigen::Index i = 0; i < run.features.rows(); ++i) {
    for (std::size_t c = 0; c < columns.size(); ++c)
      values[static_cast<Eigen::Index>(c)] = run.features.data(i, columns[c]);
    out[static_cast<std::size_t>(i)] = tracker.push(run.features.timeAt(i), values);
  }
  return out;
}

struct RawScores {
  std::vector<std::vector<double>> scores;    // [segment][channel]
  std::vector<std::vector<Deviation>> worst;  // [segment][channel], at the highest score
};

// rest_bands and sensor_of: per channel (empty bands: the levels alone, as the thresholds are set).
RawScores rawScores(const std::vector<SegmentSignature>& segments,
                    const std::vector<std::string>& channels, const SignatureOptions& o,
                    const SegmentedRecording& run, const std::vector<double>& rest_bands = {},
                    const std::vector<std::size_t>& sensor_of = {}) {
  const std::vector<std::vector<bool>> at_rest =
      sensorsAtRest(run, channels, rest_bands, sensor_of, o.persistence);
  RawScores out;
  out.scores.assign(segments.size(), std::vector<double>(channels.size(), 0.0));
  out.worst.assign(segments.size(), std::vector<Deviation>(channels.size()));
  const std::vector<double> edges = segmentEdges(run);
  const double t0 = run.features.timeAt(0);
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const int column = run.features.require(channels[c]);
    for (std::size_t s = 0; s < segments.size(); ++s) {
      SustainedDeviation sustained(o.persistence);
      const ChannelSignature& sig = segments[s].channels[c];
      for (Eigen::Index i = 0; i < run.features.rows(); ++i) {
        const double t = run.features.timeAt(i) - t0;
        if (t < edges[s] || t > edges[s + 1]) continue;
        const double phase = (t - edges[s]) / (edges[s + 1] - edges[s]);
        const double value = run.features.data(i, column);
        const std::vector<bool>& rest = at_rest[static_cast<std::size_t>(i)];
        const Reading reading{value, !rest.empty() && rest[sensor_of[c]]};
        const double d = sustained.push(t, deviationAt(segments, o, s, c, phase, reading));
        if (d <= out.scores[s][c]) continue;
        out.scores[s][c] = d;
        const auto bin = std::min<Eigen::Index>(static_cast<Eigen::Index>(phase * o.phase_bins),
                                                sig.mean.size() - 1);
        out.worst[s][c] = {s, c, channels[c], t, phase, sig.mean[bin], value, d};
      }
    }
  }
  return out;
}

// Each channel's nominal score: the worst of the demonstrations, each judged by the others.
void setThresholds(const std::vector<SegmentedRecording>& demos, const ChannelFloors& floors,
                   const std::vector<std::string>& channels, SensorySignature* signature) {
  const SignatureOptions& o = signature->options;
  for (std::size_t held_out = 0; held_out < demos.size(); ++held_out) {
    std::vector<SegmentedRecording> others;
    for (std::size_t d = 0; d < demos.size(); ++d)
      if (d != held_out) others.push_back(demos[d]);
    const RawScores raw = rawScores(expectations(others, floors, o), channels, o, demos[held_out]);
    for (std::size_t s = 0; s < raw.scores.size(); ++s)
      for (std::size_t c = 0; c < channels.size(); ++c) {
        ChannelSignature& sig = signature->segments[s].channels[c];
        sig.nominal_score = std::max(sig.nominal_score, raw.scores[s][c]);
      }
  }
  for (SegmentSignature& s : signature->segments)
    for (ChannelSignature& c : s.channels)
      c.threshold = std::max(o.min_threshold, o.threshold_margin * c.nominal_score);
}

}  // namespace

void checkSignatureOptions(const SignatureOptions& o) {
  if (o.phase_bins < 2 || o.phase_bins > 1000)
    throw std::invalid_argument("phase_bins must be in [2, 1000], got " +
                                std::to_string(o.phase_bins));
  const std::pair<const char*, double> at_least_zero[] = {
      {"phase_slack", o.phase_slack},   {"time_slack", o.time_slack},
      {"persistence", o.persistence},   {"min_spread_fraction", o.min_spread_fraction},
      {"noise_sigmas", o.noise_sigmas}, {"rest_band_fraction", o.rest_band_fraction}};
  for (const auto& [name, v] : at_least_zero)
    if (!(v >= 0) || !std::isfinite(v))
      throw std::invalid_argument(std::string(name) + " must be finite and >= 0");
  if (!(o.threshold_margin > 0) || !std::isfinite(o.threshold_margin) || !(o.min_threshold > 0) ||
      !std::isfinite(o.min_threshold))
    throw std::invalid_argument("threshold_margin and min_threshold must be finite and > 0");
}

std::vector<std::size_t> sensorOf(const SensorySignature& signature) {
  std::vector<std::size_t> out;
  std::vector<std::string> seen;
  for (std::size_t c = 0; c < signature.channels.size(); ++c) {
    if (signature.sources.size() != signature.channels.size()) {
      out.push_back(c);
      continue;
    }
    const auto it = std::find(seen.begin(), seen.end(), signature.sources[c]);
    out.push_back(static_cast<std::size_t>(it - seen.begin()));
    if (it == seen.end()) seen.push_back(signature.sources[c]);
  }
  return out;
}

SensorySignature learnSignature(const std::vector<SegmentedRecording>& demos,
                                const std::vector<std::string>& channels,
                                const SignatureOptions& options,
                                const std::vector<std::string>& sources) {
  if (demos.size() < 2)
    throw std::invalid_argument("a sensory signature needs at least 2 demonstrations, got " +
                                std::to_string(demos.size()));
  if (channels.empty()) throw std::invalid_argument("a sensory signature needs a channel");
  checkSignatureOptions(options);
  for (std::size_t d = 0; d < demos.size(); ++d)
    checkRecording(demos[d], demos.front().boundaries.size(), channels,
                   "demonstration " + std::to_string(d));
  if (!sources.empty() && sources.size() != channels.size())
    throw std::invalid_argument("a sensory signature needs one source per channel, got " +
                                std::to_string(sources.size()) + " for " +
                                std::to_string(channels.size()));
  SensorySignature signature;
  signature.channels = channels;
  signature.sources = sources;
  signature.options = options;
  signature.demonstrations = demos.size();
  const ChannelFloors floors = channelFloors(demos, channels, options);
  signature.segments = expectations(demos, floors, options);
  if (options.rest_band_fraction > 0) {
    signature.rest_bands = floors.rest_bands;
    setHeld(demos, floors, sensorOf(signature), options, &signature.segments);
  }
  setThresholds(demos, floors, channels, &signature);
  return signature;
}

double segmentSlack(const SignatureOptions& options, const SegmentSignature& segment) {
  return segment.duration_mean > 0
             ? std::max(options.phase_slack, options.time_slack / segment.duration_mean)
             : options.phase_slack;
}

namespace {

// A missing contact: the sensor at rest where the demonstrations all held one (2 bands away:
// their noise and the run's cannot meet).
bool missingContact(const ChannelSignature& channel, long bin, const Reading& r) {
  return r.sensor_at_rest && channel.held.size() > bin && channel.held[bin] >= 2.0;
}

// The smallest distance to the expected level over the phase bins [from, to] of one segment; a
// missing contact counts twice the channel's threshold.
double deviationOver(const ChannelSignature& channel, std::size_t phase_bins, double from,
                     double to, const Reading& reading) {
  const auto last = static_cast<long>(channel.mean.size()) - 1;
  const auto bin = [&](double p) {
    return std::clamp(static_cast<long>(std::floor(std::clamp(p, 0.0, 1.0) * phase_bins)), 0L,
                      last);
  };
  double best = std::numeric_limits<double>::infinity();
  for (long b = bin(from); b <= bin(to); ++b) {
    const double level = std::abs(reading.value - channel.mean[b]) / channel.spread[b];
    best = std::min(best, missingContact(channel, b, reading)
                              ? std::max(level, 2.0 * channel.threshold)
                              : level);
  }
  return best;
}

}  // namespace

double deviationAt(const std::vector<SegmentSignature>& segments, const SignatureOptions& options,
                   std::size_t segment, std::size_t channel, double phase, const Reading& reading) {
  const SegmentSignature& here = segments[segment];
  const double slack = segmentSlack(options, here);
  const double p = std::clamp(phase, 0.0, 1.0);
  double best =
      deviationOver(here.channels[channel], options.phase_bins, p - slack, p + slack, reading);
  // The part of the slack beyond this segment's edge, in seconds, then in the neighbour's phase.
  const double before = (slack - p) * here.duration_mean;
  if (before > 0 && segment > 0 && segments[segment - 1].duration_mean > 0) {
    const SegmentSignature& previous = segments[segment - 1];
    best = std::min(best, deviationOver(previous.channels[channel], options.phase_bins,
                                        1.0 - before / previous.duration_mean, 1.0, reading));
  }
  const double after = (p + slack - 1.0) * here.duration_mean;
  if (after > 0 && segment + 1 < segments.size() && segments[segment + 1].duration_mean > 0) {
    const SegmentSignature& next = segments[segment + 1];
    best = std::min(best, deviationOver(next.channels[channel], options.phase_bins, 0.0,
                                        after / next.duration_mean, reading));
  }
  return best;
}

double SustainedDeviation::push(double time, double deviation) {
  if (!started_) first_time_ = time;
  started_ = true;
  while (!window_.empty() && window_.back().second >= deviation) window_.pop_back();
  window_.emplace_back(time, deviation);
  while (window_.front().first < time - persistence_) window_.pop_front();
  return time - first_time_ >= persistence_ ? window_.front().second : 0.0;
}

RestTracker::RestTracker(std::vector<double> rest_bands, std::vector<std::size_t> sensor_of,
                         double window)
    : rest_bands_(std::move(rest_bands)), sensor_of_(std::move(sensor_of)), window_(window) {
  const std::size_t sensors =
      sensor_of_.empty() ? 0 : *std::max_element(sensor_of_.begin(), sensor_of_.end()) + 1;
  at_rest_.assign(sensors, false);
}

const std::vector<bool>& RestTracker::push(double time, const Eigen::VectorXd& values) {
  if (rest_bands_.size() != static_cast<std::size_t>(values.size())) return at_rest_;  // off
  if (recent_.empty() && rest_.size() == 0) {
    first_time_ = time;
    sum_ = Eigen::VectorXd::Zero(values.size());
  }
  recent_.emplace_back(time, values);
  sum_ += values;
  while (recent_.size() > 1 && recent_.front().first < time - window_) {
    sum_ -= recent_.front().second;
    recent_.pop_front();
  }
  if (time - first_time_ < window_) return at_rest_;
  const Eigen::VectorXd mean = sum_ / static_cast<double>(recent_.size());
  if (rest_.size() == 0) rest_ = mean;
  std::fill(at_rest_.begin(), at_rest_.end(), true);
  for (std::size_t c = 0; c < rest_bands_.size(); ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    if (!(std::abs(mean[i] - rest_[i]) < rest_bands_[c])) at_rest_[sensor_of_[c]] = false;
  }
  return at_rest_;
}

void RestTracker::restart() {
  recent_.clear();
  rest_.resize(0);
  std::fill(at_rest_.begin(), at_rest_.end(), false);
}

void SustainedDeviation::reset() {
  window_.clear();
  started_ = false;
}

SignatureMonitor::SignatureMonitor(const SensorySignature& signature)
    : signature_(signature),
      recent_(signature.channels.size(), SustainedDeviation(signature.options.persistence)),
      sensor_of_(sensorOf(signature)),
      rest_(signature.rest_bands, sensor_of_, signature.options.persistence) {}

void SignatureMonitor::reset() {
  for (SustainedDeviation& r : recent_) r.reset();
}

void SignatureMonitor::start() {
  reset();
  rest_.restart();
}

Deviation SignatureMonitor::observe(std::size_t segment, double phase, double time,
                                    const Eigen::VectorXd& values) {
  if (segment >= signature_.segments.size())
    throw std::invalid_argument("segment " + std::to_string(segment) + " of a signature with " +
                                std::to_string(signature_.segments.size()));
  if (values.size() != static_cast<Eigen::Index>(signature_.channels.size()))
    throw std::invalid_argument("expected " + std::to_string(signature_.channels.size()) +
                                " channel values, got " + std::to_string(values.size()));
  if (segment != segment_) reset();
  segment_ = segment;
  const std::vector<bool>& at_rest = rest_.push(time, values);
  const SignatureOptions& o = signature_.options;
  Deviation worst;
  for (std::size_t c = 0; c < recent_.size(); ++c) {
    const ChannelSignature& sig = signature_.segments[segment].channels[c];
    const double d = deviationAt(signature_.segments, o, segment, c, phase,
                                 {values[c], !at_rest.empty() && at_rest[sensor_of_[c]]});
    const double score = recent_[c].push(time, d) / sig.threshold;
    if (c > 0 && score <= worst.score) continue;
    const auto bin = std::min<Eigen::Index>(
        static_cast<Eigen::Index>(std::clamp(phase, 0.0, 1.0) * o.phase_bins), sig.mean.size() - 1);
    worst = {segment, c, signature_.channels[c], time, phase, sig.mean[bin], values[c], score};
  }
  return worst;
}

std::vector<std::vector<double>> scoreRecording(const SensorySignature& signature,
                                                const SegmentedRecording& run,
                                                std::vector<Deviation>* worst) {
  checkRecording(run, signature.segments.size() - 1, signature.channels, "the run");
  const RawScores raw = rawScores(signature.segments, signature.channels, signature.options, run,
                                  signature.rest_bands, sensorOf(signature));
  std::vector<std::vector<double>> scores = raw.scores;
  if (worst) worst->clear();
  for (std::size_t s = 0; s < scores.size(); ++s) {
    std::size_t top = 0;
    for (std::size_t c = 0; c < scores[s].size(); ++c) {
      scores[s][c] /= signature.segments[s].channels[c].threshold;
      if (scores[s][c] > scores[s][top]) top = c;
    }
    if (!worst) continue;
    Deviation w = raw.worst[s][top];
    w.segment = s;
    w.channel = top;
    w.channel_name = signature.channels[top];
    w.score = scores[s][top];
    worst->push_back(w);
  }
  return scores;
}

}  // namespace lfd
