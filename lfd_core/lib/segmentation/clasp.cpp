// ClaSP classification score profile, significance test and univariate recursive segmentation.
//
// Labels follow claspy: at split s, subsequence i is truly "right" (1) iff i >= s, and predicted by
// the majority label of its k neighbours. The w subsequences [s - w, s) straddle the split (they
// start left of it but reach into the right part), so neither label is true for them. claspy forces
// their prediction to 1; that charges every split w false positives, a penalty of w / s on the
// true-negative rate that makes the profile lean towards the end of the series (and, with claspy's
// swapped AUC arguments, w / (n - s) towards its start). We leave them out of the score and of the
// significance test instead, so a clean change scores 1 wherever it lies.
// Score kRocAuc is the ROC-AUC of the hard predictions against the truth, i.e. the balanced
// accuracy (TPR + TNR) / 2 (the textbook definition; claspy's argument order yields
// (PPV + NPV) / 2).
#include "lfd_core/segmentation/clasp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double scoreFromConfusion(const std::size_t cm[2][2], ClaspScore score) {
  const double tn = static_cast<double>(cm[0][0]), fp = static_cast<double>(cm[0][1]);
  const double fn = static_cast<double>(cm[1][0]), tp = static_cast<double>(cm[1][1]);
  if (tp + fn == 0.0 || tn + fp == 0.0) return kNaN;  // one class is empty
  if (score == ClaspScore::kRocAuc) return 0.5 * (tp / (tp + fn) + tn / (tn + fp));
  const double f1_pos = 2.0 * tp / (2.0 * tp + fp + fn);
  const double f1_neg = 2.0 * tn / (2.0 * tn + fn + fp);
  return 0.5 * (f1_pos + f1_neg);
}

constexpr unsigned char kStraddles = 2;

// Predicted labels at one split (kStraddles for the subsequences that straddle it).
std::vector<unsigned char> predictedLabels(const KnnResult& knn, std::size_t split) {
  const std::size_t m = knn.num_subsequences, k = knn.k, w = knn.window;
  std::vector<unsigned char> pred(m, 0);
  for (std::size_t i = 0; i < m; ++i) {
    std::size_t ones = 0, valid = 0;
    for (std::size_t r = 0; r < k; ++r) {
      const std::int32_t j = knn.indices[i * k + r];
      if (j < 0) continue;
      ++valid;
      ones += static_cast<std::size_t>(j) >= split;
    }
    pred[i] = 2 * ones > valid;
    if (i < split && i + w >= split) pred[i] = kStraddles;
  }
  return pred;
}

// log10 of the two-sided normal tail 2 * (1 - Phi(|z|)), exact down to ~1e-300 and asymptotic
// beyond (erfc underflows there).
double log10TwoSidedP(double z) {
  const double x = std::abs(z) / std::sqrt(2.0);
  const double p = std::erfc(x);
  if (p > 1e-290) return std::log10(p);
  // erfc(x) ~ exp(-x^2) / (x sqrt(pi)) * (1 - 1 / (2 x^2))
  return (-x * x - std::log(x * std::sqrt(M_PI)) + std::log1p(-0.5 / (x * x))) / std::log(10.0);
}

}  // namespace

