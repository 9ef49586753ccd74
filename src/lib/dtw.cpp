#include "lfd_core/dtw.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>

#ifdef __AVX__
#include <immintrin.h>
#endif

namespace lfd {

double DtwResult::distance() const {
  return std::sqrt(std::max(0.0, cost));
}

bool dtw_in_band(long i, long j, long n, long m, int band) {
  if (band < 0) return true;
  const long radius = std::max<long>(band, std::labs(n - m));
  return std::labs(i - j) <= radius;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Largest direction matrix we allocate (bytes); beyond it the caller must use a band or costs.
constexpr std::size_t kMaxDirectionBytes = std::size_t(1) << 31;

void check_pair(const double* a, std::size_t n, const double* b, std::size_t m) {
  if (n == 0 || m == 0 || a == nullptr || b == nullptr) {
    throw std::invalid_argument("DTW needs two non-empty series (got lengths " + std::to_string(n) +
                                " and " + std::to_string(m) + ")");
  }
  if (n > (std::size_t(1) << 30) || m > (std::size_t(1) << 30)) {
    throw std::invalid_argument("DTW series too long");
  }
}

// Step codes of the scalar direction matrix.
enum Step : std::uint8_t { kDiag = 0, kUp = 1, kLeft = 2 };

WarpingPath backtrack(long n, long m, const std::uint8_t* steps /* n*m */) {
  WarpingPath path;
  path.reserve(static_cast<std::size_t>(n + m));
  long i = n - 1, j = m - 1;
  while (i > 0 || j > 0) {
    path.emplace_back(static_cast<int>(i), static_cast<int>(j));
    if (i == 0) {
      --j;
    } else if (j == 0) {
      --i;
    } else {
      const std::uint8_t s = steps[i * m + j];
      if (s == kLeft) {
        --j;
      } else if (s == kUp) {
        --i;
      } else {
        --i;
        --j;
      }
    }
  }
  path.emplace_back(0, 0);
  std::reverse(path.begin(), path.end());
  return path;
}

// Columns [lo, hi] of row i that lie in the band (the whole row without a band).
std::pair<std::size_t, std::size_t> band_columns(std::size_t i, std::size_t n, std::size_t m,
                                                 int band) {
  if (band < 0) return {0, m - 1};
  const long radius = std::max<long>(band, std::labs(long(n) - long(m)));
  const long lo = std::max<long>(0, long(i) - radius);
  const long hi = std::min<long>(long(m) - 1, long(i) + radius);
  return {std::size_t(lo), std::size_t(hi)};
}

}  // namespace

double dtw_cost(const double* a, std::size_t n, const double* b, std::size_t m,
                const DtwOptions& options) {
  check_pair(a, n, b, m);
  if (m > n) {  // the cost is symmetric: keep the rows short
    std::swap(a, b);
    std::swap(n, m);
  }
  std::vector<double> prev(m, kInf), cur(m, kInf);
  for (std::size_t i = 0; i < n; ++i) {
    const auto [lo, hi] = band_columns(i, n, m, options.band);
    std::fill(cur.begin(), cur.end(), kInf);  // cells outside the band stay infinite
    double left = kInf;
    double diag = i == 0 ? 0.0 : (lo > 0 ? prev[lo - 1] : kInf);
    const double ai = a[i];
    for (std::size_t j = lo; j <= hi; ++j) {
      const double up = prev[j];
      const double d = ai - b[j];
      const double value = d * d + std::min(std::min(diag, up), left);
      cur[j] = value;
      left = value;
      diag = up;
    }
    std::swap(prev, cur);
  }
  return prev[m - 1];
}

double dtw_cost(const std::vector<double>& a, const std::vector<double>& b,
                const DtwOptions& options) {
  return dtw_cost(a.data(), a.size(), b.data(), b.size(), options);
}

DtwResult dtw(const double* a, std::size_t n, const double* b, std::size_t m,
              const DtwOptions& options) {
  check_pair(a, n, b, m);
  if (n * m > kMaxDirectionBytes) {
    throw std::invalid_argument("DTW path of " + std::to_string(n) + "x" + std::to_string(m) +
                                " cells needs too much memory; use a band or dtw_cost");
  }
  std::vector<std::uint8_t> steps(n * m, kDiag);
  std::vector<double> prev(m, kInf), cur(m, kInf);
  for (std::size_t i = 0; i < n; ++i) {
    const auto [lo, hi] = band_columns(i, n, m, options.band);
    std::fill(cur.begin(), cur.end(), kInf);
    double left = kInf;
    double diag = i == 0 ? 0.0 : (lo > 0 ? prev[lo - 1] : kInf);
    const double ai = a[i];
    std::uint8_t* row_steps = steps.data() + i * m;
    for (std::size_t j = lo; j <= hi; ++j) {
      const double up = prev[j];
      const double d = ai - b[j];
      const double best_vertical = std::min(diag, up);
      std::uint8_t step = up < diag ? kUp : kDiag;
      double best = best_vertical;
      if (left < best_vertical) {
        step = kLeft;
        best = left;
      }
      row_steps[j] = step;
      const double value = d * d + best;
      cur[j] = value;
      left = value;
      diag = up;
    }
    std::swap(prev, cur);
  }
  DtwResult result;
  result.cost = prev[m - 1];
  result.path = backtrack(long(n), long(m), steps.data());
  return result;
}

DtwResult dtw(const std::vector<double>& a, const std::vector<double>& b,
              const DtwOptions& options) {
  return dtw(a.data(), a.size(), b.data(), b.size(), options);
}

std::pair<std::vector<double>, std::vector<double>> dtw_aligned_pair(const double* a,
                                                                     const double* b,
                                                                     const WarpingPath& path) {
  std::pair<std::vector<double>, std::vector<double>> out;
  out.first.reserve(path.size());
  out.second.reserve(path.size());
  for (const auto& [i, j] : path) {
    out.first.push_back(a[i]);
    out.second.push_back(b[j]);
  }
  return out;
}

double dtw_path_cost(const double* a, const double* b, const WarpingPath& path) {
  double cost = 0.0;
  for (const auto& [i, j] : path) cost += (a[i] - b[j]) * (a[i] - b[j]);
  return cost;
}

// ---------------------------------------------------------------------------------------------
// Batched kernel: 8 pairs per float vector. Rows are processed in stripes of 4 so that four
// independent dependency chains (each row's left-to-right recurrence) are in flight at once;
// the chain min+add latency would otherwise bound the throughput.
// ---------------------------------------------------------------------------------------------
namespace {

typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));
static_assert(kDtwLanes == 8, "kernel is written for 8 float lanes");
constexpr int kStripe = 4;

