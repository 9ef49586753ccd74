// Exact self-join k-NN of all subsequences (ClaSP's first stage).
//
// Every pair (i, j), j > i + exclusion_zone, is visited once. The dot product of the two
// subsequences is kept per diagonal d = j - i and advanced one row at a time in O(1)
// (qt(i, i+d) = qt(i-1, i-1+d) - x[i-1] x[i-1+d] + x[i+w-1] x[i+w-1+d]), so a row is one
// contiguous, vectorizable sweep. The similarity of a pair is written as
//   s(i, j) = qt * A_i A_j - B_i B_j + F_i F_j - C_i - C_j
// which covers both distances with per-subsequence constants:
//   z-normalized:  s = Pearson correlation (A = 1 / (sqrt(w) sigma), B = mu / sigma, C = 0);
//                  a flat subsequence (sigma ~ 0) has A = B = 0, F = 1: flat-flat pairs are
//                  identical (s = 1), flat-vs-varying pairs uncorrelated (s = 0).
//   Euclidean:     s = -d^2 = 2 qt - C_i - C_j with C_i = |x_i|^2 (A, B, F unused).
// Larger s = nearer. Each row keeps its k best in a tiny sorted array; a pair updates the row of i
// and the row of j. Exact ties (flat subsequences under z-normalization) go to the smaller index,
// as in claspy: identical subsequences then all vote for where the pattern first occurs, so a
// constant stretch gives a neutral profile instead of a perfect score for every split inside it
// (which "nearest in time" tie-breaking would produce).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_core/segmentation/clasp.hpp"

namespace lfd {
namespace {

// A subsequence whose std is below this fraction of the series' std is treated as constant:
// z-normalizing it would only amplify rounding noise.
constexpr double kFlatRelativeStd = 1e-4;

struct PairTerms {
  std::vector<double> a, b, c, f;
};

// Per-subsequence constants of the similarity formula (see file comment). `x` is mean-centred.
PairTerms pairTerms(const std::vector<double>& x, std::size_t w, ClaspDistance distance) {
  const std::size_t n = x.size();
  const std::size_t m = n - w + 1;
  PairTerms t;
  t.a.resize(m);
  t.b.assign(m, 0.0);
  t.c.assign(m, 0.0);
  t.f.assign(m, 0.0);
  std::vector<double> sum(n + 1, 0.0), sum_sq(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    sum[i + 1] = sum[i] + x[i];
    sum_sq[i + 1] = sum_sq[i] + x[i] * x[i];
  }
  if (distance == ClaspDistance::kEuclidean) {
    for (std::size_t i = 0; i < m; ++i) {
      t.a[i] = std::sqrt(2.0);
      t.c[i] = sum_sq[i + w] - sum_sq[i];
    }
    return t;
  }
  const double global_var = sum_sq[n] / static_cast<double>(n);  // x is centred
  const double flat_std = kFlatRelativeStd * std::sqrt(std::max(global_var, 0.0));
  const double wd = static_cast<double>(w);
  for (std::size_t i = 0; i < m; ++i) {
    const double mu = (sum[i + w] - sum[i]) / wd;
    const double var = std::max((sum_sq[i + w] - sum_sq[i]) / wd - mu * mu, 0.0);
    const double sigma = std::sqrt(var);
    if (sigma <= flat_std || sigma == 0.0) {
      t.a[i] = 0.0;
      t.f[i] = 1.0;
    } else {
      t.a[i] = 1.0 / (std::sqrt(wd) * sigma);
      t.b[i] = mu / sigma;
    }
  }
  return t;
}

double toDistance(double s, std::size_t w, ClaspDistance distance) {
  if (distance == ClaspDistance::kEuclidean) return std::sqrt(std::max(0.0, -s));
  return std::sqrt(std::max(0.0, 2.0 * static_cast<double>(w) * (1.0 - s)));
}

// Per-row sorted top-k lists (descending similarity). Kept as flat arrays for locality.
class TopK {
 public:
  TopK(std::size_t m, std::size_t k)
      : k_(k),
        score_(m * k, -std::numeric_limits<double>::infinity()),
        index_(m * k, -1),
        worst_(m, -std::numeric_limits<double>::infinity()) {}

  // Worst kept similarity of a row: a candidate below it can be skipped without a call.
  const double* worst() const { return worst_.data(); }
  double worst(std::size_t row) const { return worst_[row]; }

