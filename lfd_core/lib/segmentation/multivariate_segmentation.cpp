// Multivariate ClaSP with Kaiser penalization (paper II-C).
//
// Recursion: every range [begin, end) between accepted changepoints gets fresh per-feature ClaSP
// profiles computed on that sub-series only (k-NN restricted to it, labels relative to it), as
// claspy's binary segmentation does. Slicing the whole-series profile instead would keep
// neighbours from outside the range and a split score that still "sees" the changepoints already
// found, so the second-best peak would often sit right next to the first changepoint. Recomputing
// costs O(L^2) per range of length L, i.e. at most O(n^2) per recursion level.
//
// Each range's combined profile is multiplied by a Kaiser window spanning the range, so splits
// near a range end (which would create short, uninterpretable segments) are penalized, and the
// argmax is the candidate. It is accepted when the weighted mean of the per-feature log10 p-values
// of ClaSP's rank-sum test is below log10(p_value_threshold) (or, with a fixed count, always).
// Ranges are split best-score first (priority queue), as in claspy.
//
// This file: the inputs' checks and the features' windows, one range's candidate choice and the
// best-first driver (ClaspRecursion). One range's combined, penalized profile is
// multivariate_range_profile.cpp; the zone-guided search (which samples may be candidates, where
// a candidate is anchored, what significance it needs) zone_guided_search.cpp; the profile
// combination and the Kaiser window profile_combination.cpp.
#include "lfd_core/segmentation/multivariate_segmentation.hpp"

#include "lfd_core/segmentation/multivariate_range_profile.hpp"
#include "lfd_core/segmentation/zone_guided_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

void checkInputs(const Eigen::MatrixXd& features, const std::vector<double>& weights,
                 const MultivariateSegmentationConfig& config) {
  const std::size_t num_features = static_cast<std::size_t>(features.cols());
  if (num_features == 0) throw std::invalid_argument("segmentMultivariate: no feature columns");
  if (!features.allFinite())
    throw std::invalid_argument("segmentMultivariate: features contain NaN/Inf values");
  if (!weights.empty() && weights.size() != num_features)
    throw std::invalid_argument("segmentMultivariate: " + std::to_string(weights.size()) +
                                " weights for " + std::to_string(num_features) + " features");
  if (!config.window_sizes.empty() && config.window_sizes.size() != num_features)
    throw std::invalid_argument(
        "segmentMultivariate: window_sizes must have one entry per feature");
  for (double v : weights)
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument("segmentMultivariate: weights must be finite and >= 0");
  if (!(config.clasp.p_value_threshold > 0.0))
    throw std::invalid_argument("segmentMultivariate: p_value_threshold must be > 0");
  if (!(config.zone_p_value_threshold >= 0.0 && config.zone_p_value_threshold < 1.0))
    throw std::invalid_argument("segmentMultivariate: zone_p_value_threshold must be in [0, 1)");
}

// The window of one feature: fixed by the config, or chosen on the whole demonstration.
std::size_t windowOf(const Eigen::Ref<const Eigen::VectorXd>& column, std::size_t f,
                     const MultivariateSegmentationConfig& config) {
  if (!config.window_sizes.empty()) return config.window_sizes[f];
  if (config.clasp.window_size) return config.clasp.window_size;
  // Automatic windows are capped at n / 10 so that one slowly varying feature cannot push the
  // automatic min_s (2 x largest window) past what leaves room for a split.
  const std::size_t n = static_cast<std::size_t>(column.size());
  const std::size_t chosen =
      selectWindowSize(column, config.clasp.window_selection, config.clasp.min_window);
  return std::max<std::size_t>(2, std::min(chosen, n / 10));
}

