// Multivariate ClaSP (paper II-C): profile combination arithmetic, Kaiser window, recovery of a
// changepoint carried by one feature among noise features, all four combinations, min_s.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "lfd_core/segmentation/multivariate_segmentation.hpp"

namespace {

using lfd::ProfileCombination;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::VectorXd vec(std::initializer_list<double> v) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double x : v) out[i++] = x;
  return out;
}

TEST(CombineProfiles, AllFourMethodsExact) {
  const std::vector<Eigen::VectorXd> p{vec({0.5, 0.9, kNaN}), vec({0.8, 0.4, 0.7})};
  const std::vector<double> w{3.0, 1.0};
  const auto avg = lfd::combineProfiles(p, w, ProfileCombination::kAverage);
  EXPECT_DOUBLE_EQ(avg[0], 0.65);
  EXPECT_DOUBLE_EQ(avg[1], 0.65);
  EXPECT_TRUE(std::isnan(avg[2]));  // undefined in one feature -> undefined
  const auto prod = lfd::combineProfiles(p, w, ProfileCombination::kProduct);
  EXPECT_NEAR(prod[0], std::sqrt(0.5 * 0.8), 1e-12);
  EXPECT_NEAR(prod[1], std::sqrt(0.9 * 0.4), 1e-12);
  const auto wavg = lfd::combineProfiles(p, w, ProfileCombination::kWeightedAverage);
  EXPECT_NEAR(wavg[0], (3 * 0.5 + 0.8) / 4, 1e-12);
  const auto wprod = lfd::combineProfiles(p, w, ProfileCombination::kWeightedProduct);
  EXPECT_NEAR(wprod[0], std::pow(0.5, 0.75) * std::pow(0.8, 0.25), 1e-12);
  EXPECT_NEAR(wprod[1], std::pow(0.9, 0.75) * std::pow(0.4, 0.25), 1e-12);
  // Unweighted methods ignore the weights; a zero weight removes a feature from weighted ones.
  EXPECT_DOUBLE_EQ(lfd::combineProfiles(p, {1.0, 0.0}, ProfileCombination::kWeightedProduct)[1],
                   0.9);
}

TEST(CombineProfiles, ProductStaysFiniteWithManyFeaturesAndZeros) {
  std::vector<Eigen::VectorXd> p(200, vec({1e-3, 0.0}));
  const auto prod = lfd::combineProfiles(p, {}, ProfileCombination::kProduct);
  EXPECT_NEAR(prod[0], 1e-3, 1e-12);  // a raw product would underflow to 0
  EXPECT_GT(prod[1], 0.0);            // zeros are clamped, not -inf in log space
}

TEST(CombineProfiles, RejectsBadInput) {
  const std::vector<Eigen::VectorXd> p{vec({0.5, 0.6}), vec({0.5})};
  EXPECT_THROW(lfd::combineProfiles(p, {}, ProfileCombination::kAverage), std::invalid_argument);
  const std::vector<Eigen::VectorXd> q{vec({0.5}), vec({0.5})};
  EXPECT_THROW(lfd::combineProfiles(q, {1.0}, ProfileCombination::kWeightedAverage),
               std::invalid_argument);
  EXPECT_THROW(lfd::combineProfiles(q, {1.0, -1.0}, ProfileCombination::kWeightedAverage),
               std::invalid_argument);
  EXPECT_THROW(lfd::combineProfiles(q, {0.0, 0.0}, ProfileCombination::kWeightedProduct),
               std::invalid_argument);
  EXPECT_THROW(lfd::combineProfiles({}, {}, ProfileCombination::kAverage), std::invalid_argument);
}

TEST(CombineProfiles, ParsesNames) {
  for (auto name : {"average", "product", "weighted_average", "weighted_product"})
    EXPECT_EQ(lfd::toString(lfd::parseProfileCombination(name)), name);
  EXPECT_THROW(lfd::parseProfileCombination("median"), std::invalid_argument);
}