  void offer(std::size_t row, std::int32_t candidate, double s) {
    double* sc = &score_[row * k_];
    std::int32_t* ix = &index_[row * k_];
    const auto better = [](double s1, std::int32_t j1, double s2, std::int32_t j2) {
      if (s1 != s2) return s1 > s2;
      return j2 < 0 || j1 < j2;
    };
    if (!better(s, candidate, sc[k_ - 1], ix[k_ - 1])) return;
    std::size_t pos = k_ - 1;
    while (pos > 0 && better(s, candidate, sc[pos - 1], ix[pos - 1])) {
      sc[pos] = sc[pos - 1];
      ix[pos] = ix[pos - 1];
      --pos;
    }
    sc[pos] = s;
    ix[pos] = candidate;
    worst_[row] = ix[k_ - 1] < 0 ? -std::numeric_limits<double>::infinity() : sc[k_ - 1];
  }

  KnnResult finish(std::size_t w, std::size_t m, ClaspDistance distance) const {
    KnnResult r;
    r.window = w;
    r.k = k_;
    r.num_subsequences = m;
    r.indices = index_;
    r.distances.resize(score_.size());
    for (std::size_t i = 0; i < score_.size(); ++i)
      r.distances[i] = index_[i] < 0 ? std::numeric_limits<double>::infinity()
                                     : toDistance(score_[i], w, distance);
    return r;
  }

