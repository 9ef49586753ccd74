// ClaSP (Classification Score Profile, Schäfer, Ermshaus & Leser) for univariate time series:
// window-size selection (SuSS / dominant period), the self-join k-NN of all subsequences, the
// classification score profile over every split point, the rank-sum significance test that makes
// the segmentation parameter-free, and a recursive univariate segmentation.
//
// Index conventions: a series has n samples; subsequence i covers samples [i, i + w). A split
// (changepoint) at sample s means "samples < s are left of the change"; subsequences i < s are
// labelled left (0), i >= s right (1). Profiles are indexed by sample (length n) and hold NaN where
// no split is allowed (the edges, see `min_segment_size`).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lfd {

/// How the subsequence length w is chosen when ClaspConfig::window_size is 0.
enum class WindowSelection {
  kSuss,             ///< summary-statistics subsequence (ClaSP's default, Ermshaus et al.)
  kDominantFourier,  ///< period of the strongest frequency of the periodogram
  kAutocorrelation,  ///< lag of the highest autocorrelation peak
};

/// Distance between two subsequences.
enum class ClaspDistance {
  kZNormalizedEuclidean,  ///< ClaSP's default: shape only, offset and amplitude invariant
  kEuclidean,             ///< keeps levels (useful for piecewise-constant robot signals)
};

/// Binary classification score computed at each split.
enum class ClaspScore {
  kRocAuc,   ///< ROC-AUC of the hard k-NN labels = balanced accuracy (claspy's default)
  kMacroF1,  ///< mean of the F1 scores of both classes (the original ClaSP paper)
};

WindowSelection parseWindowSelection(const std::string& name);  ///< "suss","fft","acf"
ClaspDistance parseClaspDistance(const std::string& name);      ///< "znorm_euclidean","euclidean"
ClaspScore parseClaspScore(const std::string& name);            ///< "roc_auc","f1"
std::string toString(WindowSelection selection);
std::string toString(ClaspDistance distance);
std::string toString(ClaspScore score);

struct ClaspConfig {
  std::size_t window_size = 0;  ///< w in samples; 0 = automatic (window_selection)
  WindowSelection window_selection = WindowSelection::kSuss;
  std::size_t min_window = 10;  ///< lower bound of the automatic window size
  std::size_t k = 3;            ///< neighbours per subsequence (majority vote)
  ClaspDistance distance = ClaspDistance::kZNormalizedEuclidean;
  ClaspScore score = ClaspScore::kRocAuc;
  /// Trivial-match exclusion radius as a fraction of w: neighbours j of i satisfy
  /// |i - j| > exclusion_radius * w.
  double exclusion_radius = 0.5;
  /// No split closer than this to either end (samples); 0 = 5 * w (claspy's default).
  std::size_t min_segment_size = 0;
  /// A changepoint is accepted when the rank-sum test on the predicted labels gives p below this.
  double p_value_threshold = 1e-15;
  /// Resolution of the k-NN as a fraction of the series' range: deterministic Gaussian jitter of
  /// this std is added before the k-NN (0 = off). Robot signals hold still for long stretches
  /// (gripper closed, arm at rest) whose subsequences are all but identical; their neighbours
  /// are then decided by rounding-level drift, i.e. by time proximity, and every split inside the
  /// stretch scores ~1. Jitter makes neighbours within such a stretch random, as they should be,
  /// so only the stretch's edges (the real changes) score high.
  double tie_jitter = 0.0;
};

/// The k nearest neighbours of every subsequence (self-join, trivial matches excluded).
struct KnnResult {
  std::size_t window = 0;
  std::size_t k = 0;
  std::size_t num_subsequences = 0;   ///< m = n - w + 1
  std::vector<std::int32_t> indices;  ///< m x k row-major, best first; -1 if fewer than k exist
  std::vector<double> distances;      ///< m x k row-major, Euclidean distances (same order)

  std::int32_t neighbour(std::size_t i, std::size_t rank) const { return indices[i * k + rank]; }
};

// ---------------------------------------------------------------- window-size selection

/// SuSS: smallest w whose rolling mean/std/range summarise the whole series within `threshold`
/// (score = 1 - mean distance between window and global statistics). Result in [lbound, n/2].
std::size_t sussWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t lbound = 10,
                           double threshold = 0.89);
