// Dynamic Time Warping (paper II-B): aligns two demonstrations of one feature before they are
// correlated.
//
// Definitions used everywhere in lfd:
//  * local cost  c(i,j) = (a[i] - b[j])^2
//  * steps       (i-1,j-1) diagonal, (i-1,j) "up" (a advances), (i,j-1) "left" (b advances)
//  * cost        D(n-1,m-1) = minimum over monotone, continuous, boundary-anchored warping
//                paths of the summed local costs; `distance` = sqrt(cost)
//  * band        Sakoe-Chiba radius r >= 0: cell (i,j) is allowed iff |i - j| <= max(r, |n - m|)
//                (widening by |n - m| keeps the end cell reachable for unequal lengths);
//                r < 0 means no band.
//  * ties        prefer diagonal, then up, then left (the same rule in the scalar and SIMD code).
//
// The scalar functions accumulate in double. The batched functions process up to 8 independent
// pairs in the lanes of one float vector (AVX when compiled with -march=native, a portable
// vector-extension fallback otherwise) and store the step choice as 2 bits per cell and pair for
// backtracking. float is accurate enough for the relevance workload: inputs are normalized to
// [0,1], so a cost of a few thousand cells carries a relative error of ~1e-6 and the
// correlations are computed afterwards in double on the recovered paths.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace lfd {

struct DtwOptions {
  int band = -1;  ///< Sakoe-Chiba radius in samples; < 0 = unconstrained
};

/// Warping path as (index into a, index into b) pairs from (0,0) to (n-1,m-1).
using WarpingPath = std::vector<std::pair<int, int>>;

struct DtwResult {
  double cost = 0.0;  ///< summed squared differences along the optimal path
  WarpingPath path;   ///< empty when only the distance was requested
  double distance() const;
};

/// Non-owning view of one pair of series to align.
struct DtwPairView {
  const double* a = nullptr;
  std::size_t n = 0;
  const double* b = nullptr;
  std::size_t m = 0;
};

/// True when cell (i,j) lies in the band for series of lengths n and m.
bool dtwInBand(long i, long j, long n, long m, int band);

/// Scalar DTW cost with memory linear in min(n,m) (two rows). Throws on empty input.
double dtwCost(const double* a, std::size_t n, const double* b, std::size_t m,
               const DtwOptions& options = {});
double dtwCost(const std::vector<double>& a, const std::vector<double>& b,
               const DtwOptions& options = {});

/// Scalar DTW with the warping path (direction matrix of n*m bytes).
DtwResult dtw(const double* a, std::size_t n, const double* b, std::size_t m,
              const DtwOptions& options = {});
DtwResult dtw(const std::vector<double>& a, const std::vector<double>& b,
              const DtwOptions& options = {});

/// Batched SIMD DTW over many independent pairs (lengths may differ; pairs of similar sizes are
/// grouped per vector). `threads` <= 0 uses the hardware concurrency. Results keep input order.
std::vector<double> dtwCostBatch(const std::vector<DtwPairView>& pairs,
                                 const DtwOptions& options = {}, int threads = 1);
std::vector<DtwResult> dtwBatch(const std::vector<DtwPairView>& pairs,
                                const DtwOptions& options = {}, int threads = 1);

/// The two signals resampled along a path: out.first[k] = a[path[k].first], and so on.
std::pair<std::vector<double>, std::vector<double>> dtwAlignedPair(const double* a, const double* b,
                                                                   const WarpingPath& path);

/// Summed local cost along a path (to check a path against its reported cost).
double dtwPathCost(const double* a, const double* b, const WarpingPath& path);

/// Number of lanes of the batched kernel (8 floats per vector).
constexpr int kDtwLanes = 8;

}  // namespace lfd
