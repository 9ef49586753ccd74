#include "lfd_core/segmentation/joint_segmentation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "lfd_core/segmentation/contact_sensors.hpp"
#include "lfd_core/segmentation/demo_alignment.hpp"
#include "lfd_core/segmentation/motion_match.hpp"
#include "lfd_core/segmentation/periodic_phases.hpp"
#include "lfd_core/segmentation/stale_readings.hpp"
#include "lfd_core/segmentation/state_features.hpp"
#include "lfd_core/util/parallel_for.hpp"

namespace lfd {

namespace {

// One demo's evidence: its pieces, where each falls on the reference's grid, whether an agreed
// boundary has claimed it, and the demo's own rows on its grid.
struct DemoEvidence {
  std::vector<BoundaryEvidence> pieces;
  std::vector<double> reference_rows;
  std::vector<bool> claimed;
  std::vector<double> grid_rows;  ///< per piece, on the demo's own grid
};

// One agreed boundary: where on the reference, how well supported, and per demo the piece that
// places it (-1: the demo shows no evidence of it) and the demo's grid row that anchors the
// alignment (the piece's, else where the alignment expects it).
struct Anchor {
  double reference_row = 0.0;
  double support = 0.0;
  std::vector<long> piece;
  std::vector<std::size_t> demo_row;
};

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
  out.pauses = joint.pauses;
  out.min_range_sigmas = joint.rhythm_min_range_sigmas;
  return out;
}

// A demo's evidence of every kind, its features and speed on the alignment grid, and which of
// the grid's columns it can fill.
void gatherEvidence(const FeatureMatrix& demo, const Eigen::MatrixXd& scaled,
                    const Eigen::VectorXd& consistency, const Eigen::VectorXd& speed,
                    const Eigen::MatrixXd& scaled_sensors, const SegmentationPipelineResult& base,
                    const SensorSelection& contact, const std::vector<SampleSpan>& stale,
                    const std::vector<ReciprocatingRun>& rhythm,
                    const SegmentationPipelineConfig& config, DemoSegmentationResult* out,
                    DemoEvidence* evidence, Eigen::MatrixXd* grid, std::vector<bool>* usable) {
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
  const std::vector<Pause> pauses = findPauses(speed, clock, joint.pauses);
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

// Noisy-OR of a demo's unclaimed evidence around each reference row: how sure this demo is that
// a boundary lies there.
Eigen::VectorXd demoSupport(const DemoEvidence& e, Eigen::Index rows, double spread_rows) {
  Eigen::VectorXd none = Eigen::VectorXd::Ones(rows);
  const Eigen::Index reach = static_cast<Eigen::Index>(std::ceil(4 * spread_rows));
  for (std::size_t p = 0; p < e.pieces.size(); ++p) {
    if (e.claimed[p]) continue;
    const double u = e.reference_rows[p];
    const Eigen::Index lo = std::max<Eigen::Index>(0, static_cast<Eigen::Index>(u) - reach);
    const Eigen::Index hi = std::min<Eigen::Index>(rows - 1, static_cast<Eigen::Index>(u) + reach);
    for (Eigen::Index r = lo; r <= hi; ++r) {
      const double z = (static_cast<double>(r) - u) / spread_rows;
      none[r] *= 1.0 - e.pieces[p].weight * std::exp(-0.5 * z * z);
    }
  }
  return Eigen::VectorXd::Ones(rows) - none;
}

// The support a boundary needs at `distance` rows from its nearest anchor: min_support beyond
// min_segment, rising linearly to short_phase_support as it comes closer (a prior on the
// length of a phase, not a wall).
double neededSupport(double distance, const JointSegmentationConfig& config,
                     double min_segment_rows) {
  if (distance >= min_segment_rows) return config.min_support;
  return config.min_support +
         (config.short_phase_support - config.min_support) * (1.0 - distance / min_segment_rows);
}

// The best supported peak that may join the anchors (it reaches the support its distance to
// them needs); -1 when none.
double nextBoundary(const Eigen::VectorXd& support, const std::vector<Anchor>& anchors,
                    const JointSegmentationConfig& config, double min_segment_rows) {
  double best_row = -1.0, best = 0.0;
  for (Eigen::Index r = 1; r + 1 < support.size(); ++r) {
    const double s = support[r];
    if (s < support[r - 1] || s <= support[r + 1] || s <= best) continue;
    double distance = min_segment_rows;
    for (const Anchor& a : anchors)
      distance = std::min(distance, std::abs(a.reference_row - static_cast<double>(r)));
    if (s < neededSupport(distance, config, min_segment_rows)) continue;
    best = s;
    best_row = static_cast<double>(r);
  }
  return best_row;
}

// The placement's distances on the grid, and the least support a demo's own evidence needs.
struct PlacementRows {
  double window = 0.0;
  double spread = 0.0;
  double colocation = 0.0;
  double min_weight = 0.0;
};

// How sharply a kind of evidence times a change: a sensor's rest edge to a sample, a pause's
// end closely, ClaSP only to within its window.
int timingPrecision(EvidenceKind kind) {
  switch (kind) {
    case EvidenceKind::kContact:
      return 4;
    case EvidenceKind::kSensorLevel:
      return 3;
    case EvidenceKind::kMotionOnset:
      return 2;
    case EvidenceKind::kMotionStop:
    case EvidenceKind::kRhythm:
      return 1;
    case EvidenceKind::kClasp:
      return 0;
  }
  return 0;
}

// The demo's piece for a boundary expected at reference row u: the unclaimed piece within the
// match window and strictly between the demo's neighbouring anchors that scores best, its score
// being the noisy-OR of the unclaimed pieces at its place (a contact and a ClaSP changepoint at
// one instant reinforce each other) times its closeness to u. -1 when there is none.
// Noisy-OR of the unclaimed pieces of a demo within colocation_rows of piece p.
double colocatedStrength(const DemoEvidence& e, std::size_t p, double colocation_rows) {
  double none = 1.0;
  for (std::size_t q = 0; q < e.pieces.size(); ++q)
    if (!e.claimed[q] && std::abs(e.grid_rows[q] - e.grid_rows[p]) <= colocation_rows)
      none *= 1.0 - e.pieces[q].weight;
  return 1.0 - none;
}

// ClaSP times a change only to within its subsequence window: a chosen ClaSP piece gives way to
// the nearest sensory or kinematic piece of the demo within `spread_rows` of it (a contact, a
// pause's end), which times the same change to a sample.
long sharpen(const DemoEvidence& e, long chosen, double spread_rows, double min_weight,
             double after_row, double before_row) {
  if (chosen < 0 || e.pieces[static_cast<std::size_t>(chosen)].kind != EvidenceKind::kClasp)
    return chosen;
  const double row = e.grid_rows[static_cast<std::size_t>(chosen)];
  long best = chosen;
  double nearest = spread_rows;
  for (std::size_t p = 0; p < e.pieces.size(); ++p) {
    const double distance = std::abs(e.grid_rows[p] - row);
    if (e.claimed[p] || e.pieces[p].kind == EvidenceKind::kClasp ||
        e.pieces[p].weight < min_weight || distance > nearest || e.grid_rows[p] <= after_row ||
        e.grid_rows[p] >= before_row)
      continue;
    nearest = distance;
    best = static_cast<long>(p);
  }
  return best;
}

long bestPiece(const DemoEvidence& e, double u, const PlacementRows& rows, double after_row,
               double before_row) {
  long best = -1;
  double best_score = 0.0;
  for (std::size_t p = 0; p < e.pieces.size(); ++p) {
    const double distance = std::abs(e.reference_rows[p] - u);
    if (e.claimed[p] || distance > rows.window || e.grid_rows[p] <= after_row ||
        e.grid_rows[p] >= before_row)
      continue;
    const double strength = colocatedStrength(e, p, rows.colocation);
    if (strength < rows.min_weight) continue;
    const double none = 1.0 - strength;
    const double z = distance / rows.spread;
    // Among pieces of equal support, the one whose kind times a change best places it.
    const double score =
        (1.0 - none) * std::exp(-0.5 * z * z) + 1e-3 * timingPrecision(e.pieces[p].kind);
    if (score > best_score) {
      best_score = score;
      best = static_cast<long>(p);
    }
  }
  return sharpen(e, best, rows.spread, rows.min_weight, after_row, before_row);
}

// The demo's grid rows of the anchors before and after reference row u (or its ends).
std::pair<double, double> neighbouringRows(const std::vector<Anchor>& anchors, std::size_t d,
                                           double u, double demo_rows) {
  double after = -1.0, before = demo_rows;
  for (const Anchor& a : anchors) {
    if (a.piece[d] < 0) continue;
    const double row = static_cast<double>(a.demo_row[d]);
    if (a.reference_row < u) after = std::max(after, row);
    if (a.reference_row > u) before = std::min(before, row);
  }
  return {after, before};
}

// "contact+clasp": the kinds of the demo's pieces at the chosen piece's place.
std::string evidenceKinds(const DemoEvidence& e, std::size_t chosen, double colocation_rows) {
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

// The demos on the alignment grid, per demo the columns it can fill (gatherEvidence), and where
// its contact sensor was blind (grid rows): where it did not measure (stale_readings.hpp), and a
// lag on either side, where its events are dropped (dropStaleEvents).
struct AlignmentGrids {
  std::vector<Eigen::MatrixXd> full;
  ColumnMasks usable;
  std::vector<std::vector<std::pair<double, double>>> blind;

  bool blindAt(std::size_t d, double row) const {
    return std::any_of(blind[d].begin(), blind[d].end(),
                       [&](const auto& span) { return row >= span.first && row <= span.second; });
  }
};

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

// The agreement, boundary by boundary.
class JointAgreement {
 public:
  JointAgreement(std::vector<DemoEvidence> evidence, const AlignmentGrids& grids,
                 DemoAlignment alignment, const JointSegmentationConfig& config,
                 double min_segment_seconds, int threads)
      : evidence_(std::move(evidence)),
        grids_(grids),
        config_(config),
        min_segment_rows_(min_segment_seconds / config.grid_step),
        spread_rows_(config.spread / config.grid_step),
        agreement_spread_rows_(config.agreement_spread / config.grid_step),
        window_rows_(config.match_window / config.grid_step),
        colocation_rows_(config.colocation / config.grid_step),
        threads_(threads),
        reference_(alignment.reference),
        to_reference_(std::move(alignment.to_reference)),
        from_reference_(std::move(alignment.from_reference)) {}

  // Adds agreed boundaries, best supported first, re-aligning between them after each.
  void run(std::size_t max_boundaries) {
    while (anchors_.size() < max_boundaries) {
      mapEvidence();
      const double u = nextBoundary(support(), anchors_, config_, min_segment_rows_);
      if (u < 0) break;
      if (!addAnchor(u)) break;
      realign();
      mapEvidence();
      retryMissing();
    }
    mapEvidence();
  }

  const std::vector<Anchor>& anchors() const { return anchors_; }
  // The weight of the strong evidence (extra_event_weight: contact made or lost) no agreed
  // boundary claims, over every demo; and how many demos have any.
  double unexplainedEvidence() const {
    double sum = 0.0;
    for (std::size_t d = 0; d < evidence_.size(); ++d) sum += unexplainedEvidenceOf(d);
    return sum;
  }
  std::size_t demosWithUnexplainedEvidence() const {
    std::size_t count = 0;
    for (std::size_t d = 0; d < evidence_.size(); ++d) count += unexplainedEvidenceOf(d) > 0.0;
    return count;
  }
  const DemoEvidence& evidence(std::size_t d) const { return evidence_[d]; }
  double expectedRow(std::size_t d, double reference_row) const {
    return mapRow(from_reference_[d], reference_row);
  }
  double colocationRows() const { return colocation_rows_; }
  // Whether demo d placed boundary k where its contact sensor felt a change.
  bool felt(std::size_t d, std::size_t k) const {
    const long p = anchors_[k].piece[d];
    if (p < 0) return false;
    const DemoEvidence& e = evidence_[d];
    const double row = e.grid_rows[static_cast<std::size_t>(p)];
    if (grids_.blindAt(d, row)) return false;
    for (std::size_t q = 0; q < e.pieces.size(); ++q)
      if (std::abs(e.grid_rows[q] - row) <= colocation_rows_ &&
          (e.pieces[q].kind == EvidenceKind::kContact ||
           e.pieces[q].kind == EvidenceKind::kSensorLevel))
        return true;
    return false;
  }
  bool everBlind(std::size_t d) const { return !grids_.blind[d].empty(); }
  bool blindAt(std::size_t d, double row) const { return grids_.blindAt(d, row); }
  double windowRows() const { return window_rows_; }

 private:
  double unexplainedEvidenceOf(std::size_t d) const {
    const DemoEvidence& e = evidence_[d];
    double sum = 0.0;
    for (std::size_t p = 0; p < e.pieces.size(); ++p)
      if (!e.claimed[p] && e.pieces[p].weight >= config_.extra_event_weight)
        sum += e.pieces[p].weight;
    return sum;
  }

  void mapEvidence() {
    for (DemoEvidence& e : evidence_) e.reference_rows.clear();
    for (std::size_t d = 0; d < evidence_.size(); ++d)
      for (double row : evidence_[d].grid_rows)
        evidence_[d].reference_rows.push_back(mapRow(to_reference_[d], row));
  }

  Eigen::VectorXd support() const {
    const Eigen::Index rows = grids_.full[reference_].rows();
    Eigen::VectorXd s = Eigen::VectorXd::Zero(rows);
    for (const DemoEvidence& e : evidence_)
      s += demoSupport(e, rows, agreement_spread_rows_) / static_cast<double>(evidence_.size());
    // Support above the background: evidence that is everywhere (a contact force varying all
    // along a wipe, in every demo at other times) supports every instant alike and so none.
    const double background = s.mean();
    return background < 1.0
               ? Eigen::VectorXd((s.array() - background).max(0.0) / (1.0 - background))
               : Eigen::VectorXd::Zero(rows);
  }

  // Adds the boundary and places it in every demo; false (and nothing added) when no demo has
  // a piece for it (the support came from pieces the order forbids), so the search stops rather
  // than loop.
  bool addAnchor(double u) {
    Anchor a;
    a.reference_row = u;
    a.piece.assign(evidence_.size(), -1);
    a.demo_row.assign(evidence_.size(), 0);
    const auto at = anchors_.insert(std::upper_bound(anchors_.begin(), anchors_.end(), a,
                                                     [](const Anchor& x, const Anchor& y) {
                                                       return x.reference_row < y.reference_row;
                                                     }),
                                    a);
    bool any = false;
    for (std::size_t d = 0; d < evidence_.size(); ++d) any = place(&*at, d) || any;
    if (!any) anchors_.erase(at);
    return any;
  }

  // Places anchor `a` in demo d on its best piece between the demo's neighbouring anchors.
  bool place(Anchor* a, std::size_t d) {
    const double rows = static_cast<double>(grids_.full[d].rows());
    const auto [after, before] = neighbouringRows(anchors_, d, a->reference_row, rows);
    const long p = bestPiece(
        evidence_[d], a->reference_row,
        {window_rows_, spread_rows_, colocation_rows_, config_.min_piece_weight}, after, before);
    if (p < 0) return false;
    a->piece[d] = p;
    a->demo_row[d] = static_cast<std::size_t>(
        std::clamp(std::lround(evidence_[d].grid_rows[static_cast<std::size_t>(p)]), 0L,
                   static_cast<long>(rows) - 1));
    claim(d, static_cast<std::size_t>(p));
    return true;
  }

  // A demo that had no piece for a boundary may have one once the alignment holds at the other
  // boundaries.
  void retryMissing() {
    for (Anchor& a : anchors_)
      for (std::size_t d = 0; d < evidence_.size(); ++d)
        if (a.piece[d] < 0) place(&a, d);
  }

  // The chosen piece and those at its place belong to this boundary.
  void claim(std::size_t d, std::size_t p) {
    DemoEvidence& e = evidence_[d];
    for (std::size_t q = 0; q < e.pieces.size(); ++q)
      if (std::abs(e.grid_rows[q] - e.grid_rows[p]) <= colocation_rows_) e.claimed[q] = true;
  }

  // The alignment of every demo, held at the boundaries placed in it (a boundary the demo lacks
  // says nothing of where it would be).
  void realign() {
    parallelFor(evidence_.size(), threads_, [&](std::size_t d) {
      if (d == reference_) return;
      std::vector<std::size_t> own, reference_rows;
      for (const Anchor& a : anchors_) {
        if (a.piece[d] < 0) continue;
        own.push_back(a.demo_row[d]);
        reference_rows.push_back(static_cast<std::size_t>(std::lround(a.reference_row)));
      }
      const auto [demo, reference] = sharedColumns(grids_.full, grids_.usable, d, reference_);
      to_reference_[d] =
          anchoredDtwMap(demo, reference, own, reference_rows, config_.alignment_band);
      from_reference_[d] =
          anchoredDtwMap(reference, demo, reference_rows, own, config_.alignment_band);
    });
  }

  std::vector<DemoEvidence> evidence_;
  const AlignmentGrids& grids_;
  const JointSegmentationConfig& config_;
  double min_segment_rows_, spread_rows_, agreement_spread_rows_, window_rows_, colocation_rows_;
  int threads_;
  std::size_t reference_;
  std::vector<std::vector<double>> to_reference_, from_reference_;
  std::vector<Anchor> anchors_;
};

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
  std::vector<std::string> names;
  for (const std::string& name : moving)
    if (std::find(selected.begin(), selected.end(), name) != selected.end()) names.push_back(name);
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
  const DemoEvidence& e = agreement.evidence(d);
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

// The agreement on the medoid's time axis (the demo with the least DTW cost to the others),
// unless most demos are left with strong evidence (a contact made or lost) that no agreed
// boundary explains: the sign that the alignment, not the demos, is wrong. The medoid can be a
// demo with a phase the others lack (a push whose hand slips off the box midway and presses
// again, onto whose second contact the others' one contact was mapped). Then the agreement is
// sought on every demo's axis in turn, and the one leaving the least strong evidence
// unexplained is kept (ties: the nearest the medoid). A few demos with unshared evidence are
// what a demo with an extra phase looks like: they are reported, and the medoid kept.
JointAgreement bestAgreement(const std::vector<DemoEvidence>& evidence, const AlignmentGrids& grids,
                             const SegmentationPipelineConfig& config) {
  const double band = config.joint.alignment_band;
  const std::vector<std::size_t> candidates = byDtwCostToOthers(grids.full, config.threads, band);
  const auto agree_on = [&](std::size_t reference, int threads) {
    JointAgreement agreement(evidence, grids,
                             alignTo(grids.full, reference, threads, band, grids.usable),
                             config.joint, config.seconds->min_segment, threads);
    agreement.run(config.segmentation.max_changepoints);
    return agreement;
  };
  JointAgreement medoid = agree_on(candidates.front(), config.threads);
  if (2 * medoid.demosWithUnexplainedEvidence() <= evidence.size()) return medoid;
  std::vector<std::optional<JointAgreement>> others(candidates.size() - 1);
  parallelFor(others.size(), config.threads,
              [&](std::size_t k) { others[k].emplace(agree_on(candidates[k + 1], 1)); });
  JointAgreement* best = &medoid;
  for (auto& other : others)
    if (other->unexplainedEvidence() < best->unexplainedEvidence()) best = &*other;
  return std::move(*best);
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
  parallelFor(n, config.threads, [&](std::size_t d) {
    speeds[d] = stateSpeed(scaled[d] * consistency.asDiagonal(), demos[d].clock(),
                           config.joint.pauses.smoothing);
  });
  const SensorSelection contact =
      sensors ? contactSensors(result.sensor_features, groups, scaled_sensors, speeds,
                               config.joint.max_speed_correlation, &result.warnings)
              : SensorSelection{};

  const std::vector<std::vector<SampleSpan>> stale =
      staleContactReadings(demos, contact, config.joint.stale_reading, &result.warnings);
  const std::vector<std::vector<ReciprocatingRun>> rhythm =
      periodicPhases(demos, states, result.selected_features, speeds, !contact.names.empty(),
                     periodicConfig(config.joint), config.threads);

  std::vector<DemoEvidence> evidence(n);
  AlignmentGrids grids;
  grids.full.resize(n);
  grids.usable.resize(n);
  parallelFor(n, config.threads, [&](std::size_t d) {
    try {
      gatherEvidence(demos[d], scaled[d], consistency, speeds[d], scaled_sensors[d], result,
                     contact, stale[d], rhythm[d], config, &result.demos[d], &evidence[d],
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
