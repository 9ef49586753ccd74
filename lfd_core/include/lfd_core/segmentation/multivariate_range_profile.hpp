// One range of multivariate ClaSP's recursion (segmentMultivariate, paper II-C): the per-feature
// ClaSP profiles of the sub-series, combined and penalized by a Kaiser window spanning it. The
// profiles are computed on the sub-series only (k-NN restricted to it), as claspy's binary
// segmentation does: a slice of the whole-series profile would keep neighbours from outside the
// range and a split score that still "sees" the changepoints already found.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "lfd_core/segmentation/clasp.hpp"
#include "lfd_core/segmentation/multivariate_segmentation.hpp"

namespace lfd {

/// One range's profiles: each with its k-NN (for the split's significance) and its weight in the
/// p-value average; `features` names the feature of each (empty for the one distance-average
/// profile, which belongs to no single feature).
struct RangeProfile {
  std::vector<Eigen::VectorXd> profiles;
  std::vector<KnnResult> knns;
  std::vector<double> weights;
  std::vector<std::size_t> features;
  Eigen::VectorXd combined, penalized;
};

/// The inputs every range's profiles are computed from.
struct ProfileInputs {
  const Eigen::MatrixXd& features;               ///< rows = samples of the whole series
  const std::vector<double>& w;                  ///< per feature: combination and p-value weight
  const std::vector<std::size_t>& active;        ///< the informative features
  const std::vector<std::size_t>& window_sizes;  ///< per feature
  std::size_t min_s;
  const MultivariateSegmentationConfig& config;
};

/// The range [begin, begin + len)'s combined profile times a Kaiser window spanning it (a split
/// near a range end would leave a short, uninterpretable segment); nothing when no feature's
/// window fits the range.
std::optional<RangeProfile> rangeProfile(const ProfileInputs& in, std::size_t begin,
                                         std::size_t len);

/// Keeps the whole series' profiles for plots (paper Fig. 5, 8).
void recordFirstProfile(const RangeProfile& r, MultivariateSegmentation* out);

/// Weighted mean of the profiles' log10 p-values (ClaSP's rank-sum test) of a split at t,
/// relative to the range.
double splitLog10P(const RangeProfile& r, std::size_t t);

}  // namespace lfd
