#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lfd_core/segmentation/feature_relevance.hpp"

namespace {

// Nine synthetic grasp-like demonstrations at different speeds. "gripper" (open -> closed at 40 %
// of the task) and "speed" (one bump per phase) have the same shape in every demo; the others are
// noise, a random walk, a ramp whose direction depends on the demo, and a constant.
std::vector<lfd::FeatureMatrix> makeDemos(unsigned seed, int count = 9) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<lfd::FeatureMatrix> demos;
  for (int d = 0; d < count; ++d) {
    const int n = 300 + 20 * d;
    lfd::FeatureMatrix m;
    m.names = {"noise_a", "gripper", "noise_b", "walk", "ramp", "speed", "constant", "noise_c"};
    m.data.resize(n, m.names.size());
    const double direction = uniform(rng);
    double walk = 0;
    for (int i = 0; i < n; ++i) {
      const double t = double(i) / (n - 1);
      m.time.push_back(i * 0.01);
      m.data(i, 0) = noise(rng);
      m.data(i, 1) = (t < 0.4 ? 0.08 : 0.0) + 0.001 * noise(rng);
      m.data(i, 2) = noise(rng);
      m.data(i, 3) = (walk += noise(rng));
      m.data(i, 4) = direction * t + 0.05 * noise(rng);
      const double phase = t < 0.4 ? t / 0.4 : (t - 0.4) / 0.6;
      m.data(i, 5) = std::sin(M_PI * phase) * (t < 0.4 ? 0.3 : 0.2) + 0.005 * noise(rng);
      m.data(i, 6) = 1.5;
      m.data(i, 7) = 0.1 * noise(rng);
    }
    demos.push_back(std::move(m));
  }
  return demos;
}

TEST(FeatureRelevance, PlantedConsistentFeaturesWinAndNoiseIsNotSelected) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto result = lfd::computeFeatureRelevance(makeDemos(seed));
    ASSERT_FALSE(result.selected.empty());
    const std::string best = result.selected.front();
    EXPECT_TRUE(best == "gripper" || best == "speed") << "seed " << seed << " best " << best;
    for (const std::string& name : result.selected) {
      EXPECT_TRUE(name == "gripper" || name == "speed") << "seed " << seed << " selected " << name;
    }
    for (const std::string& noise : {"noise_a", "noise_b", "noise_c", "walk", "constant"}) {
      EXPECT_FALSE(result.feature(noise).selected) << noise;
      EXPECT_LT(result.feature(noise).score, 0.5 * result.feature(best).score) << noise;
    }
    // The DTW weighting separates the planted features from the noise more than correlation alone
    // (paper Fig. 4): the gap to the best noise feature grows relative to the best score.
    const double best_corr = result.feature(best).mean_correlation;
    double noise_corr = -1, noise_score = -1;
    for (const std::string& noise : {"noise_a", "noise_b", "noise_c"}) {
      noise_corr = std::max(noise_corr, result.feature(noise).mean_correlation);
      noise_score = std::max(noise_score, result.feature(noise).score);
    }
    EXPECT_LT(noise_score / result.feature(best).score, noise_corr / best_corr);
  }
}

