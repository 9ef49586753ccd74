// ClaSP: k-NN exactness against brute force, incremental profile against direct recomputation,
// window selection, planted changepoints (1..3) and the stopping rule on stationary series.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lfd_core/segmentation/clasp.hpp"

namespace {

using lfd::ClaspConfig;
using lfd::ClaspDistance;
using lfd::ClaspScore;

// A regime of a synthetic piecewise series.
enum class Shape { kSine, kSquare, kSaw };
struct Regime {
  Shape shape;
  double period;
  double noise;
  std::size_t length;
};

Eigen::VectorXd piecewise(const std::vector<Regime>& regimes, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::size_t n = 0;
  for (const auto& r : regimes) n += r.length;
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  std::size_t t = 0;
  for (const auto& r : regimes) {
    for (std::size_t i = 0; i < r.length; ++i, ++t) {
      const double phase = 2.0 * M_PI * static_cast<double>(t) / r.period;
      double v = 0.0;
      switch (r.shape) {
        case Shape::kSine:
          v = std::sin(phase);
          break;
        case Shape::kSquare:
          v = std::sin(phase) >= 0.0 ? 1.0 : -1.0;
          break;
        case Shape::kSaw:
          v = std::fmod(static_cast<double>(t) / r.period, 1.0) * 2.0 - 1.0;
          break;
      }
      x[static_cast<Eigen::Index>(t)] = v + r.noise * gauss(rng);
    }
  }
  return x;
}

Eigen::VectorXd randomWalk(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  double v = 0.0;
  for (std::size_t i = 0; i < n; ++i) x[static_cast<Eigen::Index>(i)] = (v += gauss(rng));
  return x;
}

void expectSameKnn(const lfd::KnnResult& fast, const lfd::KnnResult& ref, bool check_indices) {
  ASSERT_EQ(fast.num_subsequences, ref.num_subsequences);
  ASSERT_EQ(fast.k, ref.k);
  for (std::size_t i = 0; i < fast.indices.size(); ++i) {
    EXPECT_NEAR(fast.distances[i], ref.distances[i], 1e-6 * (1.0 + ref.distances[i])) << i;
    if (check_indices) {
      EXPECT_EQ(fast.indices[i], ref.indices[i]) << "entry " << i;
    }
  }
}

TEST(ClaspKnn, MatchesBruteForceOnRandomWalks) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Eigen::VectorXd x = randomWalk(300 + 37 * seed, seed);
    for (std::size_t w : {5, 16, 31}) {
      const std::size_t excl = w / 2;
      for (auto dist : {ClaspDistance::kZNormalizedEuclidean, ClaspDistance::kEuclidean}) {
        const auto fast = lfd::selfJoinKnn(x, w, 3, excl, dist);
        const auto ref = lfd::bruteForceKnn(x, w, 3, excl, dist);
        expectSameKnn(fast, ref, true);
      }
    }
  }
}

TEST(ClaspKnn, BruteForceAgreesWithDirectZNormDistance) {
  // Independent check of the similarity algebra: recompute the reported distance from scratch.
  const Eigen::VectorXd x = randomWalk(200, 9);
  const std::size_t w = 12;
  const auto knn = lfd::selfJoinKnn(x, w, 3, w / 2);
  const auto znorm = [&](std::size_t i) {
    Eigen::VectorXd s = x.segment(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(w));
    const double mu = s.mean();
    const double sd = std::sqrt((s.array() - mu).square().mean());
    return Eigen::VectorXd((s.array() - mu) / sd);
  };
  for (std::size_t i = 0; i < knn.num_subsequences; i += 7) {
    const auto j = static_cast<std::size_t>(knn.neighbour(i, 0));
    EXPECT_GT(j > i ? j - i : i - j, w / 2);
    EXPECT_NEAR((znorm(i) - znorm(j)).norm(), knn.distances[i * 3], 1e-6);
  }
}

