#include "lfd_core/segmentation/joint_segmentation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "lfd_core/segmentation/contact_sensors.hpp"
#include "lfd_core/segmentation/demo_alignment.hpp"
#include "lfd_core/segmentation/joint_agreement.hpp"
#include "lfd_core/segmentation/motion_match.hpp"
#include "lfd_core/segmentation/periodic_phases.hpp"
#include "lfd_core/segmentation/stale_readings.hpp"
#include "lfd_core/segmentation/state_features.hpp"
#include "lfd_core/util/parallel_for.hpp"

namespace lfd {

namespace {

std::string describe(const std::string& what, std::size_t d) {
  return "demonstration " + std::to_string(d) + ": " + what;
}

// Each feature over its own range in this demo (at least half its range over the task, so that
// a feature this demo barely moves is not blown up to noise): demos toward other goals move to
// other places, and the alignment should follow the shape of the motion, as II-B's DTW does.
Eigen::MatrixXd ownShape(const Eigen::MatrixXd& scaled) {
  Eigen::MatrixXd out = scaled;
  for (Eigen::Index c = 0; c < out.cols(); ++c) {
    const double lo = out.col(c).minCoeff(), range = out.col(c).maxCoeff() - lo;
    out.col(c) = (out.col(c).array() - lo) / std::max(range, 0.5);
  }
  return out;
}

// The speed as one more feature for the alignment, in units of the demo's typical speed and
// weighing as much as all the state features together: they stand still through a pause, and
// only the speed says where motion resumes; a phase is a motion between pauses more than a
// place.
Eigen::MatrixXd withSpeed(const Eigen::MatrixXd& states, const Eigen::VectorXd& speed) {
  Eigen::MatrixXd out(states.rows(), states.cols() + 1);
  out.leftCols(states.cols()) = states;
  const double typical = typicalSpeed(speed);
  const double weight = std::sqrt(static_cast<double>(std::max<Eigen::Index>(1, states.cols())));
  out.col(states.cols()) = typical > 0 ? Eigen::VectorXd(weight * (speed / typical).cwiseMin(1.5))
                                       : Eigen::VectorXd::Zero(speed.size());
  return out;
}

std::size_t sampleAt(const FeatureMatrix& demo, double grid_row, double step) {
  const double t = demo.timeAt(0) + grid_row * step;
  std::size_t i = 0;
  while (i + 1 < static_cast<std::size_t>(demo.rows()) &&
         demo.timeAt(static_cast<Eigen::Index>(i + 1)) <= t)
    ++i;
  return i;
}

// Each state feature weighed by how consistently the demos move it (II-B's mean correlation
// after DTW, clipped to [0, 1]): a wrist that turns a little at random in each demo would
// otherwise hide the pauses from the speed and mislead the alignment. All 1 without II-B (one
// demo).
Eigen::VectorXd consistencyWeights(const SegmentationPipelineResult& result,
                                   const std::vector<std::string>& states) {
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(states.size()));
  if (!result.relevance_computed) return weights;
  for (std::size_t c = 0; c < states.size(); ++c)
    for (const FeatureRelevance& f : result.relevance.features)
      if (f.name == states[c])
        weights[static_cast<Eigen::Index>(c)] = std::clamp(f.mean_correlation, 0.0, 1.0);
  return weights;
}

PeriodicPhaseConfig periodicConfig(const JointSegmentationConfig& joint) {
  PeriodicPhaseConfig out;
  out.smoothing = joint.pauses.smoothing;
  out.min_range_sigmas = joint.rhythm_min_range_sigmas;
  return out;
}

// A demo's evidence of every kind, its features and speed on the alignment grid, and which of
// the grid's columns it can fill.
void gatherEvidence(const FeatureMatrix& demo, const Eigen::MatrixXd& scaled,
                    const Eigen::VectorXd& consistency, const Eigen::VectorXd& speed,
                    const std::vector<Pause>& pauses, const Eigen::MatrixXd& scaled_sensors,
                    const SegmentationPipelineResult& base, const SensorSelection& contact,
                    const std::vector<SampleSpan>& stale,
                    const std::vector<ReciprocatingRun>& rhythm,
                    const SegmentationPipelineConfig& config, DemoSegmentationResult* out,
                    DemoPieces* evidence, Eigen::MatrixXd* grid, std::vector<bool>* usable) {
  const JointSegmentationConfig& joint = config.joint;
  const double rate = sampleRateOf(demo);
  SegmentationPipelineConfig own = inSamples(config, rate);
  if (joint.event_merge_gap > 0)
    own.events.merge_gap = static_cast<std::size_t>(std::lround(joint.event_merge_gap * rate));
  out->num_samples = static_cast<std::size_t>(demo.rows());
  out->sample_rate = rate;
  out->clasp = segmentMultivariate(demo.select(base.selected_features).data, base.feature_weights,
                                   own.segmentation);
  out->min_segment_length = out->clasp.min_segment_length;
  std::vector<BoundaryEvidence>& pieces = evidence->pieces;
  pieces = claspEvidence(out->clasp, joint.weights.clasp);
  if (!contact.names.empty()) {
    SensorEvents events =
        measuredEvents(demo.select(contact.names).data, own.events, contact.groups, stale);
    dropStaleEvents(stale, own.events.difference_lag, &events);
    out->events = events.all;
    out->event_details = events.details;
    // A reversal within colocation of the edge is at the edge's instant (a press overshooting
    // as it lands; teleop push).
    const auto s = sensoryEvidence(events, joint.weights,
                                   static_cast<std::size_t>(std::lround(joint.ramp_fold * rate)),
                                   static_cast<std::size_t>(std::lround(joint.colocation * rate)));
    pieces.insert(pieces.end(), s.begin(), s.end());
  }
  const auto r = rhythmEvidence(rhythm, pieces, joint.weights.rhythm,
                                static_cast<std::size_t>(std::lround(joint.ramp_fold * rate)));
  pieces.insert(pieces.end(), r.begin(), r.end());
  const std::vector<double> clock = demo.clock();
  for (const Pause& p : pauses) out->pauses.push_back({p.begin, p.end - 1});
  const auto m =
      motionOnsetEvidence(speed, clock, pauses, joint.pauses, joint.weights.motion_onset);
  pieces.insert(pieces.end(), m.begin(), m.end());
  const auto stops = motionStopEvidence(speed, clock, joint.pauses, joint.weights.motion_stop);
  pieces.insert(pieces.end(), stops.begin(), stops.end());
  gatherIntoPauses(pauses, out->num_samples,
                   static_cast<std::size_t>(std::lround(joint.colocation * rate)), &pieces);
  for (const BoundaryEvidence& p : pieces)
    evidence->grid_rows.push_back((clock[p.index] - clock.front()) / joint.grid_step);
  evidence->claimed.assign(pieces.size(), false);
  // The sensors align the demos too: contact begins and ends in the same order in each. So does a
  // periodic phase: its strokes, 3 in one demo and 6 in another, leave DTW free to match any
  // stroke with any other, and its edges drift apart.
  Eigen::MatrixXd aligned(scaled.rows(), scaled.cols() + 2 + scaled_sensors.cols());
  // A sensor weighs as much as the state features together, as the speed does: where contact
  // begins and ends is the surest landmark two demos share.
  const double weight = std::sqrt(static_cast<double>(std::max<Eigen::Index>(1, scaled.cols())));
  Eigen::VectorXd periodic = Eigen::VectorXd::Zero(scaled.rows());
  for (const ReciprocatingRun& run : rhythm)
    periodic
        .segment(static_cast<Eigen::Index>(run.begin),
                 static_cast<Eigen::Index>(run.end - run.begin + 1))
        .setOnes();
  aligned << withSpeed(ownShape(scaled) * consistency.asDiagonal(), speed), weight * periodic,
      weight * scaled_sensors;
  *grid = onUniformGrid(aligned, clock, joint.grid_step);
  // The columns this demo can fill: the periodic one where it has a periodic phase (one found in
  // one demo and missed in another is squeezed onto a few of the other's rows), the sensors'
  // where they measured throughout (a dead sensor's constant or a stale one's cached reading
  // reads as rest while the other demo is in contact; stale F/T: touches expected 0.4-2 s from
  // where they were).
  usable->assign(static_cast<std::size_t>(aligned.cols()), true);
  const auto periodic_column = static_cast<std::size_t>(scaled.cols() + 1);
  (*usable)[periodic_column] = !rhythm.empty();
  for (std::size_t c = periodic_column + 1; c < usable->size(); ++c) (*usable)[c] = stale.empty();
}

// "contact+clasp": the kinds of the demo's pieces at the chosen piece's place.
std::string evidenceKinds(const DemoPieces& e, std::size_t chosen, double colocation_rows) {
  std::vector<std::string> kinds;
  for (std::size_t p = 0; p < e.pieces.size(); ++p) {
    if (std::abs(e.grid_rows[p] - e.grid_rows[chosen]) > colocation_rows) continue;
    const std::string k = toString(e.pieces[p].kind);
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
  }
  std::string out;
  for (const std::string& k : kinds) out += (out.empty() ? "" : "+") + k;
  return out;
}

// `spans` of `demo`, widened by `margin` s on either side, in rows of a grid of `step` s from its
// first sample.
std::vector<std::pair<double, double>> gridSpans(const FeatureMatrix& demo,
                                                 const std::vector<SampleSpan>& spans,
                                                 double margin, double step) {
  std::vector<std::pair<double, double>> out;
  const auto row = [&](std::size_t i) {
    return (demo.timeAt(static_cast<Eigen::Index>(i)) - demo.timeAt(0)) / step;
  };
  for (const SampleSpan& s : spans)
    out.emplace_back(row(s.begin) - margin / step, row(s.end - 1) + margin / step);
  return out;
}

std::string secondsAfterStart(const FeatureMatrix& demo, std::size_t index) {
  std::ostringstream out;
  out.precision(3);
  out << demo.timeAt(static_cast<Eigen::Index>(index)) - demo.timeAt(0) << " s";
  return out.str();
}

// Each demo's motion for placeByMotion on a grid of `step` s: the state features II-B selected
// (those the demos move alike), each over its range in the task; every moving one without II-B
// (one demo) or when it selected sensors only. A wrist that turns a little at random in each demo
// makes every instant of a wipe look like every other (stale F/T: a touch matched 3 s late).
std::vector<Eigen::MatrixXd> motionGrids(const std::vector<FeatureMatrix>& demos,
                                         const std::vector<std::string>& moving,
                                         const std::vector<std::string>& selected, double step) {
  std::vector<std::string> names = selectedStates(moving, selected);
  if (names.empty()) names = moving;
  if (names.empty()) return {};  // no state feature moves: nothing to match
  const std::vector<Eigen::MatrixXd> scaled = scaledStates(demos, names);
  std::vector<Eigen::MatrixXd> out;
  for (std::size_t d = 0; d < demos.size(); ++d)
    out.push_back(onUniformGrid(scaled[d], demos[d].clock(), step));
  return out;
}

// Per demo and agreed boundary, the sample placed by the motion around it in the demos that felt
// it (motion_match.hpp), where that lands while the demo's contact sensor was blind; -1
// elsewhere. `motion`: each demo's state features on a grid of config.motion_match_step. The
// search spans the demo between its neighbouring boundaries, not the match window around where
// the alignment expects it: a blind sensor leaves the alignment itself 0.5-2 s off.
std::vector<std::vector<long>> placeByMotion(const JointAgreement& agreement,
                                             const std::vector<FeatureMatrix>& demos,
                                             const std::vector<Eigen::MatrixXd>& motion,
                                             const JointSegmentationConfig& config) {
  const auto& anchors = agreement.anchors();
  std::vector<std::vector<long>> out(demos.size(), std::vector<long>(anchors.size(), -1));
  if (motion.empty()) return out;
  const double step = config.motion_match_step;
  const auto half =
      static_cast<std::size_t>(std::max(1L, std::lround(config.motion_match_window / step)));
  const auto motion_row = [&](std::size_t d, std::size_t sample) {
    const double t = demos[d].timeAt(static_cast<Eigen::Index>(sample)) - demos[d].timeAt(0);
    return std::clamp(std::lround(t / step), 0L, static_cast<long>(motion[d].rows()) - 1);
  };
  const auto placed = [&](std::size_t d, std::size_t k) {
    const auto p = static_cast<std::size_t>(anchors[k].piece[d]);
    return motion_row(d, agreement.evidence(d).pieces[p].index);
  };
  for (std::size_t k = 0; k < anchors.size(); ++k) {
    std::vector<std::optional<MotionAround>> around(demos.size());  // the demos that felt it
    for (std::size_t s = 0; s < demos.size(); ++s)
      if (agreement.felt(s, k))
        around[s] = motionAround(motion[s], static_cast<std::size_t>(placed(s, k)), half);
    for (std::size_t d = 0; d < demos.size(); ++d) {
      if (!agreement.everBlind(d)) continue;
      std::vector<MotionAround> felt;  // never the demo itself: it would match its own piece
      for (std::size_t s = 0; s < demos.size(); ++s)
        if (s != d && around[s]) felt.push_back(*around[s]);
      if (felt.empty()) continue;
      // Between the boundaries the demo felt, and after the one placed before. A boundary it
      // felt is matched too: a level step after the sensor woke up may stand for a touch it
      // missed.
      long first = 0, last = static_cast<long>(motion[d].rows()) - 1;
      for (std::size_t j = 0; j < anchors.size(); ++j) {
        long row = -1;
        if (j < k && out[d][j] >= 0) row = motion_row(d, static_cast<std::size_t>(out[d][j]));
        if (j != k && agreement.felt(d, j)) row = placed(d, j);
        if (row < 0) continue;
        if (j < k) first = std::max(first, row + 1);
        if (j > k) last = std::min(last, row - 1);
      }
      if (first > last) continue;
      const std::size_t row = bestMatchingRow(motion[d], felt, static_cast<std::size_t>(first),
                                              static_cast<std::size_t>(last), half);
      // Only where the sensor was blind: elsewhere the demo's own evidence holds.
      if (agreement.blindAt(d, static_cast<double>(row) * step / config.grid_step))
        out[d][k] = static_cast<long>(sampleAt(demos[d], static_cast<double>(row), step));
    }
  }
  return out;
}

// The demo's changepoints, zones (the match windows), and what it lacks or has in excess.
// `by_motion`: per agreed boundary, the sample placeByMotion gave it in this demo (-1: none).
void reportDemo(const JointAgreement& agreement, const FeatureMatrix& demo, std::size_t d,
                const std::vector<long>& by_motion, const JointSegmentationConfig& config,
                DemoSegmentationResult* out, std::vector<std::string>* warnings) {
  const DemoPieces& e = agreement.evidence(d);
  const std::size_t half = static_cast<std::size_t>(config.match_window * out->sample_rate);
  const auto& anchors = agreement.anchors();
  for (std::size_t k = 0; k < anchors.size(); ++k) {
    const std::size_t expected =
        sampleAt(demo, agreement.expectedRow(d, anchors[k].reference_row), config.grid_step);
    out->zones.push_back(
        {expected > half ? expected - half : 0, std::min(expected + half, out->num_samples - 1)});
    const long p = anchors[k].piece[d];
    if (by_motion[k] >= 0) {
      warnings->push_back(describe(
          "boundary " + std::to_string(k + 1) + " of " + std::to_string(anchors.size()) +
              " placed by the motion around it in the other demonstrations: the contact sensor "
              "did not measure there",
          d));
      out->changepoints.push_back(static_cast<std::size_t>(by_motion[k]));
      out->changepoint_evidence.push_back("motion_match");
      continue;
    }
    if (p < 0) {
      warnings->push_back(describe(
          "no evidence of boundary " + std::to_string(k + 1) + " of " +
              std::to_string(anchors.size()) + " (the others agree on it near " +
              secondsAfterStart(demo, expected) + "): this demonstration may lack that phase",
          d));
      continue;
    }
    out->changepoints.push_back(e.pieces[static_cast<std::size_t>(p)].index);
    out->changepoint_evidence.push_back(
        evidenceKinds(e, static_cast<std::size_t>(p), agreement.colocationRows()));
  }
  std::vector<std::string> extra;
  for (std::size_t p = 0; p < e.pieces.size(); ++p) {
    if (e.claimed[p]) continue;
    out->rejected.push_back(e.pieces[p].index);
    if (e.pieces[p].weight >= config.extra_event_weight)
      extra.push_back(toString(e.pieces[p].kind) + " at " +
                      secondsAfterStart(demo, e.pieces[p].index));
  }
  if (!extra.empty()) {
    std::string list;
    for (const std::string& x : extra) list += (list.empty() ? "" : ", ") + x;
    warnings->push_back(
        describe("strong evidence the other demonstrations do not share (an extra "
                 "phase?): " +
                     list,
                 d));
  }
  std::sort(out->rejected.begin(), out->rejected.end());
  out->rejected.erase(std::unique(out->rejected.begin(), out->rejected.end()), out->rejected.end());
  for (std::size_t cp : out->changepoints)
    out->changepoint_times.push_back(demo.timeAt(static_cast<Eigen::Index>(cp)));
  for (std::size_t cp : out->rejected)
    out->rejected_times.push_back(demo.timeAt(static_cast<Eigen::Index>(cp)));
}

}  // namespace

