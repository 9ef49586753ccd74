#include "lfd_core/segmentation/feature_relevance.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace lfd {

const FeatureRelevance& FeatureRelevanceResult::feature(const std::string& name) const {
  for (const FeatureRelevance& f : features) {
    if (f.name == name) return f;
  }
  throw std::invalid_argument("no relevance computed for feature '" + name + "'");
}

std::vector<double> FeatureRelevanceResult::selectedScores() const {
  std::vector<double> scores;
  for (const std::string& name : selected) scores.push_back(feature(name).score);
  return scores;
}

double pearsonCorrelation(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n < 2) return 0.0;
  double mx = 0, my = 0;
  for (std::size_t k = 0; k < n; ++k) mx += x[k], my += y[k];
  mx /= n, my /= n;
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double dx = x[k] - mx, dy = y[k] - my;
    sxy += dx * dy, sxx += dx * dx, syy += dy * dy;
  }
  // Relative guard: a signal whose variance is rounding noise counts as constant.
  const double eps = 1e-20 * n * (1.0 + mx * mx + my * my);
  if (sxx <= eps || syy <= eps) return 0.0;
  return std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
}

std::vector<std::size_t> selectByThreshold(const std::vector<double>& scores,
                                           const std::vector<bool>& excluded, double threshold) {
  std::vector<std::size_t> candidates;
  for (std::size_t f = 0; f < scores.size(); ++f) {
    if ((excluded.empty() || !excluded[f]) && std::isfinite(scores[f])) candidates.push_back(f);
  }
  if (candidates.empty()) return {};
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&](std::size_t a, std::size_t b) { return scores[a] > scores[b]; });
  const double best = scores[candidates.front()];
  if (best <= 0) return {candidates.front()};
  std::vector<std::size_t> selected;
  for (std::size_t f : candidates) {
    if (scores[f] >= threshold * best) selected.push_back(f);
  }
  return selected;
}