// The informative features (varying, positive weight), their windows set in out->window_sizes.
// A constant feature has no changepoint to offer and would only flatten the combination.
std::vector<std::size_t> activeFeatures(const Eigen::MatrixXd& features,
                                        const std::vector<double>& w,
                                        const MultivariateSegmentationConfig& config,
                                        MultivariateSegmentation* out) {
  const std::size_t n = static_cast<std::size_t>(features.rows());
  std::vector<std::size_t> active;
  for (std::size_t f = 0; f < w.size(); ++f) {
    const auto col = features.col(static_cast<Eigen::Index>(f));
    const double range = n ? col.maxCoeff() - col.minCoeff() : 0.0;
    if (n < 6 || !(range > 1e-12 * (1.0 + col.cwiseAbs().maxCoeff())) || w[f] <= 0.0) continue;
    out->window_sizes[f] = windowOf(col, f, config);
    if (out->window_sizes[f] < 2)
      throw std::invalid_argument("segmentMultivariate: window size of feature " +
                                  std::to_string(f) + " must be >= 2");
    active.push_back(f);
  }
  return active;
}

// min_s: configured, or room for two of the largest windows and at most 20 segments.
std::size_t minSegmentLength(const MultivariateSegmentation& out,
                             const std::vector<std::size_t>& active, std::size_t n,
                             const MultivariateSegmentationConfig& config) {
  if (config.min_segment_length) return config.min_segment_length;
  std::size_t max_window = 0;
  for (std::size_t f : active) max_window = std::max(max_window, out.window_sizes[f]);
  return std::max(2 * max_window, n / 20);
}

// The highest penalized score of the range that may be a candidate (in an open zone not yet
// tested in this range); -1 = none.
Eigen::Index bestOpenSample(const Eigen::VectorXd& penalized, std::size_t begin,
                            const ZoneGuide& guide, const std::vector<bool>& tested) {
  Eigen::Index best = -1;
  for (Eigen::Index t = 0; t < penalized.size(); ++t) {
    if (std::isnan(penalized[t]) || (best >= 0 && penalized[t] <= penalized[best])) continue;
    const std::size_t at = begin + static_cast<std::size_t>(t);
    if (!guide.open(at)) continue;
    if (guide.restricted() && tested[static_cast<std::size_t>(guide.zoneOf(at))]) continue;
    best = t;
  }
  return best;
}

// ClaSP's own evidence (the significance at its argmax) decides whether the zone holds a
// changepoint; the zone's sensory event then says when (zone_anchors).
SplitCandidate candidateAt(const RangeProfile& r, std::size_t begin, std::size_t end,
                           Eigen::Index best, const ZoneGuide& guide) {
  SplitCandidate c;
  const Eigen::Index anchor = guide.anchorFor(r.penalized, begin, best);
  c.index = begin + static_cast<std::size_t>(anchor >= 0 ? anchor : best);
  c.profile_argmax = begin + static_cast<std::size_t>(best);
  c.anchored = anchor >= 0;
  c.range_begin = begin;
  c.range_end = end;
  c.score = r.penalized[best];
  c.log10_p_value = splitLog10P(r, static_cast<std::size_t>(best));
  return c;
}

// The best-first recursion: every range's significant candidate waits in a queue ordered by
// score; the best one splits its range, and both halves are searched again, as in claspy.
class ClaspRecursion {
 public:
  ClaspRecursion(const ProfileInputs& in, std::size_t n, MultivariateSegmentation* out)
      : in_(in), n_(n), out_(out), guide_(in.config, in.min_s, n) {}

  void run() {
    const bool learn = in_.config.num_changepoints < 0;
    const std::size_t max_cps = learn ? std::min(in_.config.max_changepoints, n_ / in_.min_s)
                                      : static_cast<std::size_t>(in_.config.num_changepoints);
    evaluate(0, n_, true);
    while (!queue_.empty() && out_->changepoints.size() < max_cps) acceptBest();
    std::sort(out_->changepoints.begin(), out_->changepoints.end());
  }

 private:
  struct Queued {
    double score;
    std::size_t candidate_index;  // into out_->candidates
    bool operator<(const Queued& o) const { return score < o.score; }
  };