TEST(ClaspKnn, FlatStretchesAndTies) {
  // Piecewise constant (a gripper closing). Euclidean keeps the levels apart; z-normalized flats
  // are all identical and tie to the smallest index (claspy's rule).
  Eigen::VectorXd x = Eigen::VectorXd::Zero(400);
  x.tail(200).setConstant(1.0);
  const auto euclid = lfd::selfJoinKnn(x, 10, 3, 5, ClaspDistance::kEuclidean);
  for (std::size_t i = 0; i < 190; ++i)
    for (std::size_t r = 0; r < 3; ++r) EXPECT_LT(euclid.neighbour(i, r), 191) << i;
  for (std::size_t i = 200; i < euclid.num_subsequences; ++i)
    for (std::size_t r = 0; r < 3; ++r) EXPECT_GE(euclid.neighbour(i, r), 200) << i;
  const auto znorm = lfd::selfJoinKnn(x, 10, 3, 5);
  EXPECT_EQ(znorm.neighbour(300, 0), 0);
  EXPECT_EQ(znorm.neighbour(300, 2), 2);
  EXPECT_EQ(znorm.neighbour(0, 0), 6);  // first index beyond the exclusion zone
  EXPECT_NEAR(znorm.distances[300 * 3], 0.0, 1e-12);
}

TEST(ClaspKnn, RejectsBadInput) {
  Eigen::VectorXd x = randomWalk(50, 1);
  EXPECT_THROW(lfd::selfJoinKnn(x, 1, 3, 0), std::invalid_argument);
  EXPECT_THROW(lfd::selfJoinKnn(x, 60, 3, 0), std::invalid_argument);
  x[10] = std::nan("");
  EXPECT_THROW(lfd::selfJoinKnn(x, 5, 3, 2), std::invalid_argument);
}

// Direct O(m k) per split reference for the incremental profile.
double directScore(const lfd::KnnResult& knn, std::size_t s, ClaspScore score) {
  const std::size_t m = knn.num_subsequences, k = knn.k, w = knn.window;
  double tp = 0, tn = 0, fp = 0, fn = 0;
  for (std::size_t i = 0; i < m; ++i) {
    int ones = 0;
    for (std::size_t r = 0; r < k; ++r) ones += static_cast<std::size_t>(knn.neighbour(i, r)) >= s;
    const int pred = 2 * ones > static_cast<int>(k);
    if (i < s && i + w >= s) continue;  // straddles the split: neither label is true
    const int truth = i >= s;
    tp += truth && pred;
    tn += !truth && !pred;
    fp += !truth && pred;
    fn += truth && !pred;
  }
  if (score == ClaspScore::kRocAuc) return 0.5 * (tp / (tp + fn) + tn / (tn + fp));
  return 0.5 * (2 * tp / (2 * tp + fp + fn) + 2 * tn / (2 * tn + fp + fn));
}

TEST(ClaspProfile, IncrementalEqualsDirect) {
  const Eigen::VectorXd x =
      piecewise({{Shape::kSine, 20, 0.1, 250}, {Shape::kSquare, 35, 0.1, 250}}, 3);
  const auto knn = lfd::selfJoinKnn(x, 15, 3, 7);
  for (auto score : {ClaspScore::kRocAuc, ClaspScore::kMacroF1}) {
    const Eigen::VectorXd p = lfd::classificationScoreProfile(knn, 40, score);
    ASSERT_EQ(p.size(), x.size());
    EXPECT_TRUE(std::isnan(p[39]));
    EXPECT_TRUE(std::isnan(p[x.size() - 39]));
    for (std::size_t s = 40; s <= static_cast<std::size_t>(x.size()) - 40; ++s)
      EXPECT_NEAR(p[static_cast<Eigen::Index>(s)], directScore(knn, s, score), 1e-12) << s;
  }
}