inline v8f vmin(v8f a, v8f b) {
#ifdef __AVX__
  return (v8f)_mm256_min_ps((__m256)a, (__m256)b);
#else
  return a < b ? a : b;
#endif
}

// Bit k set when a[k] < b[k].
inline unsigned lane_mask_lt(v8f a, v8f b) {
#ifdef __AVX__
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps((__m256)a, (__m256)b, _CMP_LT_OQ)));
#else
  const v8i lt = a < b;
  unsigned bits = 0;
  for (int k = 0; k < 8; ++k) bits |= (lt[k] ? 1u : 0u) << k;
  return bits;
#endif
}

inline v8f splat(float x) {
  return v8f{x, x, x, x, x, x, x, x};
}

struct LanePair {
  const DtwPairView* view = nullptr;  // null = unused lane
};

// Reusable buffers of one worker thread.
struct Workspace {
  std::vector<v8f> a, b, prev;
  std::vector<std::uint8_t> steps;  // [row][col][0:up bits, 1:left bits]
  std::vector<std::uint8_t> end_column;
};

template <bool kPaths, bool kBand>
void run_group(const DtwPairView* const* lanes, int used, int band, Workspace& ws, double* costs,
               WarpingPath* paths) {
  std::size_t rows = 0, cols = 0;
  for (int k = 0; k < used; ++k) {
    rows = std::max(rows, lanes[k]->n);
    cols = std::max(cols, lanes[k]->m);
  }
  const std::size_t padded_rows = (rows + kStripe - 1) / kStripe * kStripe;
  // Interleave: a[i][k] = lane k's a[i]; padding stays 0 (never reaches a lane's end cell).
  ws.a.assign(padded_rows, splat(0.f));
  ws.b.assign(cols, splat(0.f));
  ws.prev.assign(cols, splat(INFINITY));
  ws.end_column.assign(cols, 0);
  for (int k = 0; k < used; ++k) {
    const DtwPairView& p = *lanes[k];
    for (std::size_t i = 0; i < p.n; ++i) ws.a[i][k] = static_cast<float>(p.a[i]);
    for (std::size_t j = 0; j < p.m; ++j) ws.b[j][k] = static_cast<float>(p.b[j]);
    ws.end_column[p.m - 1] = 1;
  }
  if (kPaths) {
    const std::size_t bytes = padded_rows * cols * 2;
    if (bytes > kMaxDirectionBytes) {
      throw std::invalid_argument("batched DTW paths of " + std::to_string(rows) + "x" +
                                  std::to_string(cols) + " cells need too much memory");
    }
    ws.steps.resize(bytes);
  }
  v8f radius = splat(0.f);
  long max_radius = long(rows + cols);  // no band: every column
  if (kBand) {
    max_radius = 0;
    for (int k = 0; k < used; ++k) {
      const long n = long(lanes[k]->n), m = long(lanes[k]->m);
      const long r = std::max<long>(band, std::labs(n - m));
      radius[k] = static_cast<float>(r);
      max_radius = std::max(max_radius, r);
    }
  }
  const v8f inf = splat(INFINITY);
  v8f* const prev = ws.prev.data();
  const v8f* const bvec = ws.b.data();

  for (std::size_t i0 = 0; i0 < padded_rows; i0 += kStripe) {
    const v8f a0 = ws.a[i0], a1 = ws.a[i0 + 1], a2 = ws.a[i0 + 2], a3 = ws.a[i0 + 3];
    // Columns that lie in some lane's band for one of the stripe's rows. Outside them every
    // lane's cell is infinite; `prev` already holds row i0-1 there (or infinity, never written).
    const std::size_t j_begin = std::size_t(std::max<long>(0, long(i0) - max_radius));
    const std::size_t j_end =
        std::size_t(std::min<long>(long(cols), long(i0) + kStripe + max_radius));
    v8f left0 = inf, left1 = inf, left2 = inf, left3 = inf;                      // D[i][j-1]
    v8f diag0 = j_begin > 0 ? prev[j_begin - 1] : (i0 == 0 ? splat(0.f) : inf);  // D[i0-1][j-1]
    v8f lo0{}, lo1{}, lo2{}, lo3{}, hi0{}, hi1{}, hi2{}, hi3{};
    if (kBand) {
      lo0 = splat(float(i0)) - radius, hi0 = splat(float(i0)) + radius;
      lo1 = lo0 + 1.f, hi1 = hi0 + 1.f, lo2 = lo0 + 2.f, hi2 = hi0 + 2.f;
      lo3 = lo0 + 3.f, hi3 = hi0 + 3.f;
    }
    std::uint8_t* s0 = kPaths ? ws.steps.data() + (i0 * cols) * 2 : nullptr;
    std::uint8_t* s1 = s0 + (kPaths ? cols * 2 : 0);
    std::uint8_t* s2 = s1 + (kPaths ? cols * 2 : 0);
    std::uint8_t* s3 = s2 + (kPaths ? cols * 2 : 0);

    for (std::size_t j = j_begin; j < j_end; ++j) {
      const v8f b = bvec[j];
      const v8f up0 = prev[j];
      v8f jf{};
      if (kBand) jf = splat(float(j));
        // One cell of row r: out = c + min(diag, up, left), with the step bits for backtracking.
#define LFD_DTW_CELL(r, a_r, up, diag, left, out)                                \
  do {                                                                           \
    const v8f d = a_r - b;                                                       \
    const v8f vertical = vmin(diag, up);                                         \
    out = d * d + vmin(vertical, left);                                          \
    if (kBand) {                                                                 \
      const v8i ok = (jf >= lo##r) & (jf <= hi##r);                              \
      out = ok ? out : inf;                                                      \
    }                                                                            \
    if (kPaths) {                                                                \
      s##r[2 * j] = static_cast<std::uint8_t>(lane_mask_lt(up, diag));           \
      s##r[2 * j + 1] = static_cast<std::uint8_t>(lane_mask_lt(left, vertical)); \
    }                                                                            \
  } while (0)
      v8f out0, out1, out2, out3;
      LFD_DTW_CELL(0, a0, up0, diag0, left0, out0);
      LFD_DTW_CELL(1, a1, out0, left0, left1, out1);
      LFD_DTW_CELL(2, a2, out1, left1, left2, out2);
      LFD_DTW_CELL(3, a3, out2, left2, left3, out3);
#undef LFD_DTW_CELL
      diag0 = up0;
      left0 = out0, left1 = out1, left2 = out2, left3 = out3;
      prev[j] = out3;
      if (ws.end_column[j]) {
        const v8f stripe[kStripe] = {out0, out1, out2, out3};
        for (int k = 0; k < used; ++k) {
          const std::size_t end_row = lanes[k]->n - 1;
          if (lanes[k]->m - 1 == j && end_row >= i0 && end_row < i0 + kStripe) {
            costs[k] = stripe[end_row - i0][k];
          }
        }
      }
    }
  }

  if (kPaths) {
    for (int k = 0; k < used; ++k) {
      const long n = long(lanes[k]->n), m = long(lanes[k]->m);
      WarpingPath& path = paths[k];
      path.clear();
      path.reserve(static_cast<std::size_t>(n + m));
      long i = n - 1, j = m - 1;
      const unsigned bit = 1u << k;
      while (i > 0 || j > 0) {
        path.emplace_back(static_cast<int>(i), static_cast<int>(j));
        if (i == 0) {
          --j;
        } else if (j == 0) {
          --i;
        } else {
          const std::uint8_t* s = ws.steps.data() + (std::size_t(i) * cols + std::size_t(j)) * 2;
          if (s[1] & bit) {
            --j;
          } else if (s[0] & bit) {
            --i;
          } else {
            --i;
            --j;
          }
        }
      }
      path.emplace_back(0, 0);
      std::reverse(path.begin(), path.end());
    }
  }
}

template <bool kPaths>
void run_batches(const std::vector<DtwPairView>& pairs, const DtwOptions& options, int threads,
                 std::vector<double>& costs, std::vector<WarpingPath>* paths) {
  for (const DtwPairView& p : pairs) check_pair(p.a, p.n, p.b, p.m);
  // Group pairs of similar shapes so that lanes waste little padding.
  std::vector<std::size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return std::make_pair(pairs[x].n, pairs[x].m) > std::make_pair(pairs[y].n, pairs[y].m);
  });
  const std::size_t groups = (pairs.size() + kDtwLanes - 1) / kDtwLanes;
  costs.assign(pairs.size(), 0.0);
  if (paths) paths->assign(pairs.size(), {});
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::size_t>(threads, std::max<std::size_t>(groups, 1)));

  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::atomic<bool> failed{false};
  auto worker = [&]() {
    Workspace ws;
    try {
      for (std::size_t g = next++; g < groups && !failed; g = next++) {
        const DtwPairView* lanes[kDtwLanes];
        double lane_costs[kDtwLanes] = {};
        WarpingPath lane_paths[kDtwLanes];
        const std::size_t first = g * kDtwLanes;
        const int used = static_cast<int>(std::min<std::size_t>(kDtwLanes, pairs.size() - first));
        for (int k = 0; k < used; ++k) lanes[k] = &pairs[order[first + k]];
        if (options.band >= 0) {
          run_group<kPaths, true>(lanes, used, options.band, ws, lane_costs, lane_paths);
        } else {
          run_group<kPaths, false>(lanes, used, options.band, ws, lane_costs, lane_paths);
        }
        for (int k = 0; k < used; ++k) {
          costs[order[first + k]] = lane_costs[k];
          if (paths) (*paths)[order[first + k]] = std::move(lane_paths[k]);
        }
      }
    } catch (...) {
      if (!failed.exchange(true)) error = std::current_exception();
    }
  };
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace

std::vector<double> dtw_cost_batch(const std::vector<DtwPairView>& pairs, const DtwOptions& options,
                                   int threads) {
  std::vector<double> costs;
  run_batches<false>(pairs, options, threads, costs, nullptr);
  return costs;
}

std::vector<DtwResult> dtw_batch(const std::vector<DtwPairView>& pairs, const DtwOptions& options,
                                 int threads) {
  std::vector<double> costs;
  std::vector<WarpingPath> paths;
  run_batches<true>(pairs, options, threads, costs, &paths);
  std::vector<DtwResult> results(pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    results[p].cost = costs[p];
    results[p].path = std::move(paths[p]);
  }
  return results;
}

}  // namespace lfd
