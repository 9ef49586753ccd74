#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "lfd_core/segmentation/dtw.hpp"

namespace {

// Textbook O(nm) DTW on a full (n+1)x(m+1) matrix with an infinite border: the independent
// reference the optimized code is compared against.
double bruteForceCost(const std::vector<double>& a, const std::vector<double>& b, int band) {
  const std::size_t n = a.size(), m = b.size();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::vector<double>> D(n + 1, std::vector<double>(m + 1, inf));
  D[0][0] = 0.0;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      if (band >= 0) {
        const long radius = std::max<long>(band, std::labs(long(n) - long(m)));
        if (std::labs(long(i) - long(j)) > radius) continue;
      }
      const double c = (a[i - 1] - b[j - 1]) * (a[i - 1] - b[j - 1]);
      D[i][j] = c + std::min({D[i - 1][j - 1], D[i - 1][j], D[i][j - 1]});
    }
  }
  return D[n][m];
}

std::vector<double> randomSeries(std::mt19937& rng, std::size_t n) {
  std::normal_distribution<double> step(0.0, 0.1);
  std::vector<double> x(n);
  double v = 0.5;
  for (double& s : x) s = (v += step(rng));
  return x;
}

void expectValidPath(const lfd::WarpingPath& path, std::size_t n, std::size_t m, int band) {
  ASSERT_FALSE(path.empty());
  EXPECT_EQ(path.front(), std::make_pair(0, 0));
  EXPECT_EQ(path.back(), std::make_pair(int(n) - 1, int(m) - 1));
  for (std::size_t k = 1; k < path.size(); ++k) {
    const int di = path[k].first - path[k - 1].first;
    const int dj = path[k].second - path[k - 1].second;
    ASSERT_TRUE((di == 0 || di == 1) && (dj == 0 || dj == 1) && (di + dj > 0))
        << "step " << k << " is not monotone and continuous";
  }
  for (const auto& [i, j] : path) {
    ASSERT_TRUE(lfd::dtwInBand(i, j, long(n), long(m), band)) << "cell outside band";
  }
}

TEST(Dtw, IdenticalSeriesHaveZeroCostAndDiagonalPath) {
  const std::vector<double> a{0.0, 1.0, 2.0, 1.0, 0.0};
  const lfd::DtwResult r = lfd::dtw(a, a);
  EXPECT_DOUBLE_EQ(r.cost, 0.0);
  ASSERT_EQ(r.path.size(), a.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ(r.path[k], std::make_pair(int(k), int(k)));
}

TEST(Dtw, KnownSmallExample) {
  // b repeats the middle sample of a: optimal warping absorbs it at zero cost.
  const std::vector<double> a{0.0, 1.0, 0.0}, b{0.0, 1.0, 1.0, 0.0};
  EXPECT_DOUBLE_EQ(lfd::dtwCost(a, b), 0.0);
  const std::vector<double> c{0.0, 0.0, 0.0};
  EXPECT_DOUBLE_EQ(lfd::dtwCost(a, c), 1.0);
}

TEST(Dtw, EmptyInputThrows) {
  EXPECT_THROW(lfd::dtwCost({}, {1.0}), std::invalid_argument);
  EXPECT_THROW(lfd::dtw({1.0}, {}), std::invalid_argument);
  EXPECT_THROW(lfd::dtwBatch({lfd::DtwPairView{}}), std::invalid_argument);
}

TEST(Dtw, ScalarMatchesBruteForceWithAndWithoutBand) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> len(1, 60);
  for (int trial = 0; trial < 200; ++trial) {
    const auto a = randomSeries(rng, len(rng));
    const auto b = randomSeries(rng, len(rng));
    for (int band : {-1, 0, 3, 10}) {
      const double expected = bruteForceCost(a, b, band);
      EXPECT_NEAR(lfd::dtwCost(a, b, {band}), expected, 1e-9 * (1 + expected));
      const lfd::DtwResult r = lfd::dtw(a, b, {band});
      EXPECT_NEAR(r.cost, expected, 1e-9 * (1 + expected));
      expectValidPath(r.path, a.size(), b.size(), band);
      EXPECT_NEAR(lfd::dtwPathCost(a.data(), b.data(), r.path), expected, 1e-9 * (1 + expected));
    }
  }
}