TEST(ClaspWindow, SelectsWindowOnTheOrderOfThePeriod) {
  const Eigen::VectorXd x = piecewise({{Shape::kSine, 50, 0.05, 2000}}, 5);
  const std::size_t fft = lfd::dominantFourierWindowSize(x, 10);
  EXPECT_NEAR(static_cast<double>(fft), 50.0, 2.0);
  const std::size_t acf = lfd::autocorrelationWindowSize(x, 10);
  EXPECT_NEAR(static_cast<double>(acf), 50.0, 2.0);
  const std::size_t suss = lfd::sussWindowSize(x, 10);
  EXPECT_GE(suss, 10u);
  EXPECT_LE(suss, 100u);
  EXPECT_EQ(lfd::selectWindowSize(x, lfd::WindowSelection::kDominantFourier, 10), fft / 2);
}

struct PlantedCase {
  std::vector<Regime> regimes;
};

std::vector<std::size_t> truthOf(const std::vector<Regime>& regimes) {
  std::vector<std::size_t> cps;
  std::size_t t = 0;
  for (std::size_t i = 0; i + 1 < regimes.size(); ++i) cps.push_back(t += regimes[i].length);
  return cps;
}

void expectPlanted(const std::vector<Regime>& regimes, unsigned seed) {
  const Eigen::VectorXd x = piecewise(regimes, seed);
  const auto seg = lfd::claspSegment(x, ClaspConfig{});
  const auto truth = truthOf(regimes);
  ASSERT_EQ(seg.changepoints.size(), truth.size()) << "window " << seg.window_size;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(static_cast<double>(seg.changepoints[i]), static_cast<double>(truth[i]),
                static_cast<double>(seg.window_size))
        << "cp " << i << " window " << seg.window_size;
    EXPECT_LT(seg.log10_p_values[i], -15.0);
  }
}

TEST(ClaspSegment, FindsOnePlantedChangepoint) {
  expectPlanted({{Shape::kSine, 30, 0.1, 1200}, {Shape::kSine, 60, 0.1, 800}}, 11);
}

TEST(ClaspSegment, FindsTwoPlantedChangepoints) {
  expectPlanted(
      {{Shape::kSine, 40, 0.1, 900}, {Shape::kSquare, 40, 0.1, 700}, {Shape::kSaw, 25, 0.1, 900}},
      12);
}

TEST(ClaspSegment, FindsThreePlantedChangepoints) {
  expectPlanted({{Shape::kSine, 40, 0.05, 800},
                 {Shape::kSquare, 60, 0.05, 800},
                 {Shape::kSine, 20, 0.05, 800},
                 {Shape::kSaw, 30, 0.05, 800}},
                13);
}

// A change of noise level alone is found, but k-NN cannot place it sharply (noisy windows find
// clean neighbours): the profile has a broad plateau, hence the wider tolerance.
TEST(ClaspSegment, FindsANoiseLevelChange) {
  const std::vector<Regime> regimes = {{Shape::kSine, 20, 0.05, 1200},
                                       {Shape::kSine, 20, 0.6, 1200}};
  const auto seg = lfd::claspSegment(piecewise(regimes, 13), ClaspConfig{});
  ASSERT_EQ(seg.changepoints.size(), 1u);
  EXPECT_NEAR(static_cast<double>(seg.changepoints[0]), 1200.0, 10.0 * seg.window_size);
}

TEST(ClaspSegment, StationarySeriesHasNoChangepoint) {
  for (unsigned seed : {21u, 22u, 23u}) {
    const Eigen::VectorXd x = piecewise({{Shape::kSine, 40, 0.2, 3000}}, seed);
    const auto seg = lfd::claspSegment(x, ClaspConfig{});
    EXPECT_TRUE(seg.changepoints.empty()) << "seed " << seed << " cp " << seg.changepoints.front();
  }
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::VectorXd noise(3000);
  for (Eigen::Index i = 0; i < noise.size(); ++i) noise[i] = gauss(rng);
  EXPECT_TRUE(lfd::claspSegment(noise, ClaspConfig{}).changepoints.empty());
}

