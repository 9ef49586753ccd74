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
#include "lfd_core/multivariate_segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMinScoreForLog = 1e-12;

bool is_weighted(ProfileCombination c) {
  return c == ProfileCombination::kWeightedAverage || c == ProfileCombination::kWeightedProduct ||
         c == ProfileCombination::kWeightedDistanceAverage;
}

bool is_distance_average(ProfileCombination c) {
  return c == ProfileCombination::kDistanceAverage ||
         c == ProfileCombination::kWeightedDistanceAverage;
}

// Zeroth-order modified Bessel function of the first kind (power series; converges for all x).
double bessel_i0(double x) {
  double sum = 1.0, term = 1.0;
  const double q = 0.25 * x * x;
  for (int k = 1; k < 500; ++k) {
    term *= q / (static_cast<double>(k) * static_cast<double>(k));
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

}  // namespace

ProfileCombination parse_profile_combination(const std::string& name) {
  if (name == "average") return ProfileCombination::kAverage;
  if (name == "product") return ProfileCombination::kProduct;
  if (name == "weighted_average") return ProfileCombination::kWeightedAverage;
  if (name == "weighted_product") return ProfileCombination::kWeightedProduct;
  if (name == "distance_average") return ProfileCombination::kDistanceAverage;
  if (name == "weighted_distance_average") return ProfileCombination::kWeightedDistanceAverage;
  throw std::invalid_argument("unknown profile combination '" + name +
                              "' (average, product, weighted_average, weighted_product, "
                              "distance_average, weighted_distance_average)");
}

std::string to_string(ProfileCombination combination) {
  switch (combination) {
    case ProfileCombination::kAverage:
      return "average";
    case ProfileCombination::kProduct:
      return "product";
    case ProfileCombination::kWeightedAverage:
      return "weighted_average";
    case ProfileCombination::kWeightedProduct:
      return "weighted_product";
    case ProfileCombination::kDistanceAverage:
      return "distance_average";
    case ProfileCombination::kWeightedDistanceAverage:
      return "weighted_distance_average";
  }
  return "?";
}

Eigen::VectorXd combine_profiles(const std::vector<Eigen::VectorXd>& profiles,
                                 const std::vector<double>& weights,
                                 ProfileCombination combination) {
  if (profiles.empty()) throw std::invalid_argument("combine_profiles: no profiles");
  const Eigen::Index n = profiles.front().size();
  for (const auto& p : profiles)
    if (p.size() != n) throw std::invalid_argument("combine_profiles: profiles differ in length");
  std::vector<double> w(profiles.size(), 1.0);
  if (is_weighted(combination) && !weights.empty()) {
    if (weights.size() != profiles.size())
      throw std::invalid_argument("combine_profiles: " + std::to_string(weights.size()) +
                                  " weights for " + std::to_string(profiles.size()) + " profiles");
    w = weights;
  }
  double total = 0.0;
  for (double v : w) {
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument("combine_profiles: weights must be finite and >= 0");
    total += v;
  }
  if (!(total > 0.0)) throw std::invalid_argument("combine_profiles: weights sum to zero");
  const bool product = combination == ProfileCombination::kProduct ||
                       combination == ProfileCombination::kWeightedProduct;

  Eigen::VectorXd out(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    double acc = 0.0;
    bool defined = true;
    for (std::size_t f = 0; f < profiles.size() && defined; ++f) {
      const double p = profiles[f][t];
      if (std::isnan(p)) {
        defined = false;
      } else if (w[f] > 0.0) {
        acc += w[f] * (product ? std::log(std::max(p, kMinScoreForLog)) : p);
      }
    }
    out[t] = !defined ? kNaN : product ? std::exp(acc / total) : acc / total;
  }
  return out;
}

Eigen::VectorXd kaiser_window(std::size_t n, double beta) {
  if (!(beta >= 0.0) || !std::isfinite(beta))
    throw std::invalid_argument("kaiser_window: beta must be finite and >= 0");
  Eigen::VectorXd win(static_cast<Eigen::Index>(n));
  if (n == 1) {
    win[0] = 1.0;
    return win;
  }
  const double norm = bessel_i0(beta);
  for (std::size_t k = 0; k < n; ++k) {
    const double r = 2.0 * static_cast<double>(k) / static_cast<double>(n - 1) - 1.0;
    win[static_cast<Eigen::Index>(k)] =
        bessel_i0(beta * std::sqrt(std::max(0.0, 1.0 - r * r))) / norm;
  }
  return win;
}

MultivariateSegmentation segment_multivariate(const Eigen::MatrixXd& features,
                                              const std::vector<double>& weights,
                                              const MultivariateSegmentationConfig& config) {
  const std::size_t n = static_cast<std::size_t>(features.rows());
  const std::size_t num_features = static_cast<std::size_t>(features.cols());
  if (num_features == 0) throw std::invalid_argument("segment_multivariate: no feature columns");
  if (!features.allFinite())
    throw std::invalid_argument("segment_multivariate: features contain NaN/Inf values");
  if (!weights.empty() && weights.size() != num_features)
    throw std::invalid_argument("segment_multivariate: " + std::to_string(weights.size()) +
                                " weights for " + std::to_string(num_features) + " features");
  if (!config.window_sizes.empty() && config.window_sizes.size() != num_features)
    throw std::invalid_argument(
        "segment_multivariate: window_sizes must have one entry per feature");
  for (double v : weights)
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument("segment_multivariate: weights must be finite and >= 0");
  if (!(config.clasp.p_value_threshold > 0.0))
    throw std::invalid_argument("segment_multivariate: p_value_threshold must be > 0");
  if (!(config.zone_p_value_threshold >= 0.0 && config.zone_p_value_threshold < 1.0))
    throw std::invalid_argument("segment_multivariate: zone_p_value_threshold must be in [0, 1)");

  // Weights used both for the combination and to average the features' p-values.
  std::vector<double> w(num_features, 1.0);
  if (is_weighted(config.combination) && !weights.empty()) w = weights;

  MultivariateSegmentation out;
  out.window_sizes.assign(num_features, 0);
  out.first_profile = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(n), kNaN);
  out.first_profile_penalized = out.first_profile;
  out.first_feature_profiles.assign(num_features,
                                    Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n)));

  // Informative features: varying and with a positive weight.
  std::vector<std::size_t> active;
  for (std::size_t f = 0; f < num_features; ++f) {
    const auto col = features.col(static_cast<Eigen::Index>(f));
    const double range = n ? col.maxCoeff() - col.minCoeff() : 0.0;
    if (n < 6 || !(range > 1e-12 * (1.0 + col.cwiseAbs().maxCoeff())) || w[f] <= 0.0) continue;
    if (!config.window_sizes.empty()) {
      out.window_sizes[f] = config.window_sizes[f];
    } else if (config.clasp.window_size) {
      out.window_sizes[f] = config.clasp.window_size;
    } else {
      // Automatic windows are capped at n / 10 so that one slowly varying feature cannot push
      // the automatic min_s (2 x largest window) past what leaves room for a split.
      const std::size_t chosen =
          select_window_size(col, config.clasp.window_selection, config.clasp.min_window);
      out.window_sizes[f] = std::max<std::size_t>(2, std::min(chosen, n / 10));
    }
    if (out.window_sizes[f] < 2)
      throw std::invalid_argument("segment_multivariate: window size of feature " +
                                  std::to_string(f) + " must be >= 2");
    active.push_back(f);
  }
  std::size_t max_window = 0;
  for (std::size_t f : active) max_window = std::max(max_window, out.window_sizes[f]);
  out.min_segment_length =
      config.min_segment_length ? config.min_segment_length : std::max(2 * max_window, n / 20);
  const std::size_t min_s = std::max<std::size_t>(out.min_segment_length, 1);
  if (active.empty() || n < 2 * min_s + 1) return out;

  const bool learn = config.num_changepoints < 0;
  const std::size_t max_cps = learn ? std::min(config.max_changepoints, n / min_s)
                                    : static_cast<std::size_t>(config.num_changepoints);
  const double log10_threshold = std::log10(config.clasp.p_value_threshold);

  struct Queued {
    double score;
    std::size_t candidate_index;  // into out.candidates
    bool operator<(const Queued& o) const { return score < o.score; }
  };
  std::priority_queue<Queued> queue;

  // Zone-guided search: without anchors a zone marks one sensory interaction, hence at most one
  // changepoint; once a zone holds a changepoint it is closed to later candidates. With anchors
  // each changepoint sits on its own event, and zones closer than min_s merged into one can hold
  // several interactions (a short push: contact and release 2 s apart); the recursion's min_s
  // margins keep their changepoints apart.
  const std::vector<Interval> zones =
      config.candidate_zones_for ? config.candidate_zones_for(min_s) : config.candidate_zones;
  const bool restricted = config.candidate_zones_for || !zones.empty();  // no zone: no candidate
  const bool one_per_zone = config.zone_anchors.empty();
  std::vector<bool> zone_used(zones.size(), false);
  const auto zone_of = [&](std::size_t t) -> int {
    for (std::size_t z = 0; z < zones.size(); ++z)
      if (zones[z].contains(t)) return static_cast<int>(z);
    return -1;
  };
  const auto in_candidate_zone = [&](std::size_t t) {
    if (!restricted) return true;
    const int z = zone_of(t);
    return z >= 0 && !(one_per_zone && zone_used[static_cast<std::size_t>(z)]);
  };
  // The anchor (sensory event) of t's zone nearest to t, relative to `begin`; -1 = none.
  const auto anchor_for = [&](const Eigen::VectorXd& profile, std::size_t begin,
                              Eigen::Index t) -> Eigen::Index {
    if (!restricted) return -1;
    const int zone = zone_of(begin + static_cast<std::size_t>(t));
    Eigen::Index nearest = -1;
    bool nearest_preferred = false;
    for (std::size_t i = 0; i < config.zone_anchors.size(); ++i) {
      const std::size_t a = config.zone_anchors[i];
      if (a < begin || a >= begin + static_cast<std::size_t>(profile.size())) continue;
      const Eigen::Index rel = static_cast<Eigen::Index>(a - begin);
      if (zone_of(a) != zone || std::isnan(profile[rel])) continue;
      const bool preferred = i < config.preferred_anchors.size() && config.preferred_anchors[i];
      if (nearest >= 0 && nearest_preferred && !preferred) continue;
      if (nearest < 0 || (preferred && !nearest_preferred) ||
          std::abs(rel - t) < std::abs(nearest - t)) {
        nearest = rel;
        nearest_preferred = preferred;
      }
    }
    return nearest;
  };
  const double needed_log10_p = restricted && config.zone_p_value_threshold > 0.0
                                    ? std::log10(config.zone_p_value_threshold)
                                    : log10_threshold;
  // A zone around a preferred anchor (a rest edge) carries more evidence (rest_edge_p_value).
  std::vector<double> zone_needed(zones.size(), needed_log10_p);
  if (config.rest_edge_p_value_threshold > 0.0) {
    for (std::size_t i = 0; i < config.zone_anchors.size(); ++i) {
      const int z = zone_of(config.zone_anchors[i]);
      if (z >= 0 && i < config.preferred_anchors.size() && config.preferred_anchors[i])
        zone_needed[static_cast<std::size_t>(z)] =
            std::max(needed_log10_p, std::log10(config.rest_edge_p_value_threshold));
    }
  }
  const auto evaluate = [&](std::size_t begin, std::size_t end, bool first) {
    const std::size_t len = end - begin;
    if (len < 2 * min_s + 1) return;
    std::vector<Eigen::VectorXd> profiles;
    std::vector<KnnResult> knns;
    std::vector<double> used_weights;
    std::vector<std::size_t> used_features;
    for (std::size_t f : active) {
      const std::size_t wf = out.window_sizes[f];
      if (len < 3 * wf) continue;  // the sub-series is too short for this feature's window
      if (is_distance_average(config.combination)) {  // one joint k-NN below instead
        used_weights.push_back(w[f]);
        used_features.push_back(f);
        continue;
      }
      ClaspConfig cfg = config.clasp;
      cfg.window_size = wf;
      cfg.min_segment_size = min_s;
      ClaspProfile p = compute_clasp_profile(
          features.col(static_cast<Eigen::Index>(f))
              .segment(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(len)),
          cfg);
      profiles.push_back(std::move(p.profile));
      knns.push_back(std::move(p.knn));
      used_weights.push_back(w[f]);
      used_features.push_back(f);
    }
    if (used_features.empty()) return;
    if (is_distance_average(config.combination)) {
      // One k-NN over every usable feature at the largest of their windows (all must fit).
      std::size_t window = 0;
      for (std::size_t f : used_features) window = std::max(window, out.window_sizes[f]);
      std::vector<std::size_t> fitting;
      std::vector<double> fitting_weights;
      for (std::size_t i = 0; i < used_features.size(); ++i) {
        fitting.push_back(used_features[i]);
        fitting_weights.push_back(used_weights[i]);
      }
      if (len < 3 * window || len < 2 * min_s + 1) return;
      Eigen::MatrixXd block(static_cast<Eigen::Index>(len),
                            static_cast<Eigen::Index>(fitting.size()));
      for (std::size_t i = 0; i < fitting.size(); ++i)
        block.col(static_cast<Eigen::Index>(i)) =
            features.col(static_cast<Eigen::Index>(fitting[i]))
                .segment(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(len));
      KnnResult knn = distance_average_knn(
          block, fitting_weights, window, config.clasp.k,
          static_cast<std::size_t>(config.clasp.exclusion_radius * static_cast<double>(window)),
          config.clasp.distance);
      profiles.assign(1, classification_score_profile(knn, min_s, config.clasp.score));
      knns.assign(1, std::move(knn));
      used_weights.assign(1, 1.0);
      if (first) {  // per-feature profiles are not computed by this method
        for (auto& p : out.first_feature_profiles) p.setZero();
        used_features.clear();
      }
    }
    const Eigen::VectorXd combined =
        is_distance_average(config.combination)
            ? profiles[0]
            : combine_profiles(profiles, used_weights, config.combination);
    const Eigen::VectorXd penalized = combined.cwiseProduct(kaiser_window(len, config.kaiser_beta));
    if (first) {
      out.first_profile = combined;
      out.first_profile_penalized = penalized;
      for (std::size_t i = 0; i < used_features.size(); ++i)
        out.first_feature_profiles[used_features[i]] = profiles[i];
    }
    // Each zone is its own hypothesis: when the best in-zone split of this range is not
    // significant, the range's other zones are still tested (next best first).
    std::vector<bool> tested(zones.size(), false);
    // With anchors a zone is searched only while it holds an event ClaSP may split at (inside
    // this range and its min_s margins): its others sit on changepoints already.
    if (restricted && !one_per_zone) {
      std::vector<bool> anchored(zones.size(), false);
      for (std::size_t a : config.zone_anchors) {
        const int z = zone_of(a);
        if (z >= 0 && a >= begin && a < end &&
            !std::isnan(penalized[static_cast<Eigen::Index>(a - begin)]))
          anchored[static_cast<std::size_t>(z)] = true;
      }
      for (std::size_t z = 0; z < zones.size(); ++z) tested[z] = !anchored[z];
    }
    for (;;) {
      Eigen::Index best = -1;
      for (Eigen::Index t = 0; t < penalized.size(); ++t) {
        if (std::isnan(penalized[t]) || (best >= 0 && penalized[t] <= penalized[best])) continue;
        const std::size_t at = begin + static_cast<std::size_t>(t);
        if (!in_candidate_zone(at)) continue;
        if (restricted && tested[static_cast<std::size_t>(zone_of(at))]) continue;
        best = t;
      }
      if (best < 0) return;
      // ClaSP's own evidence (the significance at its argmax) decides whether the zone holds a
      // changepoint; the zone's sensory event then says when (zone_anchors).
      double weighted_log_p = 0.0, weight_sum = 0.0;
      for (std::size_t i = 0; i < knns.size(); ++i) {
        weighted_log_p +=
            used_weights[i] * split_log10_p_value(knns[i], static_cast<std::size_t>(best));
        weight_sum += used_weights[i];
      }
      SplitCandidate c;
      const Eigen::Index anchor = anchor_for(penalized, begin, best);
      c.index = begin + static_cast<std::size_t>(anchor >= 0 ? anchor : best);
      c.profile_argmax = begin + static_cast<std::size_t>(best);
      c.anchored = anchor >= 0;
      c.range_begin = begin;
      c.range_end = end;
      c.score = penalized[best];
      c.log10_p_value = weighted_log_p / weight_sum;
      out.candidates.push_back(c);
      const double needed = restricted
                                ? zone_needed[static_cast<std::size_t>(zone_of(c.profile_argmax))]
                                : needed_log10_p;
      // Outside zones a long demo needs more evidence (significance_per_sample): the rank-sum
      // test's log p grows with the number of subsequences for the same split quality.
      const double needed_here =
          restricted ? needed
                     : std::min(needed, -config.significance_per_sample * static_cast<double>(n));
      if (learn && c.log10_p_value > needed_here) {  // not significant
        if (!restricted) return;                     // plain ClaSP: the range stays whole
        tested[static_cast<std::size_t>(zone_of(c.profile_argmax))] = true;
        continue;
      }
      queue.push({c.score, out.candidates.size() - 1});
      return;
    }
  };

  evaluate(0, n, true);
  while (!queue.empty() && out.changepoints.size() < max_cps) {
    SplitCandidate& c = out.candidates[queue.top().candidate_index];
    queue.pop();
    if (restricted && one_per_zone) {
      const int z = zone_of(c.index);
      if (zone_used[static_cast<std::size_t>(z)]) {
        evaluate(c.range_begin, c.range_end, false);  // its zone was taken meanwhile: search again
        continue;
      }
      zone_used[static_cast<std::size_t>(z)] = true;
    }
    c.accepted = true;
    out.changepoints.push_back(c.index);
    const std::size_t cp = c.index, begin = c.range_begin, end = c.range_end;
    evaluate(begin, cp, false);  // may reallocate out.candidates: `c` is not used below
    evaluate(cp, end, false);
  }
  std::sort(out.changepoints.begin(), out.changepoints.end());
  return out;
}

}  // namespace lfd