TEST(KaiserWindow, ShapeAndKnownValues) {
  const auto k = lfd::kaiserWindow(101, 2.0);
  EXPECT_NEAR(k[50], 1.0, 1e-12);
  EXPECT_NEAR(k[0], 1.0 / 2.2795853023360673, 1e-9);  // 1 / I0(2)
  EXPECT_NEAR(k[100], k[0], 1e-12);
  for (Eigen::Index i = 0; i < 50; ++i) {
    EXPECT_LT(k[i], k[i + 1]);
    EXPECT_NEAR(k[i], k[100 - i], 1e-12);
  }
  // Stronger fades: the ends are 1 / I0(beta) (I0 values of scipy.special.i0).
  EXPECT_NEAR(lfd::kaiserWindow(11, 5.0)[0] * 27.239871823604442, 1.0, 1e-13);
  EXPECT_NEAR(lfd::kaiserWindow(11, 10.0)[10] * 2815.716628466254, 1.0, 1e-13);
  EXPECT_TRUE(lfd::kaiserWindow(10, 0.0).isOnes());
  EXPECT_THROW(lfd::kaiserWindow(10, -1.0), std::invalid_argument);
}

// Feature with a real changepoint at `cp`: a sine that turns into a square wave.
Eigen::VectorXd shapeChange(std::size_t n, std::size_t cp, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 0.05);
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  for (std::size_t t = 0; t < n; ++t) {
    const double s = std::sin(2.0 * M_PI * static_cast<double>(t) / 40.0);
    x[static_cast<Eigen::Index>(t)] = (t < cp ? s : (s >= 0 ? 1.0 : -1.0)) + g(rng);
  }
  return x;
}

// Feature with a changepoint in level and speed: slow drift, then a faster oscillation.
Eigen::VectorXd levelChange(std::size_t n, std::size_t cp, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 0.05);
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  for (std::size_t t = 0; t < n; ++t) {
    const double tt = static_cast<double>(t);
    x[static_cast<Eigen::Index>(t)] =
        (t < cp ? std::sin(2.0 * M_PI * tt / 70.0) : 2.0 + 0.5 * std::sin(2.0 * M_PI * tt / 25.0)) +
        g(rng);
  }
  return x;
}

Eigen::VectorXd noise(std::size_t n, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd x(static_cast<Eigen::Index>(n));
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = g(rng);
  return x;
}

TEST(MultivariateSegmentation, WeightedProductIgnoresLowWeightNoiseFeatures) {
  const std::size_t n = 2000, cp = 1100;
  int correct = 0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    std::mt19937 rng(seed);
    Eigen::MatrixXd f(n, 4);
    f.col(0) = shapeChange(n, cp, rng);
    f.col(1) = noise(n, rng);
    f.col(2) = noise(n, rng);
    f.col(3) = noise(n, rng);
    lfd::MultivariateSegmentationConfig config;  // weighted product, significance test
    const auto seg = lfd::segmentMultivariate(f, {1.0, 0.05, 0.05, 0.05}, config);
    ASSERT_EQ(seg.changepoints.size(), 1u) << "seed " << seed;
    correct += std::abs(static_cast<double>(seg.changepoints[0]) - cp) <= seg.window_sizes[0];
  }
  EXPECT_EQ(correct, 3);
}

TEST(MultivariateSegmentation, EveryCombinationFindsASharedChangepoint) {
  const std::size_t n = 2000, cp = 800;
  std::mt19937 rng(7);
  Eigen::MatrixXd f(n, 3);
  f.col(0) = shapeChange(n, cp, rng);
  f.col(1) = levelChange(n, cp, rng);
  f.col(2) = noise(n, rng);
  const std::vector<double> weights{1.0, 0.8, 0.1};
  for (auto method : {ProfileCombination::kAverage, ProfileCombination::kProduct,
                      ProfileCombination::kWeightedAverage, ProfileCombination::kWeightedProduct}) {
    lfd::MultivariateSegmentationConfig config;
    config.combination = method;
    const auto seg = lfd::segmentMultivariate(f, weights, config);
    ASSERT_FALSE(seg.changepoints.empty()) << lfd::toString(method);
    ASSERT_FALSE(seg.candidates.empty());
    EXPECT_TRUE(seg.candidates.front().accepted);
    EXPECT_NEAR(static_cast<double>(seg.candidates.front().index), static_cast<double>(cp), 40.0)
        << lfd::toString(method);
  }
}

