// One range of the multivariate ClaSP recursion (multivariate_range_profile.hpp).
#include "lfd_core/segmentation/multivariate_range_profile.hpp"

#include <algorithm>
#include <utility>

namespace lfd {
namespace {

bool isDistanceAverage(ProfileCombination c) {
  return c == ProfileCombination::kDistanceAverage ||
         c == ProfileCombination::kWeightedDistanceAverage;
}

Eigen::VectorXd columnRange(const Eigen::MatrixXd& features, std::size_t f, std::size_t begin,
                            std::size_t len) {
  return features.col(static_cast<Eigen::Index>(f))
      .segment(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(len));
}

// The features whose window fits the range three times (shorter ones have no profile there).
void addFittingFeatures(const ProfileInputs& in, std::size_t len, RangeProfile* r) {
  for (std::size_t f : in.active) {
    if (len < 3 * in.window_sizes[f]) continue;
    r->weights.push_back(in.w[f]);
    r->features.push_back(f);
  }
}

// One ClaSP profile per fitting feature, computed on the range only (see the header).
void perFeatureProfiles(const ProfileInputs& in, std::size_t begin, std::size_t len,
                        RangeProfile* r) {
  for (std::size_t f : r->features) {
    ClaspConfig cfg = in.config.clasp;
    cfg.window_size = in.window_sizes[f];
    cfg.min_segment_size = in.min_s;
    ClaspProfile p = computeClaspProfile(columnRange(in.features, f, begin, len), cfg);
    r->profiles.push_back(std::move(p.profile));
    r->knns.push_back(std::move(p.knn));
  }
}

// One k-NN over every fitting feature at the largest of their windows; false when the range is
// too short for that window.
bool distanceAverageProfile(const ProfileInputs& in, std::size_t begin, std::size_t len,
                            RangeProfile* r) {
  std::size_t window = 0;
  for (std::size_t f : r->features) window = std::max(window, in.window_sizes[f]);
  if (len < 3 * window) return false;
  Eigen::MatrixXd block(static_cast<Eigen::Index>(len),
                        static_cast<Eigen::Index>(r->features.size()));
  for (std::size_t i = 0; i < r->features.size(); ++i)
    block.col(static_cast<Eigen::Index>(i)) = columnRange(in.features, r->features[i], begin, len);
  const ClaspConfig& clasp = in.config.clasp;
  KnnResult knn = distanceAverageKnn(
      block, r->weights, window, clasp.k,
      static_cast<std::size_t>(clasp.exclusion_radius * static_cast<double>(window)),
      clasp.distance);
  r->profiles.assign(1, classificationScoreProfile(knn, in.min_s, clasp.score));
  r->knns.assign(1, std::move(knn));
  r->weights.assign(1, 1.0);
  r->features.clear();
  return true;
}

}  // namespace

std::optional<RangeProfile> rangeProfile(const ProfileInputs& in, std::size_t begin,
                                         std::size_t len) {
  RangeProfile r;
  addFittingFeatures(in, len, &r);
  if (r.features.empty()) return std::nullopt;
  const bool joint = isDistanceAverage(in.config.combination);
  if (joint) {
    if (!distanceAverageProfile(in, begin, len, &r)) return std::nullopt;
    r.combined = r.profiles[0];
  } else {
    perFeatureProfiles(in, begin, len, &r);
    r.combined = combineProfiles(r.profiles, r.weights, in.config.combination);
  }
  r.penalized = r.combined.cwiseProduct(kaiserWindow(len, in.config.kaiser_beta));
  return r;
}

void recordFirstProfile(const RangeProfile& r, MultivariateSegmentation* out) {
  out->first_profile = r.combined;
  out->first_profile_penalized = r.penalized;
  for (std::size_t i = 0; i < r.features.size(); ++i)
    out->first_feature_profiles[r.features[i]] = r.profiles[i];
}

double splitLog10P(const RangeProfile& r, std::size_t t) {
  double weighted_log_p = 0.0, weight_sum = 0.0;
  for (std::size_t i = 0; i < r.knns.size(); ++i) {
    weighted_log_p += r.weights[i] * splitLog10PValue(r.knns[i], t);
    weight_sum += r.weights[i];
  }
  return weighted_log_p / weight_sum;
}

}  // namespace lfd