TEST(ClaspSegment, FixedCountReturnsThatManyChangepoints) {
  const Eigen::VectorXd x =
      piecewise({{Shape::kSine, 30, 0.1, 1000}, {Shape::kSquare, 60, 0.1, 1000}}, 4);
  const auto seg = lfd::claspSegment(x, ClaspConfig{}, 1);
  ASSERT_EQ(seg.changepoints.size(), 1u);
  EXPECT_NEAR(static_cast<double>(seg.changepoints[0]), 1000.0,
              static_cast<double>(seg.window_size));
  EXPECT_TRUE(lfd::claspSegment(x, ClaspConfig{}, 0).changepoints.empty());
}

// A perfectly separable change scores (almost) 1 wherever it lies: the straddling subsequences
// do not charge early splits more than late ones (claspy's forced labels would cap a change at
// 20% of the series near 1 - w / (2 s)).
TEST(ClaspProfile, CleanChangeIsNotPulledTowardsEitherEnd) {
  for (const std::size_t first : {400u, 1600u}) {
    const Eigen::VectorXd x =
        piecewise({{Shape::kSine, 25, 0.02, first}, {Shape::kSquare, 50, 0.02, 2000 - first}}, 31);
    ClaspConfig config;
    config.window_size = 25;
    const lfd::ClaspProfile p = lfd::computeClaspProfile(x, config);
    Eigen::Index best = -1;
    for (Eigen::Index i = 0; i < p.profile.size(); ++i)
      if (!std::isnan(p.profile[i]) && (best < 0 || p.profile[i] > p.profile[best])) best = i;
    EXPECT_NEAR(static_cast<double>(best), static_cast<double>(first), 25.0) << first;
    EXPECT_GT(p.profile[best], 0.97) << first;
  }
}

// A held signal (e.g. a gripper that closes once) has near-identical subsequences on each side of
// its step; without jitter their neighbours follow rounding-level drift, i.e. time proximity, and
// splits well inside the held stretch score as high as the step. Jitter puts the peak on the step.
TEST(ClaspProfile, TieJitterPutsThePeakOnTheStepOfAHeldSignal) {
  const Eigen::Index n = 1000, step = 400;
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = (i < step ? 0.08 : 0.01) + 1e-9 * double(i);
  ClaspConfig config;
  config.window_size = 20;
  config.distance = ClaspDistance::kEuclidean;
  config.tie_jitter = 0.01;
  const lfd::ClaspProfile p = lfd::computeClaspProfile(x, config);
  Eigen::Index best = -1;
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isnan(p.profile[i]) && (best < 0 || p.profile[i] > p.profile[best])) best = i;
  EXPECT_NEAR(static_cast<double>(best), static_cast<double>(step), 20.0);
  EXPECT_LT(p.profile[700], p.profile[best] - 0.05);  // deep inside the held stretch
  config.tie_jitter = -1.0;
  EXPECT_THROW(lfd::computeClaspProfile(x, config), std::invalid_argument);
}

TEST(ClaspSignificance, SeparatesRealFromRandomSplit) {
  const Eigen::VectorXd x =
      piecewise({{Shape::kSine, 30, 0.1, 1000}, {Shape::kSquare, 60, 0.1, 1000}}, 6);
  const auto knn = lfd::selfJoinKnn(x, 20, 3, 10);
  EXPECT_LT(lfd::splitLog10PValue(knn, 1000), -50.0);
  EXPECT_GT(lfd::splitLog10PValue(knn, 500), lfd::splitLog10PValue(knn, 1000));
  EXPECT_EQ(lfd::splitLog10PValue(knn, 0), 0.0);
}

TEST(ClaspConfigParsing, RoundTrips) {
  for (auto s : {"suss", "fft", "acf"}) EXPECT_EQ(lfd::toString(lfd::parseWindowSelection(s)), s);
  for (auto s : {"roc_auc", "f1"}) EXPECT_EQ(lfd::toString(lfd::parseClaspScore(s)), s);
  for (auto s : {"euclidean", "znorm_euclidean"})
    EXPECT_EQ(lfd::toString(lfd::parseClaspDistance(s)), s);
  EXPECT_THROW(lfd::parseClaspScore("accuracy"), std::invalid_argument);
}

}  // namespace