TEST(MultivariateSegmentation, FirstProfilesArePenalizedByTheKaiserWindow) {
  const std::size_t n = 1500;
  std::mt19937 rng(3);
  Eigen::MatrixXd f(n, 2);
  f.col(0) = shapeChange(n, 700, rng);
  f.col(1) = levelChange(n, 700, rng);
  lfd::MultivariateSegmentationConfig config;
  config.kaiser_beta = 3.0;
  const auto seg = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(seg.first_profile.size(), static_cast<Eigen::Index>(n));
  const Eigen::VectorXd kaiser = lfd::kaiserWindow(n, 3.0);
  const std::size_t min_s = seg.min_segment_length;
  for (std::size_t t = 0; t < n; ++t) {
    const auto i = static_cast<Eigen::Index>(t);
    if (t < min_s || t > n - min_s) {
      EXPECT_TRUE(std::isnan(seg.first_profile[i])) << t;
    } else {
      ASSERT_FALSE(std::isnan(seg.first_profile[i])) << t;
      EXPECT_NEAR(seg.first_profile_penalized[i], seg.first_profile[i] * kaiser[i], 1e-12);
    }
  }
  EXPECT_EQ(seg.first_feature_profiles.size(), 2u);
}

TEST(MultivariateSegmentation, MinSegmentLengthIsEnforced) {
  const std::size_t n = 2000;
  std::mt19937 rng(5);
  Eigen::MatrixXd f(n, 2);
  f.col(0) = shapeChange(n, 1000, rng);
  f.col(1) = noise(n, rng);
  lfd::MultivariateSegmentationConfig config;
  config.num_changepoints = 6;  // force more splits than the data holds
  config.min_segment_length = 300;
  const auto seg = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_FALSE(seg.changepoints.empty());
  EXPECT_LE(seg.changepoints.size(), 6u);
  std::size_t previous = 0;
  for (std::size_t cp : seg.changepoints) {
    EXPECT_GE(cp - previous, 300u);
    previous = cp;
  }
  EXPECT_GE(n - previous, 300u);
  config.min_segment_length = 1000;  // no split leaves two segments of >= 1000 + 1
  EXPECT_TRUE(lfd::segmentMultivariate(f, {1.0, 1.0}, config).changepoints.empty());
}

// Two features, each with its own changepoint: a level change at 600, a shape change at 1300.
Eigen::MatrixXd changesAt600And1300() {
  const std::size_t n = 2000;
  std::mt19937 rng(4);
  Eigen::MatrixXd f(n, 2);
  f.col(0) = shapeChange(n, 1300, rng);
  f.col(1) = levelChange(n, 600, rng);
  return f;
}

TEST(MultivariateSegmentation, CandidateZonesRestrictTheArgmax) {
  const Eigen::MatrixXd f = changesAt600And1300();
  lfd::MultivariateSegmentationConfig config;
  config.num_changepoints = 1;
  const auto free = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(free.changepoints.size(), 1u);
  // Only allow the zone around the other changepoint: the argmax must come from inside it.
  const bool first_at_600 = std::abs(static_cast<double>(free.changepoints[0]) - 600.0) < 100.0;
  const lfd::Interval zone = first_at_600 ? lfd::Interval{1200, 1400} : lfd::Interval{500, 700};
  config.candidate_zones = {zone};
  const auto zoned = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(zoned.changepoints.size(), 1u);
  EXPECT_TRUE(zone.contains(zoned.changepoints[0])) << zoned.changepoints[0];
  Eigen::Index best = static_cast<Eigen::Index>(zone.begin);
  for (auto t = static_cast<Eigen::Index>(zone.begin); t <= static_cast<Eigen::Index>(zone.end);
       ++t)
    if (zoned.first_profile_penalized[t] > zoned.first_profile_penalized[best]) best = t;
  EXPECT_EQ(zoned.changepoints[0], static_cast<std::size_t>(best));
}

