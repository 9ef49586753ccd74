// Multivariate ClaSP (paper II-C): one ClaSP profile per selected feature, combined into one
// profile (average / product, optionally weighted by the feature relevance of II-B), penalized by
// a Kaiser window on each recursion's sub-series, and split recursively.
//
// Input convention (same as FeatureMatrix::data): rows = samples of ONE demonstration, all features
// on the same clock; columns = features. Changepoints are row indices.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "lfd_core/segmentation/clasp.hpp"
#include "lfd_core/segmentation/sensory_events.hpp"

namespace lfd {

/// How per-feature profiles are merged (the paper's default is kWeightedProduct).
enum class ProfileCombination {
  kAverage,          ///< arithmetic mean
  kProduct,          ///< geometric mean (the product, normalised to stay in [0, 1])
  kWeightedAverage,  ///< sum_f w_f p_f / sum_f w_f
  kWeightedProduct,  ///< prod_f p_f^(w_f / sum w) = exp(sum_f w_f log p_f / sum_f w_f)
  /// Not a profile combination: one k-NN on the per-channel distance profiles, each z-normalized
  /// and averaged before the neighbours are taken (the ClaSP authors' multivariate method,
  /// distanceAverageKnn), one window for all features (the largest of theirs), one profile.
  kDistanceAverage,
  kWeightedDistanceAverage,  ///< the same with the profiles weighted by feature relevance
};

/// "average", "product", "weighted_average", "weighted_product", "distance_average",
/// "weighted_distance_average" (throws std::invalid_argument).
ProfileCombination parseProfileCombination(const std::string& name);
std::string toString(ProfileCombination combination);
/// Whether the combination weighs the profiles by feature relevance.
bool isWeighted(ProfileCombination combination);

/// Combines equally long profiles. NaN in any profile makes that sample NaN. Weights must be
/// >= 0 with a positive sum (ignored by the unweighted methods; empty = all ones). Product
/// methods work in log space and return the (weighted) geometric mean, so the result keeps the
/// scale of a single ClaSP score whatever the number of features, and never underflows; a score
/// <= 0 is clamped to 1e-12 before the log.
Eigen::VectorXd combineProfiles(const std::vector<Eigen::VectorXd>& profiles,
                                const std::vector<double>& weights, ProfileCombination combination);

/// Kaiser window of length n with shape beta (I0-Bessel), peak 1 in the middle, fading toward
/// both ends (w(0) = w(n-1) = 1 / I0(beta)).
Eigen::VectorXd kaiserWindow(std::size_t n, double beta);

struct MultivariateSegmentationConfig {
  ProfileCombination combination = ProfileCombination::kWeightedProduct;
  /// Per-feature ClaSP settings. window_size 0 = each feature gets its own automatic window,
  /// chosen once on the whole demonstration (capped at n / 10) and reused in every recursion
  /// step.
  /// Default distance here is Euclidean, not ClaSP's z-normalized one: robot features are
  /// piecewise smooth (min-jerk moves, gripper steps) and z-normalization erases the level and
  /// amplitude differences that tell the phases apart (measured on synthetic 2-phase
  /// demonstrations: 18/20 correct vs 11/20).
  ClaspConfig clasp = [] {
    ClaspConfig c;
    c.distance = ClaspDistance::kEuclidean;
    return c;
  }();
  /// Fixed windows per feature (overrides clasp.window_size when non-empty; size = #features).
  std::vector<std::size_t> window_sizes;
  /// min_s: minimum segment length in samples (no changepoint closer than this to a range end or
  /// another changepoint). 0 = max(2 * largest feature window, n / 20).
  std::size_t min_segment_length = 0;
  /// Kaiser shape: 0 disables the penalization (window of ones). 2 fades the score to 0.44 at
  /// the range ends, 0.61 at 10 % and 0.83 at 25 % of the range: short end segments lose, while a
  /// clear changepoint a quarter into the range still beats a flat profile (~0.5 everywhere).
  double kaiser_beta = 2.0;
  /// Optional extension (empty = the paper: candidates anywhere, validated afterwards). When
  /// given, e.g. the confidence zones of sensory_events.hpp, each recursion step takes the argmax
  /// of its penalized profile only inside these intervals, so a strong peak outside every zone
  /// cannot hide a weaker in-zone changepoint of the same range. Without zone_anchors each zone
  /// holds at most one changepoint (a zone marks one sensory interaction); with them, one per
  /// anchor (zones closer than min_s merge and may hold several interactions).
  std::vector<Interval> candidate_zones;
  /// Alternative to candidate_zones for zones that depend on min_s (eq. 1): called once min_s is
  /// known, its result replaces candidate_zones. Empty result = no zone, hence no changepoint.
  std::function<std::vector<Interval>(std::size_t min_s)> candidate_zones_for;
  /// Significance needed by an in-zone candidate (zone-guided search only; 0 = the ClaSP
  /// threshold). The sensory event is independent evidence of a change there, so ClaSP's own
  /// evidence may be weaker than for a candidate anywhere.
  double zone_p_value_threshold = 0.0;
  /// The same for a zone that holds a preferred anchor (0 = as zone_p_value_threshold).
  double rest_edge_p_value_threshold = 0.0;
  /// Sensory events that anchor the zones (zone-guided search only; empty = off). ClaSP still
  /// decides whether a zone holds a changepoint (its in-zone argmax and that argmax's
  /// significance), but the changepoint is placed at the zone's event nearest to the argmax. The
  /// features kept for their consistency across demos (II-B) are smooth kinematics whose profile
  /// peaks up to a window away from the interaction, often on the zone's edge and at a different
  /// point of the skill in every demo; the sensors time an interaction to a few samples.
  std::vector<std::size_t> zone_anchors;
  /// Per zone_anchors entry (empty = none): a zone's preferred anchors are taken before its
  /// others (the sensory events where a signal leaves or regains its rest level: contact made or
  /// lost, rather than a force ramp reaching its plateau).
  std::vector<bool> preferred_anchors;
  /// Candidates outside zones (no sensors) need log10 p <= -significance_per_sample x the
  /// demo's length (samples) when that is stricter than clasp.p_value_threshold; 0 = off. The
  /// log p of ClaSP's rank-sum test grows with the number of subsequences for the same split
  /// quality, so a fixed threshold over-segments long or densely sampled demos.
  double significance_per_sample = 0.0;
  int num_changepoints = -1;          ///< < 0: stop with the significance test; >= 0: exact count
  std::size_t max_changepoints = 16;  ///< safety cap when the test decides
};

/// One accepted or rejected split candidate of the recursion.
struct SplitCandidate {
  std::size_t index = 0;        ///< sample index of the candidate
  std::size_t range_begin = 0;  ///< the sub-series [begin, end) it was found in
  std::size_t range_end = 0;
  double score = 0.0;          ///< penalized combined score at the candidate
  double log10_p_value = 0.0;  ///< weighted mean of the per-feature log10 p-values
  bool accepted = false;
  /// Placed at a sensory event of its zone instead of the profile's in-zone argmax
  /// (profile_argmax, where score and log10_p_value are taken); see zone_anchors.
  bool anchored = false;
  std::size_t profile_argmax = 0;
};

struct MultivariateSegmentation {
  std::vector<std::size_t> changepoints;    ///< sorted accepted changepoints (row indices)
  std::vector<SplitCandidate> candidates;   ///< every candidate, in the order examined
  std::vector<std::size_t> window_sizes;    ///< per feature
  std::size_t min_segment_length = 0;       ///< the min_s actually used
  Eigen::VectorXd first_profile;            ///< combined profile of the whole series (NaN at edges)
  Eigen::VectorXd first_profile_penalized;  ///< the same times the Kaiser window (paper Fig. 5)
  std::vector<Eigen::VectorXd> first_feature_profiles;  ///< per feature, whole series
};

/// Segments one demonstration. `features`: rows = samples, cols = features (finite; a constant
/// column carries no information and is left out of the combination, with a zero profile).
/// `weights`: one relevance score per column (empty = all ones). Throws std::invalid_argument on
/// shape mismatch, non-finite values, negative weights or a series too short for min_s.
MultivariateSegmentation segmentMultivariate(const Eigen::MatrixXd& features,
                                             const std::vector<double>& weights,
                                             const MultivariateSegmentationConfig& config);

}  // namespace lfd