SegmentationPipelineResult segmentJointly(const PreparedSegmentation& prepared,
                                          const std::vector<FeatureMatrix>& demos,
                                          const SegmentationPipelineConfig& config) {
  if (!config.seconds)
    throw std::invalid_argument(
        "the joint segmentation needs its time parameters in seconds (demos with a clock)");
  const auto start = std::chrono::steady_clock::now();
  SegmentationPipelineResult result = prepared.base;
  const std::size_t n = demos.size();
  result.demos.resize(n);
  const std::vector<std::string> states = movingStates(demos, result.state_features);
  const std::vector<Eigen::MatrixXd> scaled = scaledStates(demos, states);
  const Eigen::VectorXd consistency = consistencyWeights(result, states);
  const std::vector<std::size_t> groups = sensorChannelGroups(result.sensor_features);
  const bool sensors = !result.sensor_features.empty() && config.validate_with_sensors;
  const std::vector<Eigen::MatrixXd> scaled_sensors =
      sensorMagnitudes(demos, sensors ? result.sensor_features : std::vector<std::string>{},
                       sensors ? groups : std::vector<std::size_t>{});

  std::vector<Eigen::VectorXd> speeds(n);
  std::vector<std::vector<Pause>> pauses(n);
  parallelFor(n, config.threads, [&](std::size_t d) {
    speeds[d] = stateSpeed(scaled[d] * consistency.asDiagonal(), demos[d].clock(),
                           config.joint.pauses.smoothing);
    pauses[d] = findPauses(speeds[d], demos[d].clock(), config.joint.pauses);
  });
  const SensorSelection contact =
      sensors ? contactSensors(result.sensor_features, groups, scaled_sensors, speeds,
                               config.joint.max_speed_correlation, &result.warnings)
              : SensorSelection{};

  const std::vector<std::vector<SampleSpan>> stale =
      staleContactReadings(demos, contact, config.joint.stale_reading, &result.warnings);
  const std::vector<std::vector<ReciprocatingRun>> rhythm =
      periodicPhases(demos, states, result.selected_features, pauses, !contact.names.empty(),
                     periodicConfig(config.joint), config.threads);

  std::vector<DemoPieces> evidence(n);
  AlignmentGrids grids;
  grids.full.resize(n);
  grids.usable.resize(n);
  parallelFor(n, config.threads, [&](std::size_t d) {
    try {
      gatherEvidence(demos[d], scaled[d], consistency, speeds[d], pauses[d], scaled_sensors[d],
                     result, contact, stale[d], rhythm[d], config, &result.demos[d], &evidence[d],
                     &grids.full[d], &grids.usable[d]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(describe(e.what(), d));
    }
  });
  for (std::size_t d = 0; d < n; ++d) {
    grids.blind.push_back(gridSpans(demos[d], stale[d], config.seconds->event_difference_lag,
                                    config.joint.grid_step));
  }
  const JointAgreement agreement = bestAgreement(evidence, grids, config);
  std::vector<Eigen::MatrixXd> motion;
  if (std::any_of(stale.begin(), stale.end(), [](const auto& s) { return !s.empty(); }))
    motion = motionGrids(demos, states, result.selected_features, config.joint.motion_match_step);
  const auto by_motion = placeByMotion(agreement, demos, motion, config.joint);
  for (std::size_t d = 0; d < n; ++d)
    reportDemo(agreement, demos[d], d, by_motion[d], config.joint, &result.demos[d],
               &result.warnings);
  addSensorWarnings(demos, sensors, &result);
  result.segmentation_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace lfd