Eigen::VectorXd classificationScoreProfile(const KnnResult& knn, std::size_t min_split,
                                           ClaspScore score) {
  const std::size_t m = knn.num_subsequences, k = knn.k, w = knn.window;
  if (m == 0 || k == 0 || knn.indices.size() != m * k)
    throw std::invalid_argument("ClaSP profile: malformed k-NN result");
  if (k > 255) throw std::invalid_argument("ClaSP profile: k must be <= 255");
  const std::size_t n = m + w - 1;
  Eigen::VectorXd profile = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(n), kNaN);
  const std::size_t lo = std::max<std::size_t>(min_split, 1);
  if (n < min_split + 1) return profile;
  const std::size_t hi = std::min(n - min_split, m - 1);
  if (lo > hi) return profile;

  // Reverse adjacency (CSR): who has j among its neighbours.
  std::vector<std::size_t> start(m + 1, 0);
  for (std::int32_t j : knn.indices)
    if (j >= 0) ++start[static_cast<std::size_t>(j) + 1];
  for (std::size_t j = 0; j < m; ++j) start[j + 1] += start[j];
  std::vector<std::uint32_t> referrers(start[m]);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t r = 0; r < k; ++r) {
        const std::int32_t j = knn.indices[i * k + r];
        if (j >= 0) referrers[fill[static_cast<std::size_t>(j)]++] = static_cast<std::uint32_t>(i);
      }
  }

  std::size_t s = lo;
  std::vector<std::uint8_t> ones(m, 0), valid(m, 0);
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t r = 0; r < k; ++r) {
      const std::int32_t j = knn.indices[i * k + r];
      if (j < 0) continue;
      ++valid[i];
      ones[i] += static_cast<std::size_t>(j) >= s;
    }
  const auto truth = [](std::size_t i, std::size_t split) { return i >= split ? 1 : 0; };
  const auto straddles = [w](std::size_t i, std::size_t split) {
    return i < split && i + w >= split;
  };
  const auto pred = [&](std::size_t i) { return 2 * ones[i] > valid[i] ? 1 : 0; };
  std::size_t cm[2][2] = {{0, 0}, {0, 0}};
  // Straddling subsequences belong to neither side: they are left out of the confusion matrix.
  const auto add = [&](std::size_t i, std::size_t split, int delta) {
    if (!straddles(i, split)) cm[truth(i, split)][pred(i)] += static_cast<std::size_t>(delta);
  };
  for (std::size_t i = 0; i < m; ++i) add(i, s, 1);

  std::vector<std::size_t> stamp(m, 0);
  std::vector<std::size_t> affected;
  affected.reserve(2 + 4 * k);
  for (std::size_t step = 1;; ++step, ++s) {
    profile[static_cast<Eigen::Index>(s)] = scoreFromConfusion(cm, score);
    if (s == hi) break;
    // Moving to s + 1: s becomes left, s - w stops straddling, s's referrers lose a "right" vote.
    affected.clear();
    const auto touch = [&](std::size_t i) {
      if (stamp[i] != step) {
        stamp[i] = step;
        affected.push_back(i);
      }
    };
    touch(s);
    if (s >= w) touch(s - w);
    for (std::size_t e = start[s]; e < start[s + 1]; ++e) touch(referrers[e]);
    for (std::size_t a : affected) add(a, s, -1);
    for (std::size_t e = start[s]; e < start[s + 1]; ++e) --ones[referrers[e]];
    for (std::size_t a : affected) add(a, s + 1, 1);
  }
  return profile;
}

double splitLog10PValue(const KnnResult& knn, std::size_t split) {
  const std::size_t m = knn.num_subsequences;
  if (split == 0 || split >= m) return 0.0;  // one side empty: no evidence
  const std::vector<unsigned char> pred = predictedLabels(knn, split);
  // Wilcoxon rank-sum on binary data: all zeros share one mid-rank, all ones another.
  double zeros = 0.0, left_zeros = 0.0, left = 0.0, total = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    if (pred[i] == kStraddles) continue;
    total += 1.0;
    left += i < split;
    if (!pred[i]) {
      zeros += 1.0;
      if (i < split) left_zeros += 1.0;
    }
  }
  const double n1 = left, n2 = total - n1;
  if (n1 < 1.0 || n2 < 1.0) return 0.0;
  const double ones = total - zeros;
  const double rank_zero = (zeros + 1.0) / 2.0;
  const double rank_one = zeros + (ones + 1.0) / 2.0;
  const double rank_sum = left_zeros * rank_zero + (n1 - left_zeros) * rank_one;
  const double expected = n1 * (total + 1.0) / 2.0;
  const double sd = std::sqrt(n1 * n2 * (total + 1.0) / 12.0);
  return log10TwoSidedP((rank_sum - expected) / sd);
}

