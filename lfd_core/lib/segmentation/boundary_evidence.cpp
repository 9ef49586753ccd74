#include "lfd_core/segmentation/boundary_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "lfd_core/segmentation/smooth_derivatives.hpp"

namespace lfd {

namespace {

// Samples in motion: above the rest threshold, in a bout whose peak reaches the small-motion
// level.
std::vector<bool> movingSamples(const Eigen::VectorXd& speed, double rest, double small) {
  const std::size_t n = static_cast<std::size_t>(speed.size());
  std::vector<bool> moving(n, false);
  for (std::size_t i = 0; i < n;) {
    if (speed[static_cast<Eigen::Index>(i)] < rest) {
      ++i;
      continue;
    }
    std::size_t j = i;
    double peak = 0.0;
    for (; j < n && speed[static_cast<Eigen::Index>(j)] >= rest; ++j)
      peak = std::max(peak, speed[static_cast<Eigen::Index>(j)]);
    if (peak >= small)
      std::fill(moving.begin() + static_cast<long>(i), moving.begin() + static_cast<long>(j), true);
    i = j;
  }
  return moving;
}

// Peak speed in [from, time[from] + window).
double peakSpeedAfter(const Eigen::VectorXd& speed, const std::vector<double>& time,
                      std::size_t from, double window) {
  double peak = 0.0;
  for (std::size_t i = from; i < time.size() && time[i] < time[from] + window; ++i)
    peak = std::max(peak, speed[static_cast<Eigen::Index>(i)]);
  return peak;
}

// Every rest run [begin, end) of the speed, the demo's first and last included.
std::vector<Pause> restRuns(const Eigen::VectorXd& speed, const std::vector<double>& time,
                            const PauseConfig& config) {
  std::vector<Pause> runs;
  const double typical = typicalSpeed(speed);
  if (!(typical > 0) || time.size() != static_cast<std::size_t>(speed.size())) return runs;
  const std::vector<bool> moving =
      movingSamples(speed, config.rest_fraction * typical, config.small_motion_fraction * typical);
  for (std::size_t i = 0; i < moving.size();) {
    std::size_t j = i;
    while (j < moving.size() && !moving[j]) ++j;
    if (j > i) runs.push_back({i, j});
    i = std::max(j, i + 1);
  }
  return runs;
}

double duration(const Pause& run, const std::vector<double>& time) {
  return (run.end < time.size() ? time[run.end] : time.back()) - time[run.begin];
}

bool atAnEnd(const Pause& run, std::size_t samples) {
  return run.begin == 0 || run.end >= samples;
}

}  // namespace

std::string toString(EvidenceKind kind) {
  switch (kind) {
    case EvidenceKind::kContact:
      return "contact";
    case EvidenceKind::kSensorLevel:
      return "sensor_level";
    case EvidenceKind::kMotionOnset:
      return "motion_onset";
    case EvidenceKind::kMotionStop:
      return "motion_stop";
    case EvidenceKind::kClasp:
      return "clasp";
    case EvidenceKind::kRhythm:
      return "rhythm";
  }
  return "clasp";
}

double typicalSpeed(const Eigen::VectorXd& speed) {
  if (speed.size() == 0) return 0.0;
  std::vector<double> v(speed.data(), speed.data() + speed.size());
  const std::size_t k = (v.size() - 1) * 95 / 100;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

Eigen::MatrixXd stateVelocities(const Eigen::MatrixXd& scaled_states,
                                const std::vector<double>& time, double smoothing_seconds) {
  const Eigen::Index n = scaled_states.rows();
  if (static_cast<std::size_t>(n) != time.size())
    throw std::invalid_argument("stateSpeed: " + std::to_string(n) + " samples but " +
                                std::to_string(time.size()) + " timestamps");
  Eigen::MatrixXd velocity = Eigen::MatrixXd::Zero(n, scaled_states.cols());
  if (n < 3 || scaled_states.cols() == 0) return velocity;
  const Eigen::VectorXd t = Eigen::Map<const Eigen::VectorXd>(time.data(), n);
  const Eigen::MatrixXd smooth = gaussianSmooth(t, scaled_states, smoothing_seconds);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index a = std::max<Eigen::Index>(0, i - 1), b = std::min(n - 1, i + 1);
    velocity.row(i) = (smooth.row(b) - smooth.row(a)) / (t[b] - t[a]);
  }
  return velocity;
}

Eigen::VectorXd stateSpeed(const Eigen::MatrixXd& scaled_states, const std::vector<double>& time,
                           double smoothing_seconds) {
  return stateVelocities(scaled_states, time, smoothing_seconds).rowwise().norm();
}

std::vector<Pause> findPauses(const Eigen::VectorXd& speed, const std::vector<double>& time,
                              const PauseConfig& config) {
  std::vector<Pause> pauses;
  for (const Pause& run : restRuns(speed, time, config))
    if (duration(run, time) >= config.min_pause || atAnEnd(run, time.size())) pauses.push_back(run);
  return pauses;
}

std::vector<BoundaryEvidence> motionStopEvidence(const Eigen::VectorXd& speed,
                                                 const std::vector<double>& time,
                                                 const PauseConfig& config, double weight) {
  std::vector<BoundaryEvidence> out;
  for (const Pause& run : restRuns(speed, time, config)) {
    if (duration(run, time) >= config.min_pause || atAnEnd(run, time.size())) continue;
    Eigen::Index slowest = 0;
    speed
        .segment(static_cast<Eigen::Index>(run.begin),
                 static_cast<Eigen::Index>(run.end - run.begin))
        .minCoeff(&slowest);
    out.push_back(
        {run.begin + static_cast<std::size_t>(slowest), weight, EvidenceKind::kMotionStop});
  }
  return out;
}

std::vector<BoundaryEvidence> motionOnsetEvidence(const Eigen::VectorXd& speed,
                                                  const std::vector<double>& time,
                                                  const std::vector<Pause>& pauses,
                                                  const PauseConfig& config, double weight) {
  std::vector<BoundaryEvidence> out;
  const double typical = typicalSpeed(speed);
  if (!(typical > 0)) return out;
  for (const Pause& p : pauses) {
    // The demo starts and ends at rest: neither is a boundary between skills.
    if (p.begin == 0 || p.end >= time.size()) continue;
    const double pause = time[p.end] - time[p.begin];
    const double motion = std::min(1.0, peakSpeedAfter(speed, time, p.end, config.motion_window) /
                                            (config.full_motion_fraction * typical));
    out.push_back({p.end, weight * (1.0 - std::exp(-pause / config.pause_scale)) * motion,
                   EvidenceKind::kMotionOnset});
  }
  return out;
}

void gatherIntoPauses(const std::vector<Pause>& pauses, std::size_t samples,
                      std::size_t start_samples, std::vector<BoundaryEvidence>* evidence) {
  for (const Pause& p : pauses) {
    if (p.begin == 0 || p.end >= samples) continue;
    for (BoundaryEvidence& e : *evidence)
      if (e.index > p.begin + start_samples && e.index <= p.end) e.index = p.end;
  }
}

namespace {

// The contact edge nearest to `index` within `fold_samples` of it (`index` when there is none):
// a change that close to a contact made or lost is that contact's own.
std::size_t foldOntoContact(const std::vector<std::size_t>& edges, std::size_t index,
                            std::size_t fold_samples) {
  std::size_t at = index, nearest = fold_samples + 1;
  for (std::size_t edge : edges) {
    const std::size_t distance = edge > index ? edge - index : index - edge;
    if (distance <= fold_samples && distance < nearest) {
      nearest = distance;
      at = edge;
    }
  }
  return at;
}

}  // namespace

std::vector<BoundaryEvidence> sensoryEvidence(const SensorEvents& events,
                                              const EvidenceWeights& weights,
                                              std::size_t fold_samples,
                                              std::size_t reversal_fold_samples) {
  std::vector<std::size_t> edges_away, edges_back;
  for (const SensoryEvent& e : events.details)
    if (e.rest_edge) (e.away_from_rest ? edges_away : edges_back).push_back(e.index);
  std::vector<BoundaryEvidence> out;
  for (const SensoryEvent& e : events.details) {
    if (e.rest_edge) {
      out.push_back({e.index, weights.contact, EvidenceKind::kContact});
      continue;
    }
    const auto& same = e.away_from_rest ? edges_away : edges_back;
    const auto& other = e.away_from_rest ? edges_back : edges_away;
    std::size_t at = foldOntoContact(same, e.index, fold_samples);
    if (at == e.index) at = foldOntoContact(other, e.index, reversal_fold_samples);
    // The two ends of one ramp are one change: together (noisy-OR) as sure as one step.
    const double weight = e.ramp_end && at == e.index ? 1.0 - std::sqrt(1.0 - weights.sensor_level)
                                                      : weights.sensor_level;
    out.push_back({at, weight, EvidenceKind::kSensorLevel});
  }
  return out;
}

std::vector<BoundaryEvidence> rhythmEvidence(const std::vector<ReciprocatingRun>& runs,
                                             const std::vector<BoundaryEvidence>& contacts,
                                             double weight, std::size_t fold_samples) {
  std::vector<std::size_t> edges;
  for (const BoundaryEvidence& c : contacts)
    if (c.kind == EvidenceKind::kContact) edges.push_back(c.index);
  std::vector<BoundaryEvidence> out;
  for (const ReciprocatingRun& run : runs) {
    out.push_back({foldOntoContact(edges, run.begin, fold_samples), weight, EvidenceKind::kRhythm});
    out.push_back({foldOntoContact(edges, run.end, fold_samples), weight, EvidenceKind::kRhythm});
  }
  return out;
}

std::vector<BoundaryEvidence> claspEvidence(const MultivariateSegmentation& clasp, double weight) {
  std::vector<BoundaryEvidence> out;
  for (std::size_t cp : clasp.changepoints) out.push_back({cp, weight, EvidenceKind::kClasp});
  return out;
}

}  // namespace lfd