TEST(FeatureRelevance, MatricesAreSymmetricWithUnitDiagonalAndScoresFollowTheFormula) {
  const auto demos = makeDemos(5, 4);
  const auto result = lfd::computeFeatureRelevance(demos);
  ASSERT_EQ(result.features.size(), demos[0].names.size());
  double dmin = INFINITY, dmax = -INFINITY;
  for (const auto& f : result.features) {
    if (f.constant) continue;
    dmin = std::min(dmin, f.mean_distance), dmax = std::max(dmax, f.mean_distance);
  }
  for (const auto& f : result.features) {
    ASSERT_EQ(f.correlation.rows(), 4);
    EXPECT_TRUE(f.correlation.isApprox(f.correlation.transpose()));
    EXPECT_TRUE(f.distance.isApprox(f.distance.transpose()));
    for (int d = 0; d < 4; ++d) EXPECT_DOUBLE_EQ(f.correlation(d, d), 1.0);
    EXPECT_TRUE(std::isfinite(f.score));
    EXPECT_GE(f.mean_correlation, -1.0);
    EXPECT_LE(f.mean_correlation, 1.0);
    const double off_diagonal_mean = (f.correlation.sum() - 4.0) / 12.0;
    if (f.constant) continue;
    EXPECT_NEAR(f.mean_correlation, off_diagonal_mean, 1e-12);
    EXPECT_NEAR(f.normalized_distance, (f.mean_distance - dmin) / (dmax - dmin), 1e-12);
    EXPECT_NEAR(f.score, f.mean_correlation * (1 - f.normalized_distance), 1e-12);
  }
}

TEST(FeatureRelevance, ConstantFeatureIsFlaggedWithoutNaN) {
  const auto result = lfd::computeFeatureRelevance(makeDemos(4, 3));
  const auto& c = result.feature("constant");
  EXPECT_TRUE(c.constant);
  EXPECT_EQ(c.score, 0.0);
  EXPECT_FALSE(c.selected);
  EXPECT_FALSE(c.selected_correlation_only);
  EXPECT_FALSE(c.correlation.hasNaN());
  EXPECT_FALSE(result.warnings.empty());
}

TEST(FeatureRelevance, CorrelationOnlyVariantIsKeptSeparately) {
  const auto result = lfd::computeFeatureRelevance(makeDemos(6));
  ASSERT_FALSE(result.selected_correlation_only.empty());
  for (const auto& f : result.features) {
    EXPECT_EQ(
        f.selected_correlation_only,
        std::find(result.selected_correlation_only.begin(), result.selected_correlation_only.end(),
                  f.name) != result.selected_correlation_only.end());
  }
}

TEST(FeatureRelevance, BadInputGivesClearErrors) {
  auto demos = makeDemos(7, 3);
  EXPECT_THROW(lfd::computeFeatureRelevance({demos[0]}), std::invalid_argument);
  EXPECT_THROW(lfd::computeFeatureRelevance({}), std::invalid_argument);
  EXPECT_THROW(lfd::computeFeatureRelevance(demos, {"missing"}), std::invalid_argument);
  auto nan_demos = demos;
  nan_demos[1].data(10, 1) = std::nan("");
  try {
    lfd::computeFeatureRelevance(nan_demos);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gripper"), std::string::npos) << e.what();
  }
  lfd::FeatureRelevanceConfig bad_threshold;
  bad_threshold.threshold = 1.5;
  EXPECT_THROW(lfd::computeFeatureRelevance(demos, {}, bad_threshold), std::invalid_argument);
}

TEST(FeatureRelevance, SelectionThresholdKeepsFeaturesNearTheBest) {
  const std::vector<double> scores{0.5, 0.95, 1.0, 0.89, 0.91};
  const auto picked = lfd::selectByThreshold(scores, {}, 0.9);
  EXPECT_EQ(picked, (std::vector<std::size_t>{2, 1, 4}));
  EXPECT_EQ(lfd::selectByThreshold({-0.2, -0.1}, {}, 0.9), (std::vector<std::size_t>{1}));
  EXPECT_EQ(lfd::selectByThreshold({1.0, 0.95}, {true, false}, 0.9), (std::vector<std::size_t>{1}));
}

TEST(FeatureRelevance, PearsonOfConstantIsZero) {
  EXPECT_EQ(lfd::pearsonCorrelation({1, 1, 1}, {1, 2, 3}), 0.0);
  EXPECT_NEAR(lfd::pearsonCorrelation({1, 2, 3}, {2, 4, 6}), 1.0, 1e-12);
  EXPECT_NEAR(lfd::pearsonCorrelation({1, 2, 3}, {3, 2, 1}), -1.0, 1e-12);
}

}  // namespace
