// Sensory events, confidence zones (paper eq. 1) and changepoint validation. The rule and the
// robustness options are documented in sensory_events.hpp.
#include "lfd_core/segmentation/sensory_events.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "lfd_core/segmentation/ramp_fit.hpp"
#include "lfd_core/util/robust_statistics.hpp"

namespace lfd {
namespace {

void checkConfig(const SensoryEventConfig& c) {
  if (!(c.relative_floor >= 0.0 && c.relative_floor <= 1.0))
    throw std::invalid_argument("sensory events: relative_floor must be in [0, 1]");
  if (!(c.threshold_ratio > 0.0 && c.threshold_ratio <= 1.0))
    throw std::invalid_argument("sensory events: threshold_ratio must be in (0, 1], got " +
                                std::to_string(c.threshold_ratio));
  if (!(c.hysteresis > 0.0 && c.hysteresis <= 1.0))
    throw std::invalid_argument("sensory events: hysteresis must be in (0, 1], got " +
                                std::to_string(c.hysteresis));
  if (!(c.noise_floor_sigmas >= 0.0) || !(c.noise_floor_excursions >= 0.0) ||
      !(c.rest_edge_sigmas >= 0.0))
    throw std::invalid_argument(
        "sensory events: noise_floor_sigmas, noise_floor_excursions and rest_edge_sigmas must be "
        ">= 0");
  if (c.difference_lag < 1)
    throw std::invalid_argument("sensory events: difference_lag must be >= 1");
}

// SensoryEventConfig::noise_block: the quiet blocks' sigma (10th percentile of the blocks that
// move at all); block 0 = one sigma over everything.
double noiseSigma(const std::vector<double>& d, std::size_t block) {
  if (block == 0 || d.size() < 2 * block) return robustSigma(d);
  std::vector<double> sigmas;
  for (std::size_t b = 0; b + block <= d.size(); b += block) {
    const double s = robustSigma(std::vector<double>(d.begin() + b, d.begin() + b + block));
    if (s > 0.0) sigmas.push_back(s);
  }
  if (sigmas.empty()) return 0.0;
  const std::size_t k = sigmas.size() / 10;
  std::nth_element(sigmas.begin(), sigmas.begin() + static_cast<std::ptrdiff_t>(k), sigmas.end());
  return sigmas[k];
}

// SensoryEventConfig::noise_floor_excursions: how far the detector's own statistic (the lagged
// difference `mag`) goes when nothing happens. Each block of `block` samples gives its largest
// |lagged difference|, 0 for a block whose raw signal does not move at all; their
// 1/kQuietBlocksPerQuiet quantile is the quiet excursion. Unlike a sigma of the raw differences it
// needs no noise model: drift, clipped (a touch pad's force cannot go below 0), quantized or
// correlated noise is measured as the detector sees it. A noise-free signal (constant between its
// changes) has a quiet excursion of 0. One block in this many is assumed quiet. A wiping demo of 13
// s in contact from 1.7 s to 11.2 s has one quiet 1 s block of 13: the 10th percentile (the 2nd
// quietest block) held a press edge and raised the floor above every press (no event in that demo).
// Every dataset and signal class is unchanged by 15 except that one; with the minimum (1 in all) a
// slowly drifting channel's calmest second set the floor below its drift (unit test
// DriftWithoutContact...).
constexpr std::size_t kQuietBlocksPerQuiet = 15;

double quietExcursion(const Eigen::Ref<const Eigen::VectorXd>& signal,
                      const std::vector<double>& mag, std::size_t block) {
  const std::size_t n = mag.size();
  if (block == 0 || n < 2 * block) return 0.0;
  std::vector<double> maxima;
  for (std::size_t b = 0; b + block <= n; b += block) {
    const auto part =
        signal.segment(static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(block));
    const bool still = !(part.maxCoeff() > part.minCoeff());
    maxima.push_back(still ? 0.0 : *std::max_element(mag.begin() + b, mag.begin() + b + block));
  }
  const std::size_t k = maxima.size() / kQuietBlocksPerQuiet;
  std::nth_element(maxima.begin(), maxima.begin() + static_cast<std::ptrdiff_t>(k), maxima.end());
  return maxima[k];
}

// Running median with a window shrunk symmetrically at the ends (so edges are not invented).
std::vector<double> runningMedian(const Eigen::Ref<const Eigen::VectorXd>& x, std::size_t window) {
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

EventThreshold parseEventThreshold(const std::string& name) {
  if (name == "ratio_of_max") return EventThreshold::kRatioOfMax;
  if (name == "noise") return EventThreshold::kNoise;
  throw std::invalid_argument("unknown event threshold '" + name + "' (ratio_of_max, noise)");
}

std::string toString(EventThreshold threshold) {
  return threshold == EventThreshold::kNoise ? "noise" : "ratio_of_max";
}

namespace {

struct Burst {
  std::size_t begin, end;  // end = first quiet sample, or n if still active at the end
  double peak;             // largest lagged difference inside
};

// An event and on which side its channel is at rest (kFit).
struct PlacedEvent {
  SensoryEvent event;
  bool from_rest = false, to_rest = false;
};

struct Channel {
  std::vector<double> y;  // median-smoothed signal
  double rest = 0.0;      // rest level
  double on = 0.0;        // activity threshold
  // The threshold is the noise floor, above the ratio of the largest change: the channel's
  // contact is within a few noise levels (a torque the press barely moves), so its drift can keep
  // it off its rest level for good.
  bool noise_limited = false;
  std::vector<PlacedEvent> events;
};

// The detector's statistic: |y[t + ahead] - y[t - behind]| of the smoothed y, 0 where it would
// use the median's shrunk edges (a single noisy sample there would look like a level change).
std::vector<double> laggedDifferences(const std::vector<double>& y, std::size_t lag,
                                      std::size_t edge) {
  const std::size_t n = y.size(), ahead = lag / 2, behind = lag - ahead;
  std::vector<double> mag(n, 0.0);
  for (std::size_t t = behind + edge; t + ahead + edge < n; ++t)
    mag[t] = std::abs(y[t + ahead] - y[t - behind]);
  return mag;
}

// On-threshold of the activity: the paper's ratio of the largest difference (or the noise rule),
// never below the noise floors.
void setActivityThreshold(const Eigen::Ref<const Eigen::VectorXd>& signal,
                          const std::vector<double>& mag, double peak,
                          const SensoryEventConfig& config, Channel* c) {
  // The sigma floor is measured on the RAW first differences (nearly independent samples) and
  // scaled to the lagged differences of a median of w samples (white noise: x 1.2533 / sqrt(w)).
  double sigma = 0.0;
  if (config.noise_floor_sigmas > 0.0) {
    std::vector<double> diffs;
    for (Eigen::Index t = 1; t < signal.size(); ++t) diffs.push_back(signal[t] - signal[t - 1]);
    const double smoothing = config.difference_lag > 1 && config.median_window > 1
                                 ? 1.2533 / std::sqrt(static_cast<double>(config.median_window))
                                 : 1.0;
    sigma = smoothing * noiseSigma(diffs, config.noise_block);
  }
  const double excursion =
      config.noise_floor_excursions > 0.0 ? quietExcursion(signal, mag, config.noise_block) : 0.0;
  const double floor =
      std::max(config.noise_floor_sigmas * sigma, config.noise_floor_excursions * excursion);
  const double ratio =
      config.threshold == EventThreshold::kNoise ? config.relative_floor : config.threshold_ratio;
  c->on = std::max(floor, ratio * peak);
  c->noise_limited = floor > ratio * peak;
}

std::vector<Burst> findBursts(const std::vector<double>& mag, double on, double off,
                              bool walk_back) {
  const std::size_t n = mag.size();
  std::vector<Burst> bursts;
  bool active = false;
  for (std::size_t t = 1; t < n; ++t) {
    if (!active && mag[t] > on) {
      // The activity began where it left the off level, not where it crossed the on level: a
      // force that builds up slowly crosses `on` late (symmetric to the off-event below).
      std::size_t begin = t;
      const std::size_t floor_at = bursts.empty() ? 1 : bursts.back().end + 1;
      while (walk_back && begin > floor_at && mag[begin - 1] > off) --begin;
      bursts.push_back({begin, n, 0.0});
      active = true;
    } else if (active && mag[t] <= off) {
      bursts.back().end = t;
      active = false;
    }
    if (active) bursts.back().peak = std::max(bursts.back().peak, mag[t]);
  }
  return bursts;
}

std::vector<Burst> mergeBursts(const std::vector<Burst>& bursts, std::size_t gap, std::size_t n) {
  std::vector<Burst> merged;
  for (const Burst& b : bursts) {
    if (!merged.empty() && merged.back().end != n && b.begin - merged.back().end <= gap) {
      merged.back().end = b.end;
      merged.back().peak = std::max(merged.back().peak, b.peak);
    } else {
      merged.push_back(b);
    }
  }
  return merged;
}

// y[t + ahead] - y[t - behind] of the smoothed y (laggedDifferences with its sign); 0 where it is
// not defined.
double signedDifference(const std::vector<double>& y, std::size_t lag, std::size_t t) {
  const std::size_t ahead = lag / 2, behind = lag - ahead;
  if (t < behind || t + ahead >= y.size()) return 0.0;
  return y[t + ahead] - y[t - behind];
}

// Where the level's change turns round, scanning from `from` towards `to` (either way): having
// gone one way by more than `off`, the signed lagged difference goes the other way by more than
// `off`; the last sample before that which still went the first way (or had no sign). `to` when
// the change never turns round.
std::size_t turningPoint(const std::vector<double>& y, std::size_t lag, std::size_t from,
                         std::size_t to, double off) {
  const long step = to >= from ? 1 : -1;
  double direction = 0.0;
  std::size_t last_along = from;
  for (std::size_t t = from; t != to; t = static_cast<std::size_t>(static_cast<long>(t) + step)) {
    const double d = signedDifference(y, lag, t);
    if (direction == 0.0 && std::abs(d) > off) direction = d > 0 ? 1.0 : -1.0;
    if (direction * d >= 0.0) last_along = t;
    if (direction * d < -off) return last_along;
  }
  return to;
}

// The windows [begin, end) fitRamp sees around a burst's start and its end. Each reaches a lag
// beyond the burst's edge on the outside and two lags inside, but not past the point where the
// level's change turns round (turningPoint): the merge gap can join two changes into one burst, a
// force rising as a snap hook deflects and falling as it clicks over, and one flat-ramp-flat fit
// across both put the rise's start on the fall (the insertion of the snap-fit class was lost). A
// window keeps at least a lag inside the burst, where the new level shows, so that a wiping
// force whose friction flips at every stroke is still fitted on its press.
struct FitWindows {
  std::size_t first_begin, first_end, last_begin, last_end;
};

FitWindows fitWindows(const Burst& b, const Channel& c, const SensoryEventConfig& config) {
  const std::size_t n = c.y.size(), lag = config.difference_lag;
  const double off = config.hysteresis * c.on;
  FitWindows w;
  w.first_begin = b.begin > lag ? b.begin - lag : 0;
  const std::size_t first_reach = std::min(n, b.begin + 2 * lag + 1);
  const std::size_t first_turn = turningPoint(c.y, lag, b.begin, first_reach, off) + 1;
  w.first_end = std::max(std::min(first_reach, std::max(first_turn, b.begin + lag + 1)),
                         std::min(n, w.first_begin + 2));
  w.last_end = std::min(n, b.end + lag + 1);
  const std::size_t last_reach = b.end > 2 * lag + w.first_begin ? b.end - 2 * lag : w.first_begin;
  if (b.end == n) {
    w.last_begin = last_reach;
    return w;
  }
  const std::size_t last_turn = turningPoint(c.y, lag, b.end - 1, last_reach, off);
  w.last_begin = std::min(std::max(last_reach, std::min(last_turn, b.end > lag ? b.end - lag : 0)),
                          w.last_end - 2);
  return w;
}

// Whether a change from level `before` to `after` moves channel c away from its rest level.
bool away(const Channel& c, double before, double after) {
  return std::abs(after - c.rest) > std::abs(before - c.rest);
}

// EventPlacement::kFit: the burst's start where the level starts to change and its end where it
// settles (fitRamp in fitWindows); the ends of a short ramp or step are one event. An event whose
// outer level is the rest level (the level at the demo's start, within the activity threshold)
// leaves or regains rest on this channel.
void placeByFit(const Burst& b, const Channel& c, const SensoryEventConfig& config,
                std::vector<PlacedEvent>* events) {
  const std::size_t n = c.y.size(), lag = config.difference_lag;
  const double strength = b.peak / c.on;
  const FitWindows w = fitWindows(b, c, config);
  const RampFit first = fitRamp(c.y, w.first_begin, w.first_end);
  const bool from_rest = std::abs(first.before - c.rest) < c.on;
  if (b.end == n) {
    events->push_back(
        {{first.start, from_rest, strength, away(c, first.before, first.after)}, from_rest, false});
    return;
  }
  const RampFit last = fitRamp(c.y, w.last_begin, w.last_end);
  const bool to_rest = std::abs(last.after - c.rest) < c.on;
  if (last.end <= first.start + lag / 2) {  // one step: the rest side says where
    const std::size_t at = !from_rest && to_rest ? last.end : first.start;
    events->push_back({{at, from_rest || to_rest, strength, away(c, first.before, last.after)},
                       from_rest,
                       to_rest});
    return;
  }
  const bool away_first = away(c, first.before, first.after);
  const bool away_last = away(c, last.before, last.after);
  const bool one_change = away_first == away_last;
  events->push_back({{first.start, from_rest, strength, away_first, one_change}, from_rest, false});
  events->push_back({{last.end, to_rest, strength, away_last, one_change}, false, to_rest});
}

// EventPlacement::kThreshold and kShift: at the burst's ends, shifted back onto the change by
// half a lag (kShift; a burst that spans less than half a lag after the shifts is one step).
void placeAtBurstEnds(const Burst& b, std::size_t n, const SensoryEventConfig& config,
                      double strength, std::vector<PlacedEvent>* events) {
  const std::size_t lag = config.difference_lag, ahead = lag / 2, behind = lag - ahead;
  const bool shift = config.placement == EventPlacement::kShift && lag > 1;
  const std::size_t begin = std::min(b.begin + (shift ? ahead : 0), n - 1);
  events->push_back({{begin, false, strength}, false, false});
  if (b.end != n && b.end - (shift ? behind : 0) >= begin + (shift ? ahead : 1))
    events->push_back({{b.end - (shift ? behind : 0), false, strength}, false, false});
}

// SensoryEventConfig::rest_edge_sigmas: Page's CUSUM change time of the raw samples x against
// the rest level. S accumulates x - reference and is reset at 0, the reference lying
// rest_edge_sigmas rest sigmas above the rest mean: at rest S keeps returning to 0, in contact it
// grows. A contact's onset is then the sample after S's last reset before the fitted ramp is under
// way, and its release (time reversed) the first sample of the last stretch that looks like rest.
// A weak first touch (or a fading last one) under noise moves S long before one sample or the
// smoothed level shows it, where the fit sees only the main change. The edge moves only outwards
// (an earlier onset, a later release), within merge_gap (activity separated by less is one
// activity) and never past the channel's neighbouring events.
void placeRestEdgesByCusum(const Eigen::Ref<const Eigen::VectorXd>& x, std::size_t head,
                           double peak, const SensoryEventConfig& config, Channel* c) {
  const std::size_t n = static_cast<std::size_t>(x.size()), lag = config.difference_lag,
                    gap = config.merge_gap;
  const auto rest = x.head(static_cast<Eigen::Index>(head));
  const double mean = rest.mean();
  const double sigma = std::sqrt((rest.array() - mean).square().mean());
  // A noise-free sensor has no statistical band: its exponential settling would otherwise look
  // like contact for ever; relative_floor x the largest difference stands for its resolution.
  const double reference =
      mean + std::max(config.rest_edge_sigmas * sigma, config.relative_floor * peak);
  std::vector<PlacedEvent>& events = c->events;
  for (std::size_t i = 0; i < events.size(); ++i) {
    PlacedEvent& p = events[i];
    const std::size_t e = p.event.index;
    const std::size_t previous = i > 0 ? events[i - 1].event.index : 0;
    const std::size_t next = i + 1 < events.size() ? events[i + 1].event.index : n;
    double s = 0.0;
    bool reset = false;
    if (p.from_rest && !p.to_rest) {
      const std::size_t lo = std::max(i > 0 ? previous + 1 : 0, e > gap ? e - gap : 0);
      std::size_t last_reset = lo;
      for (std::size_t t = lo; t < std::min(n, e + lag); ++t) {
        s = std::max(0.0, s + x[static_cast<Eigen::Index>(t)] - reference);
        if (s == 0.0) reset = true, last_reset = t;
      }
      if (s > 0.0 && reset && last_reset + 1 < e) p.event.index = last_reset + 1;
    } else if (p.to_rest && !p.from_rest) {
      const std::size_t lo = std::max(previous, e > lag ? e - lag : 0);
      const std::size_t hi = std::min(next, e + gap + 1);
      std::size_t first_reset = hi;
      for (std::size_t t = hi; t-- > lo;) {
        s = std::max(0.0, s + x[static_cast<Eigen::Index>(t)] - reference);
        if (s == 0.0) reset = true, first_reset = t;
      }
      if (s > 0.0 && reset && first_reset > e) p.event.index = first_reset;
    }
  }
}

// One channel: smoothed signal, rest level, activity threshold and its events.
Channel analyseChannel(const Eigen::Ref<const Eigen::VectorXd>& signal,
                       const SensoryEventConfig& config) {
  if (!signal.allFinite()) throw std::invalid_argument("sensory events: signal has NaN/Inf values");
  Channel c;
  const std::size_t n = static_cast<std::size_t>(signal.size());
  if (n < 2) return c;
  c.y = runningMedian(signal, config.median_window);
  const std::size_t edge = config.median_window > 1 ? config.median_window / 2 : 0;
  const std::vector<double> mag = laggedDifferences(c.y, config.difference_lag, edge);
  const double peak = *std::max_element(mag.begin(), mag.end());
  if (!(peak > 0.0)) return c;
  setActivityThreshold(signal, mag, peak, config, &c);
  const bool walk_back = config.placement != EventPlacement::kThreshold;
  const std::vector<Burst> bursts =
      mergeBursts(findBursts(mag, c.on, config.hysteresis * c.on, walk_back), config.merge_gap, n);
  // The rest level: where the sensor starts, before the robot interacts with anything.
  const std::size_t head =
      std::min(n, std::max<std::size_t>(config.noise_block, config.difference_lag));
  c.rest = medianOf(std::vector<double>(c.y.begin(), c.y.begin() + head));
  const bool fit = config.placement == EventPlacement::kFit && config.difference_lag > 1;
  for (const Burst& b : bursts) {
    if (b.end != n && b.end - b.begin < config.min_active_samples) continue;
    if (fit)
      placeByFit(b, c, config, &c.events);
    else
      placeAtBurstEnds(b, n, config, b.peak / c.on, &c.events);
  }
  std::sort(c.events.begin(), c.events.end(), [](const PlacedEvent& a, const PlacedEvent& b) {
    return a.event.index < b.event.index;
  });
  if (fit && config.rest_edge_sigmas > 0.0) placeRestEdgesByCusum(signal, head, peak, config, &c);
  return c;
}

// Whether channel c sits at its rest level over [from, to) (median distance within its threshold).
bool atRest(const Channel& c, std::size_t from, std::size_t to) {
  if (c.events.empty()) return true;  // never active
  to = std::min(to, c.y.size());
  if (from >= to) return true;
  std::vector<double> d;
  for (std::size_t t = from; t < to; ++t) d.push_back(std::abs(c.y[t] - c.rest));
  return medianOf(d) < c.on;
}

// Whether channel c leaves its rest level (`leaving`) or regains it at a sample of [from, to).
bool restEdgeWithin(const Channel& c, bool leaving, std::size_t from, std::size_t to) {
  return std::any_of(c.events.begin(), c.events.end(), [&](const PlacedEvent& p) {
    return (leaving ? p.from_rest : p.to_rest) && p.event.index >= from && p.event.index < to;
  });
}

// For every sample, the length of the run of samples around it where the whole group sits at
// rest (0 where it does not).
std::vector<std::size_t> restRunLengths(const std::vector<Channel>& channels,
                                        const std::vector<std::size_t>& group) {
  const std::size_t n = channels[group.front()].y.size();
  std::vector<std::size_t> run(n, 0);
  std::size_t t = 0;
  while (t < n) {
    const auto quiet = [&](std::size_t i) {
      for (std::size_t c : group)
        if (!channels[c].events.empty() &&
            !(std::abs(channels[c].y[i] - channels[c].rest) < channels[c].on))
          return false;
      return true;
    };
    if (!quiet(t)) {
      ++t;
      continue;
    }
    std::size_t end = t;
    while (end < n && quiet(end)) ++end;
    std::fill(run.begin() + static_cast<std::ptrdiff_t>(t),
              run.begin() + static_cast<std::ptrdiff_t>(end), end - t);
    t = end;
  }
  return run;
}

// The channels that say when the sensor is at rest: those whose contact stands clear of their
// noise, when it has any (else all of them).
std::vector<std::size_t> decidingChannels(const std::vector<Channel>& channels,
                                          const std::vector<std::size_t>& group) {
  std::vector<std::size_t> clear;
  for (std::size_t c : group)
    if (!channels[c].events.empty() && !channels[c].noise_limited) clear.push_back(c);
  return clear.empty() ? group : clear;
}

// A sensor of several channels (a touch pad per finger, a force vector) is at rest only when
// all of them are: one pad letting go while the other takes over is not the contact's end, and the
// sensor leaves rest with its first channel and regains it with its last (a channel's edge is
// none when another leaves rest up to a lag before it, or regains it up to a lag after it: the
// friction of a wiping hand that flips one last time while the press force still fades). And
// a rest shorter than `min_rest` samples (the merge gap: activity separated by less is one
// activity) is a pause within the interaction, not its end: a teleoperator's hesitation, an arm
// slowing between two strokes. Only the deciding channels (above) can hold the sensor off rest.
void flagRestEdgesOfGroup(std::vector<Channel>* channels, const std::vector<std::size_t>& group,
                          std::size_t lag, std::size_t min_rest) {
  const std::vector<std::size_t> deciding = decidingChannels(*channels, group);
  const std::vector<std::size_t> run = restRunLengths(*channels, deciding);
  const auto longest = [&](std::size_t from, std::size_t to) {
    std::size_t best = 0;
    for (std::size_t t = from; t < std::min(to, run.size()); ++t) best = std::max(best, run[t]);
    return best;
  };
  for (std::size_t c : group) {
    for (PlacedEvent& p : (*channels)[c].events) {
      const std::size_t e = p.event.index, lo = e > lag ? e - lag : 0;
      bool before = p.from_rest && longest(lo, e) >= min_rest;
      bool after = p.to_rest && longest(e, e + lag) >= min_rest;
      for (std::size_t o : deciding) {
        if (o == c) continue;
        const Channel& other = (*channels)[o];
        before = before && atRest(other, lo, e) && !restEdgeWithin(other, true, lo, e);
        after =
            after && atRest(other, e, e + lag) && !restEdgeWithin(other, false, e + 1, e + lag + 1);
      }
      p.event.rest_edge = before || after;
    }
  }
}

std::vector<SensoryEvent> uniqueByIndex(std::vector<SensoryEvent> events) {
  std::stable_sort(events.begin(), events.end(),
                   [](const SensoryEvent& a, const SensoryEvent& b) { return a.index < b.index; });
  std::vector<SensoryEvent> unique;
  for (const SensoryEvent& e : events) {
    if (!unique.empty() && unique.back().index == e.index) {
      unique.back().rest_edge = unique.back().rest_edge || e.rest_edge;
      if (e.strength > unique.back().strength) unique.back().away_from_rest = e.away_from_rest;
      unique.back().ramp_end = unique.back().ramp_end && e.ramp_end;
      unique.back().strength = std::max(unique.back().strength, e.strength);
    } else {
      unique.push_back(e);
    }
  }
  return unique;
}

}  // namespace

EventPlacement parseEventPlacement(const std::string& name) {
  if (name == "threshold") return EventPlacement::kThreshold;
  if (name == "shift") return EventPlacement::kShift;
  if (name == "fit") return EventPlacement::kFit;
  throw std::invalid_argument("unknown event placement '" + name + "' (threshold, shift, fit)");
}

std::string toString(EventPlacement placement) {
  switch (placement) {
    case EventPlacement::kThreshold:
      return "threshold";
    case EventPlacement::kShift:
      return "shift";
    case EventPlacement::kFit:
      return "fit";
  }
  return "?";
}

std::vector<SensoryEvent> detectSensoryEventDetails(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                                    const SensoryEventConfig& config) {
  checkConfig(config);
  std::vector<SensoryEvent> events;
  for (const PlacedEvent& p : analyseChannel(signal, config).events) events.push_back(p.event);
  return uniqueByIndex(events);
}

std::vector<std::size_t> detectSensoryEvents(const Eigen::Ref<const Eigen::VectorXd>& signal,
                                             const SensoryEventConfig& config) {
  std::vector<std::size_t> out;
  for (const SensoryEvent& e : detectSensoryEventDetails(signal, config)) out.push_back(e.index);
  return out;
}

std::vector<Interval> confidenceZones(const std::vector<std::size_t>& events, std::size_t min_s,
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

ChangepointValidation validateWithZones(const std::vector<std::size_t>& candidates,
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

SensorEvents detectSensorEvents(const Eigen::MatrixXd& sensors, const SensoryEventConfig& config,
                                const std::vector<std::size_t>& groups) {
  checkConfig(config);
  const std::size_t cols = static_cast<std::size_t>(sensors.cols());
  if (!groups.empty() && groups.size() != cols)
    throw std::invalid_argument("sensory events: " + std::to_string(groups.size()) +
                                " group ids for " + std::to_string(cols) + " sensor columns");
  std::vector<Channel> channels;
  for (std::size_t c = 0; c < cols; ++c) {
    // Only a bad value is named by its column here; any other error propagates as it is (a
    // failure inside the detector was reported as NaN/Inf).
    if (!sensors.col(static_cast<Eigen::Index>(c)).allFinite())
      throw std::invalid_argument("sensory events: sensor column " + std::to_string(c) +
                                  " has NaN/Inf values");
    channels.push_back(analyseChannel(sensors.col(static_cast<Eigen::Index>(c)), config));
  }
  std::map<std::size_t, std::vector<std::size_t>> members;  // group id -> its columns
  for (std::size_t c = 0; c < cols; ++c) members[groups.empty() ? c : groups[c]].push_back(c);
  SensorEvents out;
  for (const auto& [id, group] : members) {
    flagRestEdgesOfGroup(&channels, group, config.difference_lag, config.merge_gap);
    // zone_events: a sensor's rest edges, or all its events when it never leaves rest cleanly.
    bool any_rest_edge = false;
    for (std::size_t c : group)
      for (const PlacedEvent& p : channels[c].events)
        any_rest_edge = any_rest_edge || p.event.rest_edge;
    for (std::size_t c : group)
      for (const PlacedEvent& p : channels[c].events)
        if (p.event.rest_edge || !any_rest_edge) out.zone_events.push_back(p.event.index);
  }
  std::sort(out.zone_events.begin(), out.zone_events.end());
  out.zone_events.erase(std::unique(out.zone_events.begin(), out.zone_events.end()),
                        out.zone_events.end());
  for (const Channel& c : channels) {
    out.per_sensor.emplace_back();
    for (const PlacedEvent& p : c.events) {
      out.per_sensor.back().push_back(p.event.index);
      out.details.push_back(p.event);
    }
    out.all.insert(out.all.end(), out.per_sensor.back().begin(), out.per_sensor.back().end());
  }
  std::sort(out.all.begin(), out.all.end());
  out.all.erase(std::unique(out.all.begin(), out.all.end()), out.all.end());
  out.details = uniqueByIndex(out.details);
  return out;
}

ChangepointValidation validateChangepoints(const std::vector<std::size_t>& candidates,
                                           const Eigen::MatrixXd& sensors, std::size_t min_s,
                                           const SensoryEventConfig& config) {
  SensorEvents events = detectSensorEvents(sensors, config);
  ChangepointValidation out = validateWithZones(
      candidates, confidenceZones(events.all, min_s, static_cast<std::size_t>(sensors.rows())));
  out.events = std::move(events.all);
  out.events_per_sensor = std::move(events.per_sensor);
  return out;
}

}  // namespace lfd