 private:
  std::size_t k_;
  std::vector<double> score_;
  std::vector<std::int32_t> index_;
  std::vector<double> worst_;
};

std::vector<double> centredCopy(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t window,
                                std::size_t k) {
  const std::size_t n = static_cast<std::size_t>(series.size());
  if (window < 2) throw std::invalid_argument("ClaSP k-NN: window must be >= 2");
  if (k < 1) throw std::invalid_argument("ClaSP k-NN: k must be >= 1");
  if (n < window + 1)
    throw std::invalid_argument("ClaSP k-NN: series of " + std::to_string(n) +
                                " samples is too short for window " + std::to_string(window));
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("ClaSP k-NN: series too long");
  if (!series.allFinite()) throw std::invalid_argument("ClaSP k-NN: series has NaN/Inf values");
  const double mean = series.mean();
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = series[static_cast<Eigen::Index>(i)] - mean;
  return x;
}

// s(i, j) from the dot product (see file comment), specialised per distance.
template <bool kZNorm>
inline double similarity(double qt, std::size_t i, std::size_t j, const PairTerms& t) {
  if (kZNorm) return qt * t.a[i] * t.a[j] - t.b[i] * t.b[j] + t.f[i] * t.f[j];
  return 2.0 * qt - t.c[i] - t.c[j];
}

// One row's sweep, as raw pointers: this is the code compiled for AVX2 as well as the baseline,
// so it holds no STL or Eigen (see DESIGN.md, Build-wide rules). Candidates that beat a row's
// k-th best go back through `offer` (rare: most blocks have none).
struct RowSweep {
  const double* x = nullptr;  // centred series
  std::size_t w = 0, m = 0, d0 = 0;
  const double *A = nullptr, *B = nullptr, *C = nullptr, *F = nullptr;
  double* q = nullptr;            // dot product per diagonal d, advanced row by row
  const double* worst = nullptr;  // k-th best similarity of every row (updated by offer)
  void (*offer)(void* top, std::size_t row, std::size_t candidate, double s) = nullptr;
  void* top = nullptr;
};

template <bool kZNorm>
inline __attribute__((always_inline)) void sweepRow(const RowSweep& r, std::size_t i) {
  constexpr std::size_t kBlock = 32;
  double block_sim[kBlock];
  const std::size_t d_end = r.m - i;  // j = i + d < m
  const double* xa = r.x;
  // Row i's dot products from row i-1's: drop x[i-1] x[i-1+d], add x[i+w-1] x[i+w-1+d]. Row 0
  // is already exact; zero factors (and in-range pointers) keep the loop branch-free.
  const double x_out = i > 0 ? xa[i - 1] : 0.0;
  const double x_in = i > 0 ? xa[i + r.w - 1] : 0.0;
  const double* out_row = i > 0 ? xa + i - 1 : xa;
  const double* in_row = i > 0 ? xa + i + r.w - 1 : xa;
  const double ai = r.A[i], bi = r.B[i], ci = r.C[i], fi = r.F[i];
  const double* Aj = r.A + i;
  const double* Bj = r.B + i;
  const double* Cj = r.C + i;
  const double* Fj = r.F + i;
  const double* worst_j = r.worst + i;
  double* q = r.q;
  // One fused, vectorizable sweep per block: advance the dot products, form the similarities
  // and test them against the k-th best of row i and of each row j. Candidates rarely beat
  // those, so most blocks end there. worst_i only grows: testing a block against its value at
  // the block start is conservative.
  for (std::size_t d_block = r.d0; d_block < d_end; d_block += kBlock) {
    const std::size_t len = d_end - d_block < kBlock ? d_end - d_block : kBlock;
    const double worst_i = r.worst[i];
    int hits = 0;
    for (std::size_t l = 0; l < len; ++l) {
      const std::size_t d = d_block + l;
      const double qd = q[d] + x_in * in_row[d] - x_out * out_row[d];
      q[d] = qd;
      const double v = kZNorm ? qd * ai * Aj[d] - bi * Bj[d] + fi * Fj[d] : 2.0 * qd - ci - Cj[d];
      block_sim[l] = v;
      hits |= static_cast<int>(v >= worst_i) | static_cast<int>(v >= worst_j[d]);
    }
    if (!hits) continue;
    for (std::size_t l = 0; l < len; ++l) {
      const std::size_t d = d_block + l;
      const double v = block_sim[l];
      if (v >= r.worst[i]) r.offer(r.top, i, i + d, v);
      if (v >= worst_j[d]) r.offer(r.top, i + d, i, v);
    }
  }
}

// Chosen per CPU at load time. AVX2 without FMA: both versions give bit-identical similarities.
__attribute__((target_clones("avx2", "default"))) void sweepRowZnorm(const RowSweep& r,
                                                                     std::size_t i) {
  sweepRow<true>(r, i);
}
__attribute__((target_clones("avx2", "default"))) void sweepRowEuclidean(const RowSweep& r,
                                                                         std::size_t i) {
  sweepRow<false>(r, i);
}

// Rows i = 0 .. m-1 of the upper triangle. `qt` holds row 0 on entry (diagonals >= d0).
void joinRows(const std::vector<double>& x, std::size_t w, std::size_t d0, const PairTerms& t,
              ClaspDistance distance, std::vector<double>& qt, TopK& top) {
  RowSweep r;
  r.x = x.data();
  r.w = w;
  r.m = x.size() - w + 1;
  r.d0 = d0;
  r.A = t.a.data();
  r.B = t.b.data();
  r.C = t.c.data();
  r.F = t.f.data();
  r.q = qt.data();
  r.worst = top.worst();
  r.top = &top;
  r.offer = [](void* top_list, std::size_t row, std::size_t candidate, double s) {
    static_cast<TopK*>(top_list)->offer(row, static_cast<std::int32_t>(candidate), s);
  };
  const bool znorm = distance != ClaspDistance::kEuclidean;
  for (std::size_t i = 0; i + d0 < r.m; ++i) {
    if (znorm) {
      sweepRowZnorm(r, i);
    } else {
      sweepRowEuclidean(r, i);
    }
  }
}

}  // namespace

KnnResult selfJoinKnn(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t window,
                      std::size_t k, std::size_t exclusion_zone, ClaspDistance distance) {
  const std::vector<double> x = centredCopy(series, window, k);
  const std::size_t n = x.size();
  const std::size_t w = window;
  const std::size_t m = n - w + 1;
  const PairTerms t = pairTerms(x, w, distance);
  TopK top(m, k);
  const std::size_t d0 = exclusion_zone + 1;  // smallest admissible diagonal
  if (d0 >= m) return top.finish(w, m, distance);

  // qt[d] = dot(x[i .. i+w), x[i+d .. i+d+w)) for the current row i; row 0 directly.
  std::vector<double> qt(m, 0.0);
  for (std::size_t d = d0; d < m; ++d) {
    double acc = 0.0;
    for (std::size_t l = 0; l < w; ++l) acc += x[l] * x[d + l];
    qt[d] = acc;
  }
  joinRows(x, w, d0, t, distance, qt, top);
  return top.finish(w, m, distance);
}

KnnResult bruteForceKnn(const Eigen::Ref<const Eigen::VectorXd>& series, std::size_t window,
                        std::size_t k, std::size_t exclusion_zone, ClaspDistance distance) {
  const std::vector<double> x = centredCopy(series, window, k);
  const std::size_t n = x.size();
  const std::size_t w = window;
  const std::size_t m = n - w + 1;
  const PairTerms t = pairTerms(x, w, distance);
  TopK top(m, k);
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t gap = i > j ? i - j : j - i;
      if (gap <= exclusion_zone) continue;
      double qt = 0.0;
      for (std::size_t l = 0; l < w; ++l) qt += x[i + l] * x[j + l];
      const double s = distance == ClaspDistance::kEuclidean ? similarity<false>(qt, i, j, t)
                                                             : similarity<true>(qt, i, j, t);
      top.offer(i, static_cast<std::int32_t>(j), s);
    }
  }
  return top.finish(w, m, distance);
}

}  // namespace lfd