ClaspProfile computeClaspProfile(const Eigen::Ref<const Eigen::VectorXd>& series,
                                 const ClaspConfig& config) {
  const std::size_t n = static_cast<std::size_t>(series.size());
  if (!series.allFinite()) throw std::invalid_argument("ClaSP: series has NaN/Inf values");
  if (config.k < 1 || config.k > 255) throw std::invalid_argument("ClaSP: k must be in [1, 255]");
  if (!(config.exclusion_radius >= 0.0))
    throw std::invalid_argument("ClaSP: exclusion_radius must be >= 0");
  if (!(config.tie_jitter >= 0.0) || !std::isfinite(config.tie_jitter))
    throw std::invalid_argument("ClaSP: tie_jitter must be finite and >= 0");
  ClaspProfile out;
  out.window_size = config.window_size
                        ? config.window_size
                        : selectWindowSize(series, config.window_selection, config.min_window);
  const std::size_t w = out.window_size;
  out.min_segment_size = config.min_segment_size ? config.min_segment_size : 5 * w;
  if (w < 2 || n < 3 * w || n < 2 * out.min_segment_size + 1)
    throw std::invalid_argument(
        "ClaSP: series of " + std::to_string(n) + " samples is too short for window " +
        std::to_string(w) + " and minimum segment size " + std::to_string(out.min_segment_size));
  const auto exclusion = static_cast<std::size_t>(config.exclusion_radius * static_cast<double>(w));
  if (config.tie_jitter > 0.0) {
    const double range = series.maxCoeff() - series.minCoeff();
    std::mt19937 rng(0x5eed);  // fixed: the same series always gets the same profile
    std::normal_distribution<double> gauss(0.0, config.tie_jitter * (range > 0.0 ? range : 1.0));
    Eigen::VectorXd jittered = series;
    for (Eigen::Index i = 0; i < jittered.size(); ++i) jittered[i] += gauss(rng);
    out.knn = selfJoinKnn(jittered, w, config.k, exclusion, config.distance);
  } else {
    out.knn = selfJoinKnn(series, w, config.k, exclusion, config.distance);
  }
  out.profile = classificationScoreProfile(out.knn, out.min_segment_size, config.score);
  return out;
}

ClaspSegmentation claspSegment(const Eigen::Ref<const Eigen::VectorXd>& series,
                               const ClaspConfig& config, int num_changepoints) {
  const std::size_t n = static_cast<std::size_t>(series.size());
  if (!series.allFinite()) throw std::invalid_argument("ClaSP: series has NaN/Inf values");
  ClaspSegmentation out;
  out.first_profile = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(n), kNaN);
  if (n < 6) return out;
  ClaspConfig cfg = config;
  cfg.window_size = config.window_size
                        ? config.window_size
                        : selectWindowSize(series, config.window_selection, config.min_window);
  cfg.min_segment_size = config.min_segment_size ? config.min_segment_size : 5 * cfg.window_size;
  out.window_size = cfg.window_size;
  const bool learn = num_changepoints < 0;
  const std::size_t max_cps =
      learn ? n / cfg.min_segment_size : static_cast<std::size_t>(num_changepoints);

  struct Candidate {
    double score;
    std::size_t begin, end, cp;
    double log10_p;
    bool operator<(const Candidate& o) const { return score < o.score; }
  };
  std::priority_queue<Candidate> queue;
  // Profile of one range; pushes its best split if it may be split and (when learning) passes.
  const auto evaluate = [&](std::size_t begin, std::size_t end, bool first) {
    if (end - begin < 2 * cfg.min_segment_size + 1 || end - begin < 3 * cfg.window_size) return;
    const ClaspProfile p = computeClaspProfile(series.segment(begin, end - begin), cfg);
    if (first) out.first_profile = p.profile;
    Eigen::Index best = -1;
    for (Eigen::Index i = 0; i < p.profile.size(); ++i)
      if (!std::isnan(p.profile[i]) && (best < 0 || p.profile[i] > p.profile[best])) best = i;
    if (best < 0) return;
    const double log10_p = splitLog10PValue(p.knn, static_cast<std::size_t>(best));
    if (learn && log10_p > std::log10(cfg.p_value_threshold)) return;
    queue.push({p.profile[best], begin, end, begin + static_cast<std::size_t>(best), log10_p});
  };
  evaluate(0, n, true);
  std::vector<std::size_t> order;
  std::vector<Candidate> accepted;
  while (!queue.empty() && accepted.size() < max_cps) {
    const Candidate c = queue.top();
    queue.pop();
    accepted.push_back(c);
    evaluate(c.begin, c.cp, false);
    evaluate(c.cp, c.end, false);
  }
  std::sort(accepted.begin(), accepted.end(),
            [](const Candidate& a, const Candidate& b) { return a.cp < b.cp; });
  for (const Candidate& c : accepted) {
    out.changepoints.push_back(c.cp);
    out.scores.push_back(c.score);
    out.log10_p_values.push_back(c.log10_p);
  }
  return out;
}

}  // namespace lfd