/// Period (samples) of the strongest Fourier component with period in [lbound, n/4].
std::size_t dominantFourierWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series,
                                      std::size_t lbound = 10);
/// Lag of the highest local maximum of the autocorrelation in [lbound, n/4].
std::size_t autocorrelationWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series,
                                      std::size_t lbound = 10);
/// Dispatches on `selection`; always returns a w with 2 <= w and 3 * w <= n, throws if n is
/// too short for any window.
std::size_t selectWindowSize(const Eigen::Ref<const Eigen::VectorXd>& series,
                             WindowSelection selection, std::size_t lbound = 10);

// ---------------------------------------------------------------- k-NN

/// Exact self-join k-NN of all length-w subsequences in O(n^2) time and O(n) memory (sliding dot
/// products along diagonals, each pair visited once). |i - j| <= exclusion_zone is excluded.
KnnResult selfJoinKnn(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t window,
                      std::size_t k, std::size_t exclusion_zone,
                      ClaspDistance distance = ClaspDistance::kZNormalizedEuclidean);
/// Multivariate k-NN by distance averaging (ClaSP authors' multivariate method, as claspy does):
/// rows = samples, columns = channels; each channel's distance profile of a query is z-normalized
/// (trivial matches set to its maximum first), the profiles are averaged with `weights` (empty =
/// equal), and the k smallest averages are the neighbours. `distances` then hold the averaged
/// z-scores, not Euclidean distances. O(d n^2) time, O(d n) memory.
KnnResult distanceAverageKnn(const Eigen::MatrixXd& series, const std::vector<double>& weights,
                             std::size_t window, std::size_t k, std::size_t exclusion_zone,
                             ClaspDistance distance = ClaspDistance::kZNormalizedEuclidean);
/// O(n^2 w) reference implementation (tests).
KnnResult bruteForceKnn(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t window,
                        std::size_t k, std::size_t exclusion_zone,
                        ClaspDistance distance = ClaspDistance::kZNormalizedEuclidean);

// ---------------------------------------------------------------- profile and significance

/// Classification score for every split s in [min_split, n - min_split] (n = series length =
/// m + w - 1); NaN elsewhere. Computed incrementally: moving the split by one relabels one
/// subsequence and updates only those that have it as a neighbour, O(m k) in total.
Eigen::VectorXd classificationScoreProfile(const KnnResult& knn, std::size_t min_split,
                                           ClaspScore score = ClaspScore::kRocAuc);

/// Two-sided Wilcoxon rank-sum p-value of the k-NN predicted labels left vs right of `split`
/// (as claspy's significance test). Returned as log10(p) so that tiny p-values stay exact.
double splitLog10PValue(const KnnResult& knn, std::size_t split);

/// Everything ClaSP computes on one series.
struct ClaspProfile {
  std::size_t window_size = 0;
  std::size_t min_segment_size = 0;
  KnnResult knn;
  Eigen::VectorXd profile;  ///< length n, NaN where no split is allowed
};

/// Selects w (unless fixed), computes the k-NN and the profile. Throws std::invalid_argument for
/// non-finite input or a series too short for the window (n < 2 * min_segment_size + 1 etc.).
ClaspProfile computeClaspProfile(const Eigen::Ref<const Eigen::VectorXd>& series,
                                 const ClaspConfig& config);

/// Result of a univariate segmentation.
struct ClaspSegmentation {
  std::vector<std::size_t> changepoints;  ///< sorted sample indices
  std::vector<double> scores;             ///< profile score of each changepoint (same order)
  std::vector<double> log10_p_values;     ///< significance of each changepoint (same order)
  std::size_t window_size = 0;
  Eigen::VectorXd first_profile;  ///< profile over the whole series
};

/// Recursive binary segmentation (claspy's BinaryClaSPSegmentation): the range with the best
/// profile maximum is split first; each new range gets its own profile. With
/// num_changepoints < 0 the significance test decides when to stop; otherwise exactly that many
/// changepoints are returned when the series allows it (ranges shorter than 2 * min segment size
/// are not split).
ClaspSegmentation claspSegment(const Eigen::Ref<const Eigen::VectorXd>& series,
                               const ClaspConfig& config, int num_changepoints = -1);

}  // namespace lfd