// A zone marks one sensory interaction: however many changepoints are asked for, a zone holds at
// most one, and a zone-less demonstration (callback returning nothing) gets none.
TEST(MultivariateSegmentation, EachZoneHoldsAtMostOneChangepoint) {
  const Eigen::MatrixXd f = changesAt600And1300();
  lfd::MultivariateSegmentationConfig config;
  config.num_changepoints = 4;
  config.min_segment_length = 100;
  const std::vector<lfd::Interval> zones{{450, 750}, {1150, 1450}};
  std::size_t seen_min_s = 0;
  config.candidate_zones_for = [&](std::size_t min_s) {
    seen_min_s = min_s;
    return zones;
  };
  const auto seg = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  EXPECT_EQ(seen_min_s, 100u);
  ASSERT_EQ(seg.changepoints.size(), 2u);
  EXPECT_TRUE(zones[0].contains(seg.changepoints[0])) << seg.changepoints[0];
  EXPECT_TRUE(zones[1].contains(seg.changepoints[1])) << seg.changepoints[1];

  config.candidate_zones_for = [](std::size_t) { return std::vector<lfd::Interval>{}; };
  const auto none = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  EXPECT_TRUE(none.changepoints.empty());
  EXPECT_FALSE(std::isnan(none.first_profile[1000]));  // profiles are still reported
}

// A noisy change whose ClaSP evidence (p ~ 1e-9) misses the strict threshold is kept inside a
// sensory zone when the zone threshold is looser, and never outside a zone.
TEST(MultivariateSegmentation, ZoneThresholdAcceptsWeakerInZoneEvidence) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 600, cp = 300;
  Eigen::MatrixXd f(n, 1);
  for (int t = 0; t < n; ++t) {
    const double s = std::sin(2.0 * M_PI * t / 40.0);
    f(t, 0) = (t < cp ? s : (s >= 0 ? 1.0 : -1.0)) + g(rng);
  }
  lfd::MultivariateSegmentationConfig config;
  config.window_sizes = {20};
  config.min_segment_length = 60;
  config.candidate_zones = {{250, 350}};
  EXPECT_TRUE(lfd::segmentMultivariate(f, {1.0}, config).changepoints.empty());
  config.zone_p_value_threshold = 1e-5;
  const auto seg = lfd::segmentMultivariate(f, {1.0}, config);
  ASSERT_EQ(seg.changepoints.size(), 1u);
  EXPECT_NEAR(static_cast<double>(seg.changepoints[0]), cp, 25.0);
  config.zone_p_value_threshold = 1.0;
  EXPECT_THROW(lfd::segmentMultivariate(f, {1.0}, config), std::invalid_argument);
}

// The whole series' in-zone argmax is a weak change in the middle (where the Kaiser window does not
// penalize): not significant enough. The other zone, with a strong change near the end, is still
// tested and holds a changepoint; one insignificant zone does not close the others.
TEST(MultivariateSegmentation, AnInsignificantZoneDoesNotCloseTheOthers) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 1500, weak = 750, strong = 1300;
  Eigen::MatrixXd f(n, 1);
  for (int t = 0; t < n; ++t) {
    const double s = std::sin(2.0 * M_PI * t / 40.0);
    f(t, 0) = (t < weak ? s : (s >= 0 ? 1.0 : -1.0)) + g(rng) + (t < strong ? 0.0 : 4.0);
  }
  lfd::MultivariateSegmentationConfig config;
  config.window_sizes = {20};
  config.min_segment_length = 60;
  config.candidate_zones = {{weak - 50, weak + 50}, {strong - 50, strong + 50}};
  config.kaiser_beta = 6.0;  // a strong fade: the end's change ranks below the middle's
  config.zone_p_value_threshold = 1e-40;  // the middle's split (1e-25) is not enough
  const auto seg = lfd::segmentMultivariate(f, {1.0}, config);
  ASSERT_GE(seg.candidates.size(), 2u);
  EXPECT_TRUE(config.candidate_zones[0].contains(seg.candidates[0].index));
  EXPECT_FALSE(seg.candidates[0].accepted);
  ASSERT_EQ(seg.changepoints.size(), 1u);
  EXPECT_TRUE(config.candidate_zones[1].contains(seg.changepoints[0]));
}