namespace {

// Every demonstration's features as plain vectors (signal[d][f]), min-max normalized per feature
// (over all demonstrations, or per demonstration), and which are constant in which demonstration.
struct NormalizedSignals {
  std::vector<std::vector<std::vector<double>>> signal;
  std::vector<std::vector<bool>> constant_in;
  std::size_t longest = 0;
};

NormalizedSignals readSignals(const std::vector<FeatureMatrix>& demos,
                              const std::vector<std::string>& features) {
  NormalizedSignals n;
  n.signal.resize(demos.size());
  n.constant_in.resize(demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) {
    const FeatureMatrix& demo = demos[d];
    const std::string context = "demonstration " + std::to_string(d);
    demo.validateShape();
    if (demo.rows() < 2) throw std::invalid_argument(context + " has fewer than 2 samples");
    n.longest = std::max<std::size_t>(n.longest, demo.rows());
    for (const std::string& name : features) {
      const int col = demo.indexOf(name);
      if (col < 0) throw std::invalid_argument(context + " has no feature '" + name + "'");
      Eigen::VectorXd x = demo.data.col(col);
      for (Eigen::Index r = 0; r < x.size(); ++r) {
        if (!std::isfinite(x[r])) {
          throw std::invalid_argument(context + ": feature '" + name + "' has " +
                                      (std::isnan(x[r]) ? "NaN" : "Inf") + " at sample " +
                                      std::to_string(r));
        }
      }
      n.signal[d].emplace_back(x.data(), x.data() + x.size());
    }
  }
  return n;
}

void normalize(NormalizedSignals& n, std::size_t num_features, bool per_demo) {
  const std::size_t num_demos = n.signal.size();
  for (std::size_t f = 0; f < num_features; ++f) {
    double lo = INFINITY, hi = -INFINITY;
    if (!per_demo) {
      for (std::size_t d = 0; d < num_demos; ++d) {
        const auto [mn, mx] = std::minmax_element(n.signal[d][f].begin(), n.signal[d][f].end());
        lo = std::min(lo, *mn), hi = std::max(hi, *mx);
      }
    }
    for (std::size_t d = 0; d < num_demos; ++d) {
      std::vector<double>& x = n.signal[d][f];
      const auto [mn, mx] = std::minmax_element(x.begin(), x.end());
      const bool flat = !(*mx - *mn > 1e-12 * (1.0 + std::max(std::abs(*mx), std::abs(*mn))));
      n.constant_in[d].push_back(flat);
      const double offset = per_demo ? *mn : lo;
      const double range = per_demo ? *mx - *mn : hi - lo;
      const bool zero = per_demo ? flat : !(range > 1e-12 * (1.0 + std::abs(hi)));
      for (double& v : x) v = zero ? 0.0 : (v - offset) / range;
    }
  }
}

// Each feature's pairwise correlation (after DTW) and distance matrices. Every (pair, feature)
// alignment runs in one batch; pairs of one demonstration pair share shapes, so they fill the
// SIMD lanes without padding.
void alignPairs(const NormalizedSignals& n, const FeatureRelevanceConfig& config,
                FeatureRelevanceResult& result) {
  const std::size_t num_demos = n.signal.size(), num_features = result.features.size();
  std::vector<std::pair<std::size_t, std::size_t>> demo_pairs;
  for (std::size_t p = 0; p < num_demos; ++p) {
    for (std::size_t q = p + 1; q < num_demos; ++q) demo_pairs.emplace_back(p, q);
  }
  std::vector<DtwPairView> views;
  views.reserve(demo_pairs.size() * num_features);
  for (const auto& [p, q] : demo_pairs) {
    for (std::size_t f = 0; f < num_features; ++f) {
      views.push_back({n.signal[p][f].data(), n.signal[p][f].size(), n.signal[q][f].data(),
                       n.signal[q][f].size()});
    }
  }
  DtwOptions dtw_options;
  if (config.band_fraction >= 0) {
    dtw_options.band = static_cast<int>(std::ceil(config.band_fraction * double(n.longest)));
  }
  const std::vector<DtwResult> alignments = dtwBatch(views, dtw_options, config.threads);
  for (std::size_t k = 0; k < demo_pairs.size(); ++k) {
    const auto [p, q] = demo_pairs[k];
    for (std::size_t f = 0; f < num_features; ++f) {
      const DtwResult& r = alignments[k * num_features + f];
      const DtwPairView& v = views[k * num_features + f];
      const auto aligned = dtwAlignedPair(v.a, v.b, r.path);
      FeatureRelevance& fr = result.features[f];
      fr.correlation(p, q) = fr.correlation(q, p) =
          pearsonCorrelation(aligned.first, aligned.second);
      fr.distance(p, q) = fr.distance(q, p) =
          std::sqrt(std::max(0.0, r.cost) / double(r.path.size()));
    }
  }
}

// The paper's score: mean correlation weighted by 1 - the normalized mean DTW distance.
void scoreFeatures(FeatureRelevanceResult& result) {
  const double n = double(result.num_demos), pairs = n * (n - 1) / 2.0;
  double dmin = INFINITY, dmax = -INFINITY;
  for (FeatureRelevance& fr : result.features) {
    fr.mean_correlation = (fr.correlation.sum() - n) / (2.0 * pairs);
    fr.mean_distance = fr.distance.sum() / (2.0 * pairs);
    if (!fr.constant)
      dmin = std::min(dmin, fr.mean_distance), dmax = std::max(dmax, fr.mean_distance);
  }
  for (FeatureRelevance& fr : result.features) {
    if (fr.constant) {
      fr.mean_correlation = 0.0;
      fr.normalized_distance = 1.0;
      fr.score = 0.0;
      result.warnings.push_back("feature '" + fr.name +
                                "' is constant in every demonstration: score 0, not selected");
    } else {
      fr.normalized_distance =
          dmax - dmin > 1e-12 ? (fr.mean_distance - dmin) / (dmax - dmin) : 0.0;
      fr.score = fr.mean_correlation * (1.0 - fr.normalized_distance);
    }
  }
}

void selectFeatures(FeatureRelevanceResult& result, double threshold) {
  std::vector<double> weighted, correlation_only;
  std::vector<bool> excluded;
  for (const FeatureRelevance& fr : result.features) {
    weighted.push_back(fr.score);
    correlation_only.push_back(fr.mean_correlation);
    excluded.push_back(fr.constant);
  }
  for (std::size_t f : selectByThreshold(weighted, excluded, threshold)) {
    result.features[f].selected = true;
    result.selected.push_back(result.features[f].name);
  }
  for (std::size_t f : selectByThreshold(correlation_only, excluded, threshold)) {
    result.features[f].selected_correlation_only = true;
    result.selected_correlation_only.push_back(result.features[f].name);
  }
  if (result.selected.empty()) {
    result.warnings.push_back("no feature varies in any demonstration: nothing selected");
    return;
  }
  const auto best =  // the best scored feature (selectByThreshold lists the best first)
      std::find_if(result.features.begin(), result.features.end(),
                   [&](const FeatureRelevance& fr) { return fr.name == result.selected[0]; });
  if (best->score <= 0) {
    result.warnings.push_back("no feature has a positive relevance score; kept only '" +
                              result.selected[0] + "'");
  }
}

}  // namespace

FeatureRelevanceResult computeFeatureRelevance(const std::vector<FeatureMatrix>& demos,
                                               std::vector<std::string> features,
                                               const FeatureRelevanceConfig& config) {
  if (demos.size() < 2) {
    throw std::invalid_argument("feature relevance needs at least 2 demonstrations, got " +
                                std::to_string(demos.size()));
  }
  if (!(config.threshold >= 0.0 && config.threshold <= 1.0)) {
    throw std::invalid_argument("relevance threshold T must be in [0,1], got " +
                                std::to_string(config.threshold));
  }
  if (features.empty()) features = demos.front().names;
  if (features.empty()) throw std::invalid_argument("feature relevance: no features");
  const std::size_t num_demos = demos.size(), num_features = features.size();
  NormalizedSignals signals = readSignals(demos, features);
  normalize(signals, num_features, config.normalize_per_demo);

  FeatureRelevanceResult result;
  result.num_demos = num_demos;
  result.features.resize(num_features);
  for (std::size_t f = 0; f < num_features; ++f) {
    FeatureRelevance& fr = result.features[f];
    fr.name = features[f];
    fr.correlation = Eigen::MatrixXd::Identity(num_demos, num_demos);
    fr.distance = Eigen::MatrixXd::Zero(num_demos, num_demos);
    fr.constant = true;
    for (std::size_t d = 0; d < num_demos; ++d)
      fr.constant = fr.constant && signals.constant_in[d][f];
  }
  alignPairs(signals, config, result);
  scoreFeatures(result);
  selectFeatures(result, config.threshold);
  return result;
}

}  // namespace lfd