  // Queues the range's significant candidate, if any.
  void evaluate(std::size_t begin, std::size_t end, bool first) {
    if (end - begin < 2 * in_.min_s + 1) return;
    const std::optional<RangeProfile> r = rangeProfile(in_, begin, end - begin);
    if (!r) return;
    if (first) recordFirstProfile(*r, out_);
    const std::optional<std::size_t> chosen = chooseCandidate(*r, begin, end);
    if (chosen) queue_.push({out_->candidates[*chosen].score, *chosen});
  }

  // Each zone is its own hypothesis: when the best in-zone split of the range is not significant,
  // the range's other zones are still tested (next best first). Every candidate examined is
  // recorded; returns the significant one's index in out_->candidates.
  std::optional<std::size_t> chooseCandidate(const RangeProfile& r, std::size_t begin,
                                             std::size_t end) {
    const bool learn = in_.config.num_changepoints < 0;
    std::vector<bool> tested = guide_.closedZones(begin, end, r.penalized);
    for (;;) {
      const Eigen::Index best = bestOpenSample(r.penalized, begin, guide_, tested);
      if (best < 0) return std::nullopt;
      const SplitCandidate c = candidateAt(r, begin, end, best, guide_);
      out_->candidates.push_back(c);
      const bool significant = !(learn && c.log10_p_value > guide_.neededLog10P(c.profile_argmax));
      if (significant) return out_->candidates.size() - 1;
      if (!guide_.restricted()) return std::nullopt;  // plain ClaSP: the range stays whole
      tested[static_cast<std::size_t>(guide_.zoneOf(c.profile_argmax))] = true;
    }
  }

  // Accepts the best queued candidate and searches both halves; a candidate whose zone was taken
  // meanwhile searches its range again instead.
  void acceptBest() {
    const std::size_t i = queue_.top().candidate_index;
    queue_.pop();
    const SplitCandidate c = out_->candidates[i];
    if (!guide_.claim(c.index)) {
      evaluate(c.range_begin, c.range_end, false);
      return;
    }
    out_->candidates[i].accepted = true;
    out_->changepoints.push_back(c.index);
    evaluate(c.range_begin, c.index, false);
    evaluate(c.index, c.range_end, false);
  }

  const ProfileInputs& in_;
  const std::size_t n_;
  MultivariateSegmentation* out_;
  ZoneGuide guide_;
  std::priority_queue<Queued> queue_;
};

// The result before any range is searched: no window, NaN combined profiles, zero per-feature
// ones (a feature left out of the combination keeps its zero profile).
MultivariateSegmentation emptyResult(std::size_t n, std::size_t num_features) {
  MultivariateSegmentation out;
  out.window_sizes.assign(num_features, 0);
  out.first_profile = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(n),
                                                std::numeric_limits<double>::quiet_NaN());
  out.first_profile_penalized = out.first_profile;
  out.first_feature_profiles.assign(num_features,
                                    Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n)));
  return out;
}

}  // namespace

MultivariateSegmentation segmentMultivariate(const Eigen::MatrixXd& features,
                                             const std::vector<double>& weights,
                                             const MultivariateSegmentationConfig& config) {
  checkInputs(features, weights, config);
  const std::size_t n = static_cast<std::size_t>(features.rows());
  const std::size_t num_features = static_cast<std::size_t>(features.cols());
  // Weights used both for the combination and to average the features' p-values.
  std::vector<double> w(num_features, 1.0);
  if (isWeighted(config.combination) && !weights.empty()) w = weights;

  MultivariateSegmentation out = emptyResult(n, num_features);
  const std::vector<std::size_t> active = activeFeatures(features, w, config, &out);
  out.min_segment_length = minSegmentLength(out, active, n, config);
  const std::size_t min_s = std::max<std::size_t>(out.min_segment_length, 1);
  if (active.empty() || n < 2 * min_s + 1) return out;
  const ProfileInputs in{features, w, active, out.window_sizes, min_s, config};
  ClaspRecursion(in, n, &out).run();
  return out;
}

}  // namespace lfd