// Over the whole series the Kaiser-penalized profile peaks between the two changes, outside
// every zone: without anchors the in-zone argmax is the zone's edge (the flank of that peak).
// With anchors ClaSP still decides which zones hold a changepoint, but each one sits on its
// zone's event nearest to the argmax, and a zone ClaSP leaves empty stays empty.
TEST(MultivariateSegmentation, AnchorsPlaceChangepointsOnTheZoneEvents) {
  const Eigen::MatrixXd f = changesAt600And1300();
  lfd::MultivariateSegmentationConfig config;
  config.min_segment_length = 100;
  const std::vector<lfd::Interval> zones{{450, 760}, {1150, 1450}, {1700, 1800}};
  config.candidate_zones = zones;
  const auto plain = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(plain.changepoints.size(), 2u);
  EXPECT_EQ(plain.changepoints[1], zones[1].begin);  // pinned to the edge, 150 before the change
  for (const lfd::SplitCandidate& c : plain.candidates) EXPECT_FALSE(c.anchored);

  // Events 80 samples after each change, one more farther inside the first zone, and one in the
  // zone where nothing changes.
  config.zone_anchors = {680, 740, 1380, 1750};
  const auto seg = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(seg.changepoints.size(), 2u);
  EXPECT_EQ(seg.changepoints[0], 680u);  // nearer to the argmax than 740
  EXPECT_EQ(seg.changepoints[1], 1380u);
  for (const lfd::SplitCandidate& c : seg.candidates) {
    EXPECT_TRUE(c.anchored);
    const auto zone = std::find_if(zones.begin(), zones.end(),
                                   [&](const lfd::Interval& z) { return z.contains(c.index); });
    ASSERT_NE(zone, zones.end());
    EXPECT_TRUE(zone->contains(c.profile_argmax)) << c.profile_argmax;
    EXPECT_EQ(c.accepted, zone != zones.end() - 1);  // nothing changes in the last zone
  }
}

// A zone's preferred anchors (rest edges: contact made or lost) are taken before a nearer
// event of the same zone (a force ramp reaching its plateau).
TEST(MultivariateSegmentation, PreferredAnchorsComeFirstInTheirZone) {
  const Eigen::MatrixXd f = changesAt600And1300();
  lfd::MultivariateSegmentationConfig config;
  config.min_segment_length = 100;
  config.candidate_zones = {{450, 760}, {1150, 1450}};
  config.zone_anchors = {680, 740, 1380};
  const auto nearest = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(nearest.changepoints.size(), 2u);
  EXPECT_EQ(nearest.changepoints[0], 680u);
  config.preferred_anchors = {false, true, false};
  const auto preferred = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_EQ(preferred.changepoints.size(), 2u);
  EXPECT_EQ(preferred.changepoints[0], 740u);
  EXPECT_EQ(preferred.changepoints[1], 1380u);
}

// Events closer than min_s make one merged zone, which may hold several interactions (a short
// push: contact and release). With anchors each changepoint sits on its own event of that zone;
// without anchors the zone holds one.
TEST(MultivariateSegmentation, AMergedZoneHoldsOneAnchoredChangepointPerEvent) {
  const Eigen::MatrixXd f = changesAt600And1300();
  lfd::MultivariateSegmentationConfig config;
  config.min_segment_length = 100;
  config.candidate_zones = {{450, 1450}};
  const auto one = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  EXPECT_EQ(one.changepoints.size(), 1u);
  config.zone_anchors = {610, 1290};
  const auto two = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  EXPECT_EQ(two.changepoints, (std::vector<std::size_t>{610, 1290}));
}

