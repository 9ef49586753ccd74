// Automatic feature selection (paper II-B): a feature that has the same shape in every
// demonstration is likely to define the task.
//
// For every feature f and every pair of demonstrations (p, q):
//   1. each demonstration's signal is min-max normalized to [0,1] (per demonstration by default,
//      so that shape matters, not the start/goal poses); a signal constant in a demonstration
//      becomes 0;
//   2. DTW aligns the pair (squared local cost, optional Sakoe-Chiba band);
//   3. C_f[p][q] = Pearson correlation of the two aligned signals (0 when one of them does not
//      vary along the path: no NaN);  D_f[p][q] = sqrt(cost / path length), the RMS difference
//      along the optimal path.
// Scores:
//   corr_f     = mean of the off-diagonal entries of C_f            (Fig. 4a, correlation only)
//   dist_f     = mean of the off-diagonal entries of D_f
//   dnorm_f    = (dist_f - min_g dist_g) / (max_g dist_g - min_g dist_g) over the non-constant
//                features g (0 for all when they are equal)
//   score_f    = corr_f * (1 - dnorm_f)                              (Fig. 4b, DTW-weighted)
// Selection (paper: CorrCoef_F x T): F = argmax score; selected = { f : score_f >= T * score_F }.
// Both variants are selected independently so Fig. 4a/4b can be compared. A feature that is
// constant in every demonstration gets score 0, is flagged and is never selected.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lfd_core/segmentation/dtw.hpp"
#include "lfd_core/segmentation/time_series.hpp"

namespace lfd {

struct FeatureRelevanceConfig {
  double threshold = 0.9;  ///< T: keep features with score >= T * best score
  /// Sakoe-Chiba band as a fraction of the longer demonstration (< 0 = unconstrained DTW). The
  /// band grows by the length difference of each pair, so different speeds remain alignable.
  double band_fraction = -1.0;
  bool normalize_per_demo = true;  ///< false: one min/max per feature across all demonstrations
  int threads = 0;                 ///< DTW worker threads; <= 0 = hardware concurrency
};

struct FeatureRelevance {
  std::string name;
  Eigen::MatrixXd correlation;     ///< N x N, C_f (diagonal 1), paper Fig. 3
  Eigen::MatrixXd distance;        ///< N x N, D_f (diagonal 0)
  double mean_correlation = 0;     ///< corr_f (correlation-only variant)
  double mean_distance = 0;        ///< dist_f
  double normalized_distance = 0;  ///< dnorm_f in [0,1]
  double score = 0;                ///< DTW-weighted score_f
  bool constant = false;           ///< constant in every demonstration (score 0, never selected)
  bool selected = false;           ///< selected by the DTW-weighted score
  bool selected_correlation_only = false;  ///< selected by corr_f alone
};

struct FeatureRelevanceResult {
  std::vector<FeatureRelevance> features;              ///< in input order
  std::vector<std::string> selected;                   ///< DTW-weighted selection, best score first
  std::vector<std::string> selected_correlation_only;  ///< correlation-only selection, best first
  std::vector<std::string> warnings;
  std::size_t num_demos = 0;

  const FeatureRelevance& feature(const std::string& name) const;  ///< throws if unknown
  /// Scores of the selected features in `selected` order (weights for the profile combination).
  std::vector<double> selectedScores() const;
};

/// Computes the relevance of `features` (all columns when empty) across `demos`. Throws
/// std::invalid_argument with fewer than 2 demonstrations, a feature missing from a
/// demonstration, non-finite samples, or empty demonstrations.
FeatureRelevanceResult computeFeatureRelevance(const std::vector<FeatureMatrix>& demos,
                                               std::vector<std::string> features = {},
                                               const FeatureRelevanceConfig& config = {});

/// Indices of the entries with score >= threshold * max score (best first); entries flagged in
/// `excluded` are skipped. If the best score is <= 0, only the best is returned.
std::vector<std::size_t> selectByThreshold(const std::vector<double>& scores,
                                           const std::vector<bool>& excluded, double threshold);

/// Pearson correlation; 0 when either signal has (numerically) no variance.
double pearsonCorrelation(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace lfd
