// The joint segmentation's consensus step (see joint_agreement.hpp).
#include "lfd_core/segmentation/joint_agreement.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "lfd_core/util/parallel_for.hpp"

namespace lfd {
namespace {

// Noisy-OR of a demo's unclaimed evidence around each reference row: how sure this demo is that
// a boundary lies there.
Eigen::VectorXd demoSupport(const DemoPieces& e, Eigen::Index rows, double spread_rows) {
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
double colocatedStrength(const DemoPieces& e, std::size_t p, double colocation_rows) {
  double none = 1.0;
  for (std::size_t q = 0; q < e.pieces.size(); ++q)
    if (!e.claimed[q] && std::abs(e.grid_rows[q] - e.grid_rows[p]) <= colocation_rows)
      none *= 1.0 - e.pieces[q].weight;
  return 1.0 - none;
}

// ClaSP times a change only to within its subsequence window: a chosen ClaSP piece gives way to
// the nearest sensory or kinematic piece of the demo within `spread_rows` of it (a contact, a
// pause's end), which times the same change to a sample.
long sharpen(const DemoPieces& e, long chosen, double spread_rows, double min_weight,
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

long bestPiece(const DemoPieces& e, double u, const PlacementRows& rows, double after_row,
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

}  // namespace

bool AlignmentGrids::blindAt(std::size_t d, double row) const {
  return std::any_of(blind[d].begin(), blind[d].end(),
                     [&](const auto& span) { return row >= span.first && row <= span.second; });
}

JointAgreement::JointAgreement(std::vector<DemoPieces> evidence, const AlignmentGrids& grids,
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

void JointAgreement::run(std::size_t max_boundaries) {
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

double JointAgreement::unexplainedEvidence() const {
  double sum = 0.0;
  for (std::size_t d = 0; d < evidence_.size(); ++d) sum += unexplainedEvidenceOf(d);
  return sum;
}

std::size_t JointAgreement::demosWithUnexplainedEvidence() const {
  std::size_t count = 0;
  for (std::size_t d = 0; d < evidence_.size(); ++d) count += unexplainedEvidenceOf(d) > 0.0;
  return count;
}

double JointAgreement::expectedRow(std::size_t d, double reference_row) const {
  return mapRow(from_reference_[d], reference_row);
}

bool JointAgreement::felt(std::size_t d, std::size_t k) const {
  const long p = anchors_[k].piece[d];
  if (p < 0) return false;
  const DemoPieces& e = evidence_[d];
  const double row = e.grid_rows[static_cast<std::size_t>(p)];
  if (grids_.blindAt(d, row)) return false;
  for (std::size_t q = 0; q < e.pieces.size(); ++q)
    if (std::abs(e.grid_rows[q] - row) <= colocation_rows_ &&
        (e.pieces[q].kind == EvidenceKind::kContact ||
         e.pieces[q].kind == EvidenceKind::kSensorLevel))
      return true;
  return false;
}

double JointAgreement::unexplainedEvidenceOf(std::size_t d) const {
  const DemoPieces& e = evidence_[d];
  double sum = 0.0;
  for (std::size_t p = 0; p < e.pieces.size(); ++p)
    if (!e.claimed[p] && e.pieces[p].weight >= config_.extra_event_weight)
      sum += e.pieces[p].weight;
  return sum;
}

void JointAgreement::mapEvidence() {
  for (DemoPieces& e : evidence_) e.reference_rows.clear();
  for (std::size_t d = 0; d < evidence_.size(); ++d)
    for (double row : evidence_[d].grid_rows)
      evidence_[d].reference_rows.push_back(mapRow(to_reference_[d], row));
}

Eigen::VectorXd JointAgreement::support() const {
  const Eigen::Index rows = grids_.full[reference_].rows();
  Eigen::VectorXd s = Eigen::VectorXd::Zero(rows);
  for (const DemoPieces& e : evidence_)
    s += demoSupport(e, rows, agreement_spread_rows_) / static_cast<double>(evidence_.size());
  // Support above the background: evidence that is everywhere (a contact force varying all
  // along a wipe, in every demo at other times) supports every instant alike and so none.
  const double background = s.mean();
  return background < 1.0 ? Eigen::VectorXd((s.array() - background).max(0.0) / (1.0 - background))
                          : Eigen::VectorXd::Zero(rows);
}

// Adds the boundary and places it in every demo; false (and nothing added) when no demo has
// a piece for it (the support came from pieces the order forbids), so the search stops rather
// than loop.
bool JointAgreement::addAnchor(double u) {
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
bool JointAgreement::place(Anchor* a, std::size_t d) {
  const double rows = static_cast<double>(grids_.full[d].rows());
  const auto [after, before] = neighbouringRows(anchors_, d, a->reference_row, rows);
  const long p = bestPiece(evidence_[d], a->reference_row,
                           {window_rows_, spread_rows_, colocation_rows_, config_.min_piece_weight},
                           after, before);
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
void JointAgreement::retryMissing() {
  for (Anchor& a : anchors_)
    for (std::size_t d = 0; d < evidence_.size(); ++d)
      if (a.piece[d] < 0) place(&a, d);
}

// The chosen piece and those at its place belong to this boundary.
void JointAgreement::claim(std::size_t d, std::size_t p) {
  DemoPieces& e = evidence_[d];
  for (std::size_t q = 0; q < e.pieces.size(); ++q)
    if (std::abs(e.grid_rows[q] - e.grid_rows[p]) <= colocation_rows_) e.claimed[q] = true;
}

// The alignment of every demo, held at the boundaries placed in it (a boundary the demo lacks
// says nothing of where it would be).
void JointAgreement::realign() {
  parallelFor(evidence_.size(), threads_, [&](std::size_t d) {
    if (d == reference_) return;
    std::vector<std::size_t> own, reference_rows;
    for (const Anchor& a : anchors_) {
      if (a.piece[d] < 0) continue;
      own.push_back(a.demo_row[d]);
      reference_rows.push_back(static_cast<std::size_t>(std::lround(a.reference_row)));
    }
    const auto [demo, reference] = sharedColumns(grids_.full, grids_.usable, d, reference_);
    to_reference_[d] = anchoredDtwMap(demo, reference, own, reference_rows, config_.alignment_band);
    from_reference_[d] =
        anchoredDtwMap(reference, demo, reference_rows, own, config_.alignment_band);
  });
}

JointAgreement bestAgreement(const std::vector<DemoPieces>& evidence, const AlignmentGrids& grids,
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

}  // namespace lfd
