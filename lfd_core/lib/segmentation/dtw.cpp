#include "lfd_core/segmentation/dtw.hpp"
#include "lfd_core/util/parallel_for.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include <immintrin.h>  // usable without -mavx: the AVX2 sweep enables the ISA per function

// v8f values only pass between this file's internal inline functions: the GCC 4.6 note on the
// ABI of 32-byte vector arguments without AVX concerns no interface.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace lfd {

double DtwResult::distance() const {
  return std::sqrt(std::max(0.0, cost));
}

bool dtwInBand(long i, long j, long n, long m, int band) {
  if (band < 0) return true;
  const long radius = std::max<long>(band, std::labs(n - m));
  return std::labs(i - j) <= radius;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Largest direction matrix we allocate (bytes); beyond it the caller must use a band or costs.
constexpr std::size_t kMaxDirectionBytes = std::size_t(1) << 31;

void checkPair(const double* a, std::size_t n, const double* b, std::size_t m) {
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

// Traces the warping path back from cell (n-1, m-1) to (0, 0). step_at(i, j) gives the step
// that reached cell (i, j) for i, j > 0; the first row and column only step along themselves.
// Shared by the scalar direction matrix and the batched kernel's per-lane step bits.
template <typename StepAt>
void traceBack(long n, long m, StepAt step_at, WarpingPath& path) {
  path.clear();
  path.reserve(static_cast<std::size_t>(n + m));
  long i = n - 1, j = m - 1;
  while (i > 0 || j > 0) {
    path.emplace_back(static_cast<int>(i), static_cast<int>(j));
    const Step step = i == 0 ? kLeft : j == 0 ? kUp : step_at(i, j);
    if (step != kLeft) --i;
    if (step != kUp) --j;
  }
  path.emplace_back(0, 0);
  std::reverse(path.begin(), path.end());
}

// Columns [lo, hi] of row i that lie in the band (the whole row without a band).
std::pair<std::size_t, std::size_t> bandColumns(std::size_t i, std::size_t n, std::size_t m,
                                                int band) {
  if (band < 0) return {0, m - 1};
  const long radius = std::max<long>(band, std::labs(long(n) - long(m)));
  const long lo = std::max<long>(0, long(i) - radius);
  const long hi = std::min<long>(long(m) - 1, long(i) + radius);
  return {std::size_t(lo), std::size_t(hi)};
}

}  // namespace

double dtwCost(const double* a, std::size_t n, const double* b, std::size_t m,
               const DtwOptions& options) {
  checkPair(a, n, b, m);
  if (m > n) {  // the cost is symmetric: keep the rows short
    std::swap(a, b);
    std::swap(n, m);
  }
  std::vector<double> prev(m, kInf), cur(m, kInf);
  for (std::size_t i = 0; i < n; ++i) {
    const auto [lo, hi] = bandColumns(i, n, m, options.band);
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

double dtwCost(const std::vector<double>& a, const std::vector<double>& b,
               const DtwOptions& options) {
  return dtwCost(a.data(), a.size(), b.data(), b.size(), options);
}

DtwResult dtw(const double* a, std::size_t n, const double* b, std::size_t m,
              const DtwOptions& options) {
  checkPair(a, n, b, m);
  if (n * m > kMaxDirectionBytes) {
    throw std::invalid_argument("DTW path of " + std::to_string(n) + "x" + std::to_string(m) +
                                " cells needs too much memory; use a band or dtwCost");
  }
  std::vector<std::uint8_t> steps(n * m, kDiag);
  std::vector<double> prev(m, kInf), cur(m, kInf);
  for (std::size_t i = 0; i < n; ++i) {
    const auto [lo, hi] = bandColumns(i, n, m, options.band);
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
  const auto step_at = [&](long i, long j) { return Step(steps[std::size_t(i) * m + j]); };
  traceBack(long(n), long(m), step_at, result.path);
  return result;
}

DtwResult dtw(const std::vector<double>& a, const std::vector<double>& b,
              const DtwOptions& options) {
  return dtw(a.data(), a.size(), b.data(), b.size(), options);
}

std::pair<std::vector<double>, std::vector<double>> dtwAlignedPair(const double* a, const double* b,
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

double dtwPathCost(const double* a, const double* b, const WarpingPath& path) {
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

inline v8f splat(float x) {
  return v8f{x, x, x, x, x, x, x, x};
}

// GCC caps a vector type's alignment at what the ISA loads aligned: alignof(v8f) is 16 in this
// (baseline) file but 32 inside the AVX2 sweep, which then uses aligned 32-byte loads. Storage
// shared with the sweep is therefore this explicitly 32-byte aligned wrapper.
struct alignas(32) Lanes {
  v8f v;
};
static_assert(sizeof(Lanes) == sizeof(v8f), "Lanes arrays are v8f arrays");

// Reusable buffers of one worker thread.
struct Workspace {
  std::vector<Lanes> a, b, prev;
  std::vector<std::uint8_t> steps;  // [row][col][0:up bits, 1:left bits]
  std::vector<std::uint8_t> end_column;
};

// What the row sweep reads and writes, as raw pointers: the ISA-specific code below touches no
// STL or Eigen, so no inline function of theirs is ever emitted with AVX for the whole program.
struct SweepArgs {
  std::size_t padded_rows = 0, cols = 0;
  const v8f* a = nullptr;
  const v8f* b = nullptr;
  v8f* prev = nullptr;
  std::uint8_t* steps = nullptr;
  const std::uint8_t* end_column = nullptr;
  Lanes radius{};
  long max_radius = 0;
  const DtwPairView* const* lanes = nullptr;
  int used = 0;
  double* costs = nullptr;
};

// The sweep, compiled twice: for the baseline ISA (SSE2) and for AVX2, chosen at run time by
// the CPU (no -march flag in the build). AVX2 only, no FMA: both give bit-identical costs.
namespace baseline_isa {
#include "dtw_sweep.inc"
}  // namespace baseline_isa
#pragma GCC push_options
#pragma GCC target("avx2")
#define LFD_DTW_AVX2 1  // the pragma does not define __AVX__: select the intrinsics explicitly
namespace avx2_isa {
#include "dtw_sweep.inc"
}  // namespace avx2_isa
#undef LFD_DTW_AVX2
#pragma GCC pop_options

template <bool kPaths, bool kBand>
void sweepRows(const SweepArgs& args) {
  static const bool kHasAvx2 = __builtin_cpu_supports("avx2");
  if (kHasAvx2) {
    avx2_isa::sweepRows<kPaths, kBand>(args);
  } else {
    baseline_isa::sweepRows<kPaths, kBand>(args);
  }
}

// Interleaves a group's pairs into the lanes: a[i] lane k = pair k's a[i]; padding stays 0 (it
// never reaches a lane's end cell).
void interleave(const DtwPairView* const* lanes, int used, std::size_t padded_rows,
                std::size_t cols, Workspace& ws) {
  ws.a.assign(padded_rows, Lanes{splat(0.f)});
  ws.b.assign(cols, Lanes{splat(0.f)});
  ws.prev.assign(cols, Lanes{splat(INFINITY)});
  ws.end_column.assign(cols, 0);
  for (int k = 0; k < used; ++k) {
    const DtwPairView& p = *lanes[k];
    for (std::size_t i = 0; i < p.n; ++i) ws.a[i].v[k] = static_cast<float>(p.a[i]);
    for (std::size_t j = 0; j < p.m; ++j) ws.b[j].v[k] = static_cast<float>(p.b[j]);
    ws.end_column[p.m - 1] = 1;
  }
}

// Lane k's warping path (n x m cells), traced back through the sweep's step bits.
void lanePath(const std::uint8_t* steps, std::size_t cols, long n, long m, int k,
              WarpingPath& path) {
  const unsigned bit = 1u << k;
  const auto step_at = [&](long i, long j) {
    const std::uint8_t* s = steps + (std::size_t(i) * cols + std::size_t(j)) * 2;
    return (s[1] & bit) ? kLeft : (s[0] & bit) ? kUp : kDiag;
  };
  traceBack(n, m, step_at, path);
}

template <bool kPaths, bool kBand>
void runGroup(const DtwPairView* const* lanes, int used, int band, Workspace& ws, double* costs,
              WarpingPath* paths) {
  std::size_t rows = 0, cols = 0;
  for (int k = 0; k < used; ++k) {
    rows = std::max(rows, lanes[k]->n);
    cols = std::max(cols, lanes[k]->m);
  }
  const std::size_t padded_rows = (rows + kStripe - 1) / kStripe * kStripe;
  interleave(lanes, used, padded_rows, cols, ws);
  if (kPaths) {
    const std::size_t bytes = padded_rows * cols * 2;
    if (bytes > kMaxDirectionBytes) {
      throw std::invalid_argument("batched DTW paths of " + std::to_string(rows) + "x" +
                                  std::to_string(cols) + " cells need too much memory");
    }
    ws.steps.resize(bytes);
  }
  SweepArgs args;
  args.max_radius = long(rows + cols);  // no band: every column
  if (kBand) {
    args.max_radius = 0;
    for (int k = 0; k < used; ++k) {
      const long n = long(lanes[k]->n), m = long(lanes[k]->m);
      const long r = std::max<long>(band, std::labs(n - m));
      args.radius.v[k] = static_cast<float>(r);
      args.max_radius = std::max(args.max_radius, r);
    }
  }
  args.padded_rows = padded_rows;
  args.cols = cols;
  args.a = &ws.a.data()->v;
  args.b = &ws.b.data()->v;
  args.prev = &ws.prev.data()->v;
  args.steps = kPaths ? ws.steps.data() : nullptr;
  args.end_column = ws.end_column.data();
  args.lanes = lanes;
  args.used = used;
  args.costs = costs;
  sweepRows<kPaths, kBand>(args);

  if (kPaths) {
    for (int k = 0; k < used; ++k) {
      lanePath(ws.steps.data(), cols, long(lanes[k]->n), long(lanes[k]->m), k, paths[k]);
    }
  }
}

template <bool kPaths>
void runBatches(const std::vector<DtwPairView>& pairs, const DtwOptions& options, int threads,
                std::vector<double>& costs, std::vector<WarpingPath>* paths) {
  for (const DtwPairView& p : pairs) checkPair(p.a, p.n, p.b, p.m);
  // Group pairs of similar shapes so that lanes waste little padding.
  std::vector<std::size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return std::make_pair(pairs[x].n, pairs[x].m) > std::make_pair(pairs[y].n, pairs[y].m);
  });
  const std::size_t groups = (pairs.size() + kDtwLanes - 1) / kDtwLanes;
  costs.assign(pairs.size(), 0.0);
  if (paths) paths->assign(pairs.size(), {});
  // One workspace per worker thread: its buffers grow to the largest group and are reused.
  parallelForWithScratch<Workspace>(groups, threads, [&](std::size_t g, Workspace& ws) {
    const DtwPairView* lanes[kDtwLanes];
    double lane_costs[kDtwLanes] = {};
    WarpingPath lane_paths[kDtwLanes];
    const std::size_t first = g * kDtwLanes;
    const int used = static_cast<int>(std::min<std::size_t>(kDtwLanes, pairs.size() - first));
    for (int k = 0; k < used; ++k) lanes[k] = &pairs[order[first + k]];
    if (options.band >= 0) {
      runGroup<kPaths, true>(lanes, used, options.band, ws, lane_costs, lane_paths);
    } else {
      runGroup<kPaths, false>(lanes, used, options.band, ws, lane_costs, lane_paths);
    }
    for (int k = 0; k < used; ++k) {
      costs[order[first + k]] = lane_costs[k];
      if (paths) (*paths)[order[first + k]] = std::move(lane_paths[k]);
    }
  });
}

}  // namespace

std::vector<double> dtwCostBatch(const std::vector<DtwPairView>& pairs, const DtwOptions& options,
                                 int threads) {
  std::vector<double> costs;
  runBatches<false>(pairs, options, threads, costs, nullptr);
  return costs;
}

std::vector<DtwResult> dtwBatch(const std::vector<DtwPairView>& pairs, const DtwOptions& options,
                                int threads) {
  std::vector<double> costs;
  std::vector<WarpingPath> paths;
  runBatches<true>(pairs, options, threads, costs, &paths);
  std::vector<DtwResult> results(pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    results[p].cost = costs[p];
    results[p].path = std::move(paths[p]);
  }
  return results;
}

}  // namespace lfd
