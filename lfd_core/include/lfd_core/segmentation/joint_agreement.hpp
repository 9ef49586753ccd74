// The joint segmentation's consensus step: the demos of a task agree on one phase sequence,
// boundary by boundary. Each demo brings its pieces of evidence (boundary_evidence.hpp) and its
// place on a common alignment grid; the demos' pieces are mapped onto one demo's time axis (the
// reference), added up there as support, and the best supported instant becomes a boundary placed
// in every demo on its own best piece near it; the alignment is then held at the boundaries placed
// and the search goes on. A demo with no piece near a boundary is reported as lacking it, never
// forced (joint_segmentation.cpp reports).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

#include "lfd_core/segmentation/boundary_evidence.hpp"
#include "lfd_core/segmentation/demo_alignment.hpp"
#include "lfd_core/segmentation/joint_segmentation_config.hpp"
#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd {

/// One demo's evidence: its pieces, where each falls on the reference's grid, whether an agreed
/// boundary has claimed it, and the demo's own rows on its grid.
struct DemoPieces {
  std::vector<BoundaryEvidence> pieces;
  std::vector<double> reference_rows;
  std::vector<bool> claimed;
  std::vector<double> grid_rows;  ///< per piece, on the demo's own grid
};

/// One agreed boundary: where on the reference, how well supported, and per demo the piece that
/// places it (-1: the demo shows no evidence of it) and the demo's grid row that anchors the
/// alignment (the piece's, else where the alignment expects it).
struct Anchor {
  double reference_row = 0.0;
  double support = 0.0;
  std::vector<long> piece;
  std::vector<std::size_t> demo_row;
};

/// The demos on the alignment grid, per demo the columns it can fill, and where its contact
/// sensor was blind (grid rows): where it did not measure (stale_readings.hpp), and a lag on
/// either side, where its events are dropped (contact_sensors.hpp: dropStaleEvents).
struct AlignmentGrids {
  std::vector<Eigen::MatrixXd> full;
  ColumnMasks usable;
  std::vector<std::vector<std::pair<double, double>>> blind;

  bool blindAt(std::size_t d, double row) const;
};

/// The agreement, boundary by boundary, on the time axis of `alignment.reference`.
class JointAgreement {
 public:
  JointAgreement(std::vector<DemoPieces> evidence, const AlignmentGrids& grids,
                 DemoAlignment alignment, const JointSegmentationConfig& config,
                 double min_segment_seconds, int threads);

  /// Adds agreed boundaries, best supported first, re-aligning between them after each.
  void run(std::size_t max_boundaries);

  const std::vector<Anchor>& anchors() const { return anchors_; }
  /// The weight of the strong evidence (extra_event_weight: contact made or lost) no agreed
  /// boundary claims, over every demo; and how many demos have any.
  double unexplainedEvidence() const;
  std::size_t demosWithUnexplainedEvidence() const;
  const DemoPieces& evidence(std::size_t d) const { return evidence_[d]; }
  /// Where demo d's grid row is expected for `reference_row` of the reference.
  double expectedRow(std::size_t d, double reference_row) const;
  double colocationRows() const { return colocation_rows_; }
  double windowRows() const { return window_rows_; }
  /// Whether demo d placed boundary k where its contact sensor felt a change.
  bool felt(std::size_t d, std::size_t k) const;
  bool everBlind(std::size_t d) const { return !grids_.blind[d].empty(); }
  bool blindAt(std::size_t d, double row) const { return grids_.blindAt(d, row); }

 private:
  double unexplainedEvidenceOf(std::size_t d) const;
  void mapEvidence();
  Eigen::VectorXd support() const;
  bool addAnchor(double u);
  bool place(Anchor* a, std::size_t d);
  void retryMissing();
  void claim(std::size_t d, std::size_t p);
  void realign();

  std::vector<DemoPieces> evidence_;
  const AlignmentGrids& grids_;
  const JointSegmentationConfig& config_;
  double min_segment_rows_, spread_rows_, agreement_spread_rows_, window_rows_, colocation_rows_;
  int threads_;
  std::size_t reference_;
  std::vector<std::vector<double>> to_reference_, from_reference_;
  std::vector<Anchor> anchors_;
};

/// The agreement on the medoid's time axis (the demo with the least DTW cost to the others),
/// unless most demos are left with strong evidence (a contact made or lost) that no agreed
/// boundary explains: the sign that the alignment, not the demos, is wrong. The medoid can be a
/// demo with a phase the others lack (a push whose hand slips off the box midway and presses
/// again, onto whose second contact the others' one contact was mapped). Then the agreement is
/// sought on every demo's axis in turn, and the one leaving the least strong evidence
/// unexplained is kept (ties: the nearest the medoid). A few demos with unshared evidence are
/// what a demo with an extra phase looks like: they are reported, and the medoid kept.
JointAgreement bestAgreement(const std::vector<DemoPieces>& evidence, const AlignmentGrids& grids,
                             const SegmentationPipelineConfig& config);

}  // namespace lfd