// A weak change (ClaSP p ~ 1e-3, under the zone threshold of 1e-5) inside a zone: accepted only
// when the zone holds a preferred anchor and rest_edge_p_value_threshold admits it.
TEST(MultivariateSegmentation, ARestEdgeZoneNeedsLessClaspEvidence) {
  std::mt19937 rng(21);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 600, cp = 300;
  Eigen::MatrixXd f(n, 1);
  for (int t = 0; t < n; ++t) f(t, 0) = (t >= cp ? 0.35 : 0.0) + g(rng);
  lfd::MultivariateSegmentationConfig config;
  config.min_segment_length = 60;
  config.clasp.window_size = 10;
  config.candidate_zones = {{250, 350}};
  config.zone_anchors = {cp};
  config.zone_p_value_threshold = 1e-5;
  const auto strict = lfd::segmentMultivariate(f, {}, config);
  ASSERT_FALSE(strict.candidates.empty());
  const double log_p = strict.candidates[0].log10_p_value;
  ASSERT_GT(log_p, -5.0) << "the change must be weak for this test";
  ASSERT_LT(log_p, -1.0) << "but not absent";
  EXPECT_TRUE(strict.changepoints.empty());
  config.rest_edge_p_value_threshold = 0.1;
  EXPECT_TRUE(lfd::segmentMultivariate(f, {}, config).changepoints.empty()) << "not preferred";
  config.preferred_anchors = {true};
  EXPECT_EQ(lfd::segmentMultivariate(f, {}, config).changepoints,
            (std::vector<std::size_t>{static_cast<std::size_t>(cp)}));
}

// Without zones a longer demo needs more evidence: significance_per_sample raises the threshold
// with the length, never lowers it below p_value_threshold.
TEST(MultivariateSegmentation, ALongDemoNeedsMoreEvidenceWithoutZones) {
  const Eigen::MatrixXd f = changesAt600And1300();
  lfd::MultivariateSegmentationConfig config;
  config.min_segment_length = 100;
  const auto plain = lfd::segmentMultivariate(f, {1.0, 1.0}, config);
  ASSERT_GE(plain.changepoints.size(), 2u);
  double strongest = 0.0;
  for (const lfd::SplitCandidate& c : plain.candidates)
    if (c.accepted) strongest = std::min(strongest, c.log10_p_value);
  // A rate whose threshold over these 2000 samples lies beyond the strongest split's evidence
  // leaves no changepoint; a rate below p_value_threshold changes nothing.
  config.significance_per_sample = -strongest / 2000.0 * 1.01;
  EXPECT_TRUE(lfd::segmentMultivariate(f, {1.0, 1.0}, config).changepoints.empty());
  config.significance_per_sample = 1e-6;
  EXPECT_EQ(lfd::segmentMultivariate(f, {1.0, 1.0}, config).changepoints, plain.changepoints);
}

TEST(MultivariateSegmentation, StationaryFeaturesGiveNoChangepoint) {
  const std::size_t n = 2000;
  std::mt19937 rng(9);
  Eigen::MatrixXd f(n, 2);
  for (std::size_t t = 0; t < n; ++t)
    f(static_cast<Eigen::Index>(t), 0) = std::sin(2.0 * M_PI * static_cast<double>(t) / 50.0);
  f.col(0) += 0.1 * noise(n, rng);
  f.col(1) = noise(n, rng);
  const auto seg = lfd::segmentMultivariate(f, {1.0, 0.5}, lfd::MultivariateSegmentationConfig{});
  EXPECT_TRUE(seg.changepoints.empty());
  ASSERT_EQ(seg.candidates.size(), 1u);
  EXPECT_FALSE(seg.candidates[0].accepted);
  EXPECT_GT(seg.candidates[0].log10_p_value, -15.0);
}

