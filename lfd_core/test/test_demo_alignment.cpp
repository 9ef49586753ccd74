// Demos aligned on a common axis (demo_alignment.hpp): the uniform grid, multivariate DTW maps
// (free and anchored), the medoid, and the interpolation of a map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "lfd_core/segmentation/demo_alignment.hpp"

namespace {

// A two-feature curve at phase u in [0, 1] whose rows all differ (no ambiguity for DTW).
Eigen::RowVector2d curve(double u) {
  return {u + 0.3 * std::sin(2.0 * M_PI * u), std::cos(1.5 * M_PI * u)};
}

// The curve sampled on `rows` rows, stretched uniformly in time.
Eigen::MatrixXd sampled(int rows) {
  Eigen::MatrixXd m(rows, 2);
  for (int i = 0; i < rows; ++i) m.row(i) = curve(static_cast<double>(i) / (rows - 1));
  return m;
}

// ---- onUniformGrid

TEST(OnUniformGrid, InterpolatesLinearlyBetweenSamples) {
  const std::vector<double> time = {0.0, 0.5, 1.0, 2.0, 2.35};
  Eigen::MatrixXd features(5, 2);
  features << 0.0, 10.0,  //
      1.0, 10.0,          //
      0.0, 20.0,          //
      4.0, 20.0,          //
      5.0, 30.0;
  const Eigen::MatrixXd grid = lfd::onUniformGrid(features, time, 0.3);
  ASSERT_EQ(grid.rows(), 8);  // floor(2.35 / 0.3) + 1
  ASSERT_EQ(grid.cols(), 2);
  const std::vector<double> first = {0.0, 0.6, 0.8, 0.2, 0.8, 2.0, 3.2, 4.0 + 0.1 / 0.35};
  const std::vector<double> second = {10.0, 10.0, 12.0, 18.0, 20.0, 20.0, 20.0, 20.0 + 1.0 / 0.35};
  for (Eigen::Index k = 0; k < grid.rows(); ++k) {
    EXPECT_NEAR(grid(k, 0), first[static_cast<std::size_t>(k)], 1e-9) << "row " << k;
    EXPECT_NEAR(grid(k, 1), second[static_cast<std::size_t>(k)], 1e-9) << "row " << k;
  }
}

TEST(OnUniformGrid, StartsAtTheFirstTimestamp) {
  const std::vector<double> time = {10.0, 10.4, 11.0};
  Eigen::MatrixXd features(3, 1);
  features << 1.0, 2.0, 3.0;
  const Eigen::MatrixXd grid = lfd::onUniformGrid(features, time, 0.5);
  ASSERT_EQ(grid.rows(), 3);
  EXPECT_NEAR(grid(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(grid(1, 0), 2.0 + 0.1 / 0.6, 1e-9);
  EXPECT_NEAR(grid(2, 0), 3.0, 1e-12);
}

TEST(OnUniformGrid, ThrowsOnABadStepOrAMissingTimestamp) {
  const std::vector<double> time = {0.0, 1.0, 2.0};
  const Eigen::MatrixXd features = Eigen::MatrixXd::Ones(3, 1);
  EXPECT_THROW(lfd::onUniformGrid(features, time, 0.0), std::invalid_argument);
  EXPECT_THROW(lfd::onUniformGrid(features, time, -0.1), std::invalid_argument);
  EXPECT_THROW(lfd::onUniformGrid(features, {0.0, 1.0}, 0.1), std::invalid_argument);
}

// ---- multivariateDtwMap

TEST(MultivariateDtwMap, MapsEachRowNearItsStretchedPosition) {
  const Eigen::MatrixXd a = sampled(60);
  const Eigen::MatrixXd b = sampled(90);  // the same motion, 1.5 times slower
  const std::vector<double> map = lfd::multivariateDtwMap(a, b);
  ASSERT_EQ(map.size(), 60u);
  for (std::size_t i = 0; i < map.size(); ++i)
    EXPECT_NEAR(map[i], static_cast<double>(i) * 89.0 / 59.0, 2.0) << "row " << i;
  EXPECT_DOUBLE_EQ(map.front(), 0.0);
  EXPECT_DOUBLE_EQ(map.back(), 89.0);
}

TEST(MultivariateDtwMap, MapsIdenticalSeriesOnTheDiagonal) {
  const Eigen::MatrixXd a = sampled(40);
  const std::vector<double> map = lfd::multivariateDtwMap(a, a);
  ASSERT_EQ(map.size(), 40u);
  for (std::size_t i = 0; i < map.size(); ++i) EXPECT_DOUBLE_EQ(map[i], static_cast<double>(i));
  EXPECT_NEAR(lfd::multivariateDtwCost(a, a), 0.0, 1e-12);
}

TEST(MultivariateDtwMap, ThrowsOnDifferentFeatureCounts) {
  EXPECT_THROW(lfd::multivariateDtwMap(sampled(10), Eigen::MatrixXd::Zero(10, 3)),
               std::invalid_argument);
}

// ---- anchoredDtwMap

bool monotone(const std::vector<double>& map) {
  for (std::size_t i = 1; i < map.size(); ++i)
    if (map[i] < map[i - 1]) return false;
  return true;
}

TEST(AnchoredDtwMap, HoldsTheAnchorsExactlyAndIsMonotone) {
  const Eigen::MatrixXd a = sampled(60);
  const Eigen::MatrixXd b = sampled(90);
  // Free DTW puts row 20 near 30 and row 40 near 60; the anchors say 38 and 70.
  const std::vector<double> map = lfd::anchoredDtwMap(a, b, {20, 40}, {38, 70});
  ASSERT_EQ(map.size(), 60u);
  EXPECT_TRUE(monotone(map));
  EXPECT_DOUBLE_EQ(map[20], 38.0);
  EXPECT_DOUBLE_EQ(map[40], 70.0);
  // The anchors cut both series: rows before an anchor map before its partner.
  EXPECT_LT(map[19], 38.0);
  EXPECT_LT(map[39], 70.0);
  EXPECT_DOUBLE_EQ(map.front(), 0.0);
  EXPECT_DOUBLE_EQ(map.back(), 89.0);
}

TEST(AnchoredDtwMap, WithoutAnchorsEqualsTheFreeMap) {
  const Eigen::MatrixXd a = sampled(50), b = sampled(70);
  EXPECT_EQ(lfd::anchoredDtwMap(a, b, {}, {}), lfd::multivariateDtwMap(a, b));
}

TEST(AnchoredDtwMap, SkipsAnchorsOutOfOrderOrOutside) {
  const Eigen::MatrixXd a = sampled(60), b = sampled(90);
  const std::vector<double> one = lfd::anchoredDtwMap(a, b, {20}, {38});
  // (10, 50) goes back in a; (30, 20) goes back in b; (70, 80) lies outside a.
  const std::vector<double> skipped = lfd::anchoredDtwMap(a, b, {20, 10, 30, 70}, {38, 50, 20, 80});
  EXPECT_EQ(skipped, one);
  EXPECT_TRUE(monotone(skipped));
}

TEST(AnchoredDtwMap, ThrowsWhenTheAnchorListsDifferInLength) {
  EXPECT_THROW(lfd::anchoredDtwMap(sampled(20), sampled(30), {5, 10}, {7}), std::invalid_argument);
}

// ---- alignToMedoid

// An outlier (a curve unlike the others) first, then the same curve at three paces: taking the
// first demo would pick the outlier.
std::vector<Eigen::MatrixXd> outlierFirst() {
  Eigen::MatrixXd outlier(60, 2);
  for (int i = 0; i < 60; ++i) {
    const double u = i / 59.0;
    outlier.row(i) << 1.0 - u, 0.5 * std::sin(6.0 * M_PI * u);
  }
  return {outlier, sampled(50), sampled(60), sampled(75)};
}

TEST(AlignToMedoid, TheOutlierIsNotTheMedoid) {
  const std::vector<Eigen::MatrixXd> demos = outlierFirst();
  const lfd::DemoAlignment alignment = lfd::alignToMedoid(demos, 1);
  EXPECT_NE(alignment.reference, 0u);
  ASSERT_EQ(alignment.to_reference.size(), demos.size());
  ASSERT_EQ(alignment.from_reference.size(), demos.size());
  ASSERT_EQ(alignment.mean_cost.size(), demos.size());
  const std::size_t ref = alignment.reference;
  const auto ref_rows = static_cast<std::size_t>(demos[ref].rows());
  for (std::size_t d = 0; d < demos.size(); ++d) {
    EXPECT_EQ(alignment.to_reference[d].size(), static_cast<std::size_t>(demos[d].rows()));
    EXPECT_EQ(alignment.from_reference[d].size(), ref_rows);
    if (d != 0 && d != ref) {
      EXPECT_LT(alignment.mean_cost[d], alignment.mean_cost[0]);
    }
  }
  for (std::size_t i = 0; i < ref_rows; ++i)
    EXPECT_DOUBLE_EQ(alignment.to_reference[ref][i], static_cast<double>(i));
}

TEST(AlignToMedoid, ThrowsOnNoDemoOrDifferentFeatureCounts) {
  EXPECT_THROW(lfd::alignToMedoid({}, 1), std::invalid_argument);
  EXPECT_THROW(lfd::alignToMedoid({sampled(10), Eigen::MatrixXd::Zero(10, 3)}, 1),
               std::invalid_argument);
  EXPECT_THROW(lfd::alignToMedoid({sampled(10), Eigen::MatrixXd(0, 2)}, 1), std::invalid_argument);
}

TEST(ByDtwCostToOthers, TheMedoidFirstAndTheOutlierLast) {
  const std::vector<Eigen::MatrixXd> demos = outlierFirst();
  const std::vector<std::size_t> order = lfd::byDtwCostToOthers(demos, 1);
  ASSERT_EQ(order.size(), demos.size());
  EXPECT_EQ(order.back(), 0u);
  EXPECT_EQ(order.front(), lfd::alignToMedoid(demos, 1).reference);
  std::vector<std::size_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<std::size_t>{0, 1, 2, 3}));
}

TEST(AlignTo, MapsEveryDemoOntoTheGivenReference) {
  const std::vector<Eigen::MatrixXd> demos = {sampled(50), sampled(60), sampled(75)};
  const lfd::DemoAlignment alignment = lfd::alignTo(demos, 2, 1);
  EXPECT_EQ(alignment.reference, 2u);
  for (std::size_t d = 0; d < demos.size(); ++d) {
    ASSERT_EQ(alignment.to_reference[d].size(), static_cast<std::size_t>(demos[d].rows()));
    ASSERT_EQ(alignment.from_reference[d].size(), 75u);
    // The same motion at another pace: each end maps onto the reference's ends.
    EXPECT_NEAR(alignment.to_reference[d].front(), 0.0, 1.0);
    EXPECT_NEAR(alignment.to_reference[d].back(), 74.0, 1.0);
  }
  EXPECT_DOUBLE_EQ(alignment.mean_cost[2], 0.0);
  EXPECT_THROW(lfd::alignTo(demos, 3, 1), std::invalid_argument);
}

// A column one demo cannot fill (a dead sensor at rest while the others press in the middle third
// of the motion) is left out of that pair's alignment: the map is the one without it. With it,
// DTW squeezes the reference's press onto as few of the dead demo's rows as it can.
TEST(AlignTo, LeavesOutTheColumnsADemoCannotFill) {
  const std::vector<Eigen::MatrixXd> demos = {sampled(50), sampled(60), sampled(75)};
  std::vector<Eigen::MatrixXd> with_sensor;
  for (const Eigen::MatrixXd& d : demos) {
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(d.rows(), d.cols() + 1);
    m.leftCols(d.cols()) = d;
    m.col(d.cols()).segment(d.rows() / 3, d.rows() / 3).setConstant(10.0);  // the press
    with_sensor.push_back(m);
  }
  with_sensor[2].col(demos[2].cols()).setZero();  // dead, the slowest demo
  lfd::ColumnMasks masks(3, std::vector<bool>(with_sensor[0].cols(), true));
  masks[2].back() = false;
  const lfd::DemoAlignment masked = lfd::alignTo(with_sensor, 0, 1, 1.0, masks);
  const lfd::DemoAlignment plain = lfd::alignTo(demos, 0, 1);
  EXPECT_EQ(masked.to_reference[2], plain.to_reference[2]);
  EXPECT_NE(lfd::alignTo(with_sensor, 0, 1).to_reference[2], plain.to_reference[2]);
  masks[1].pop_back();
  EXPECT_THROW(lfd::alignTo(with_sensor, 0, 1, 1.0, masks), std::invalid_argument);
}

// ---- mapRow

TEST(MapRow, InterpolatesBetweenRowsAndClampsAtTheEnds) {
  const std::vector<double> map = {0.0, 2.0, 6.0};
  EXPECT_DOUBLE_EQ(lfd::mapRow(map, 0.5), 1.0);
  EXPECT_DOUBLE_EQ(lfd::mapRow(map, 1.25), 3.0);
  EXPECT_DOUBLE_EQ(lfd::mapRow(map, 1.0), 2.0);
  EXPECT_DOUBLE_EQ(lfd::mapRow(map, -1.0), 0.0);
  EXPECT_DOUBLE_EQ(lfd::mapRow(map, 2.0), 6.0);
  EXPECT_DOUBLE_EQ(lfd::mapRow(map, 7.5), 6.0);
}

}  // namespace
