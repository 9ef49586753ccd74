// Periodic back-and-forth motion (grating, sawing, wiping strokes, stirring) as a phase of its own:
// the joint segmentation's evidence that a periodic phase begins or ends where no sensor says so,
// and nothing inside it. A stroke is the motion between two dips of the speed; two strokes
// reciprocate when the second goes back along the first (their displacements point opposite ways)
// over a similar distance in a similar time. A run of strokes that each reciprocate with the next
// is a periodic phase; its first stroke's start and its last stroke's end are its edges.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace lfd {

/// How strokes and their reciprocation are told (statistics and ratios, no unit).
struct ReciprocationConfig {
  /// A dip of the speed ends a stroke when the speed rises by this fraction of the demo's 95th
  /// percentile speed on both sides of it: a reversal slows the hand to (nearly) nothing, the
  /// tremor of a steady motion does not.
  double min_dip = 0.2;
  /// The cosine between a stroke's displacement and the reverse of the next one's: 1 = straight
  /// back, 0.5 = within 60 degrees of it.
  double min_reversal_cosine = 0.5;
  /// The shorter of two reciprocating strokes covers at least this fraction of the longer's
  /// distance and lasts at least this fraction of its time: grating strokes of 3 and 6 cm
  /// reciprocate, a 30 cm reach and the first 4 cm stroke after it do not.
  double min_similarity = 0.4;
  /// Strokes in a run: 4 = out, back, out, back (two cycles). A single out-and-back (a reach
  /// and its return) is no periodic phase.
  std::size_t min_strokes = 4;
};

/// A periodic phase: samples [begin, end], the first stroke's start and the last stroke's end.
struct ReciprocatingRun {
  std::size_t begin = 0;
  std::size_t end = 0;
};

/// The periodic phases of one demo. `states`: rows = samples, each column a state feature already
/// divided by its range over the task (the features the demos move consistently: a wrist that
/// turns a little at random adds its own drift to every stroke); `time`: the demo's clock (s);
/// `smoothing_seconds`: the Gaussian sigma of the speed (as PauseConfig::smoothing). Throws
/// std::invalid_argument on a size mismatch.
std::vector<ReciprocatingRun> reciprocatingRuns(const Eigen::MatrixXd& states,
                                                const std::vector<double>& time,
                                                double smoothing_seconds,
                                                const ReciprocationConfig& config = {});

/// The same with the states' speed profile given (stateSpeed of `states`, one value per row):
/// a caller that tries many subsets of features smooths each feature once. Throws
/// std::invalid_argument on a size mismatch.
std::vector<ReciprocatingRun> reciprocatingRuns(const Eigen::MatrixXd& states,
                                                const Eigen::VectorXd& speed,
                                                const ReciprocationConfig& config = {});

}  // namespace lfd