TEST(Dtw, BatchMatchesScalarOnUnequalLengths) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> len(1, 90);
  std::vector<std::vector<double>> as, bs;
  for (int p = 0; p < 37; ++p) {  // not a multiple of the lane count: partial last group
    as.push_back(randomSeries(rng, len(rng)));
    bs.push_back(randomSeries(rng, len(rng)));
  }
  std::vector<lfd::DtwPairView> views;
  for (std::size_t p = 0; p < as.size(); ++p) {
    views.push_back({as[p].data(), as[p].size(), bs[p].data(), bs[p].size()});
  }
  for (int band : {-1, 0, 5}) {
    for (int threads : {1, 2}) {
      const auto costs = lfd::dtwCostBatch(views, {band}, threads);
      const auto results = lfd::dtwBatch(views, {band}, threads);
      ASSERT_EQ(costs.size(), views.size());
      for (std::size_t p = 0; p < views.size(); ++p) {
        const double expected = bruteForceCost(as[p], bs[p], band);
        const double tol = 1e-4 * (1 + expected);  // float lanes
        EXPECT_NEAR(costs[p], expected, tol) << "pair " << p << " band " << band;
        EXPECT_NEAR(results[p].cost, expected, tol) << "pair " << p << " band " << band;
        expectValidPath(results[p].path, as[p].size(), bs[p].size(), band);
        // The recovered path is optimal: its cost equals the optimum (up to float ties).
        EXPECT_NEAR(lfd::dtwPathCost(as[p].data(), bs[p].data(), results[p].path), expected, tol);
      }
    }
  }
}

TEST(Dtw, BatchHandlesSeriesMuchLongerThanTheirPartner) {
  // Rows beyond the column count once broke the column range of the unbanded kernel.
  std::mt19937 rng(5);
  std::vector<std::vector<double>> as, bs;
  for (int p = 0; p < 9; ++p) {
    as.push_back(randomSeries(rng, 150 + p));
    bs.push_back(randomSeries(rng, 10 + p));
  }
  std::vector<lfd::DtwPairView> views;
  for (int p = 0; p < 9; ++p)
    views.push_back({as[p].data(), as[p].size(), bs[p].data(), bs[p].size()});
  const auto results = lfd::dtwBatch(views);
  for (int p = 0; p < 9; ++p) {
    const double expected = bruteForceCost(as[p], bs[p], -1);
    EXPECT_NEAR(results[p].cost, expected, 1e-4 * (1 + expected)) << "pair " << p;
    expectValidPath(results[p].path, as[p].size(), bs[p].size(), -1);
  }
}

TEST(Dtw, BatchPathEqualsScalarPathWithoutTies) {
  // Continuous random values make ties improbable, so both implementations pick the same path.
  std::mt19937 rng(3);
  std::vector<double> a = randomSeries(rng, 300), b = randomSeries(rng, 250);
  const lfd::DtwResult scalar = lfd::dtw(a, b);
  const auto batch = lfd::dtwBatch({{a.data(), a.size(), b.data(), b.size()}});
  EXPECT_EQ(batch[0].path, scalar.path);
}

TEST(Dtw, AlignedPairFollowsPath) {
  const std::vector<double> a{0.0, 1.0, 0.0}, b{0.0, 1.0, 1.0, 0.0};
  const lfd::DtwResult r = lfd::dtw(a, b);
  const auto aligned = lfd::dtwAlignedPair(a.data(), b.data(), r.path);
  ASSERT_EQ(aligned.first.size(), r.path.size());
  EXPECT_EQ(aligned.first, aligned.second);  // zero-cost alignment: identical aligned signals
}

}  // namespace