TEST(MultivariateSegmentation, ConstantColumnIsIgnoredAndBadInputRejected) {
  const std::size_t n = 1500;
  std::mt19937 rng(2);
  Eigen::MatrixXd f(n, 2);
  f.col(0) = shapeChange(n, 600, rng);
  f.col(1).setConstant(3.0);
  const auto seg = lfd::segmentMultivariate(f, {1.0, 1.0}, lfd::MultivariateSegmentationConfig{});
  ASSERT_EQ(seg.changepoints.size(), 1u);
  EXPECT_NEAR(static_cast<double>(seg.changepoints[0]), 600.0, 40.0);
  EXPECT_EQ(seg.window_sizes[1], 0u);
  EXPECT_TRUE(seg.first_feature_profiles[1].isZero());

  lfd::MultivariateSegmentationConfig config;
  EXPECT_THROW(lfd::segmentMultivariate(f, {1.0}, config), std::invalid_argument);
  EXPECT_THROW(lfd::segmentMultivariate(f, {1.0, -0.1}, config), std::invalid_argument);
  EXPECT_THROW(lfd::segmentMultivariate(Eigen::MatrixXd(n, 0), {}, config), std::invalid_argument);
  f(10, 0) = std::nan("");
  EXPECT_THROW(lfd::segmentMultivariate(f, {1.0, 1.0}, config), std::invalid_argument);
}

}  // namespace

namespace {

// Distance averaging: with one channel, z-normalizing its distance profile keeps the order, so
// the neighbours are exactly the univariate self-join's.
TEST(DistanceAverage, OneChannelGivesTheUnivariateNeighbours) {
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd x(300);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = std::sin(0.2 * i) + 0.3 * g(rng);
  for (auto distance :
       {lfd::ClaspDistance::kEuclidean, lfd::ClaspDistance::kZNormalizedEuclidean}) {
    const lfd::KnnResult uni = lfd::bruteForceKnn(x, 20, 3, 10, distance);
    const lfd::KnnResult avg = lfd::distanceAverageKnn(Eigen::MatrixXd(x), {}, 20, 3, 10, distance);
    ASSERT_EQ(avg.num_subsequences, uni.num_subsequences);
    std::size_t same = 0;
    for (std::size_t i = 0; i < uni.indices.size(); ++i) same += uni.indices[i] == avg.indices[i];
    EXPECT_GE(same, uni.indices.size() * 99 / 100);  // ties aside
  }
}

// Two channels of very different scales: the small one carries the change, the large one is
// noise. The z-normalized average gives both the same say, so the change is found; weighting the
// noise channel to 0 leaves the change channel alone.
TEST(DistanceAverage, ScaleFreeAndWeighted) {
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Index n = 600, change = 180;  // off-centre: the Kaiser window favours 300
  Eigen::MatrixXd x(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    x(i, 0) = 0.001 * (i < change ? std::sin(0.3 * i) : std::sin(0.9 * i)) + 0.00005 * g(rng);
    x(i, 1) = 1000.0 * g(rng);
  }
  lfd::MultivariateSegmentationConfig config;
  config.clasp.window_size = 20;
  config.clasp.distance = lfd::ClaspDistance::kEuclidean;  // raw distances: scales differ 1e6
  config.num_changepoints = 1;
  for (auto c :
       {ProfileCombination::kDistanceAverage, ProfileCombination::kWeightedDistanceAverage}) {
    config.combination = c;
    const auto r = lfd::segmentMultivariate(
        x, {1.0, c == ProfileCombination::kDistanceAverage ? 1.0 : 0.1}, config);
    ASSERT_EQ(r.changepoints.size(), 1u);
    EXPECT_NEAR(static_cast<double>(r.changepoints[0]), static_cast<double>(change), 25.0);
  }
  EXPECT_EQ(lfd::parseProfileCombination("weighted_distance_average"),
            ProfileCombination::kWeightedDistanceAverage);
  EXPECT_EQ(lfd::toString(ProfileCombination::kDistanceAverage), "distance_average");
}

}  // namespace
