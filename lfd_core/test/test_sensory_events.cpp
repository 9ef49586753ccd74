// Sensory events and confidence zones (paper eq. 1): exact event indices on hand-made signals,
// zone clipping and merging, accept/reject, and the noise robustness options.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "lfd_core/segmentation/sensory_events.hpp"

namespace {

using lfd::Interval;
using lfd::SensoryEventConfig;
using Events = std::vector<std::size_t>;
using Zones = std::vector<Interval>;

SensoryEventConfig paperLiteral() {
  SensoryEventConfig c;
  c.median_window = 1;
  c.noise_floor_sigmas = 0.0;
  c.hysteresis = 1.0;
  return c;
}

Eigen::VectorXd fromDiffs(const std::vector<double>& diffs) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(diffs.size() + 1));
  x[0] = 0.0;
  for (std::size_t i = 0; i < diffs.size(); ++i)
    x[static_cast<Eigen::Index>(i + 1)] = x[static_cast<Eigen::Index>(i)] + diffs[i];
  return x;
}

TEST(SensoryEvents, StepGivesOnAndOffEventForBothSigns) {
  Eigen::VectorXd up = Eigen::VectorXd::Zero(200);
  up.tail(100).setConstant(1.0);
  EXPECT_EQ(lfd::detectSensoryEvents(up, paperLiteral()), (Events{100, 101}));
  EXPECT_EQ(lfd::detectSensoryEvents(up), (Events{100, 101}));  // defaults keep clean steps
  const Eigen::VectorXd down = -up;                             // high -> low
  EXPECT_EQ(lfd::detectSensoryEvents(down, paperLiteral()), (Events{100, 101}));
}

TEST(SensoryEvents, PulseGivesBeginningAndEndOfBothEdges) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(100);
  x.segment(50, 10).setConstant(2.0);
  EXPECT_EQ(lfd::detectSensoryEvents(x, paperLiteral()), (Events{50, 51, 60, 61}));
}

TEST(SensoryEvents, ThresholdIsARatioOfTheLargestDifference) {
  // |diff| at t = 1..7: 0.1 0.5 1.0 0.3 0.15 0.0 0.0 -> threshold 0.4.
  const Eigen::VectorXd x = fromDiffs({0.1, 0.5, 1.0, 0.3, 0.15, 0.0, 0.0});
  EXPECT_EQ(lfd::detectSensoryEvents(x, paperLiteral()), (Events{2, 4}));
  SensoryEventConfig hyst = paperLiteral();
  hyst.hysteresis = 0.5;  // stays active until |diff| <= 0.2
  EXPECT_EQ(lfd::detectSensoryEvents(x, hyst), (Events{2, 5}));
  SensoryEventConfig high = paperLiteral();
  high.threshold_ratio = 0.9;
  EXPECT_EQ(lfd::detectSensoryEvents(x, high), (Events{3, 4}));
}

TEST(SensoryEvents, ActivityRunningToTheEndHasNoOffEvent) {
  const Eigen::VectorXd x = fromDiffs({0.0, 0.0, 1.0, 1.0, 1.0});
  EXPECT_EQ(lfd::detectSensoryEvents(x, paperLiteral()), (Events{3}));
}

TEST(SensoryEvents, ConstantOrTinySignalsHaveNoEvents) {
  EXPECT_TRUE(lfd::detectSensoryEvents(Eigen::VectorXd::Constant(50, 4.0)).empty());
  EXPECT_TRUE(lfd::detectSensoryEvents(Eigen::VectorXd::Zero(1)).empty());
}

TEST(SensoryEvents, NoiseFloorAndMedianKeepNoiseFromFloodingEvents) {
  std::mt19937 rng(1);
  std::normal_distribution<double> g(0.0, 0.05);
  Eigen::VectorXd pure(2000), step(2000), spiky(2000);
  for (Eigen::Index t = 0; t < 2000; ++t) {
    pure[t] = g(rng);
    step[t] = (t >= 1000 ? 1.0 : 0.0) + g(rng);
    spiky[t] = (t >= 1500 ? 1.0 : 0.0) + 0.01 * g(rng);
  }
  spiky[400] = 5.0;  // one-sample glitch, larger than the real step
  // Paper-literal: 0.4 x max of pure noise is crossed everywhere.
  EXPECT_GT(lfd::detectSensoryEvents(pure, paperLiteral()).size(), 20u);
  EXPECT_TRUE(lfd::detectSensoryEvents(pure).empty());
  const Events on_step = lfd::detectSensoryEvents(step);
  ASSERT_FALSE(on_step.empty());
  for (std::size_t e : on_step) EXPECT_NEAR(static_cast<double>(e), 1000.0, 4.0);
  // The glitch dominates the literal rule (the real step is below 0.4 x 5) ...
  const Events literal = lfd::detectSensoryEvents(spiky, paperLiteral());
  ASSERT_FALSE(literal.empty());
  EXPECT_EQ(literal.front(), 400u);
  // ... while the median filter removes it and finds the step.
  const Events robust = lfd::detectSensoryEvents(spiky);
  ASSERT_FALSE(robust.empty());
  for (std::size_t e : robust) EXPECT_NEAR(static_cast<double>(e), 1500.0, 3.0);
}

TEST(SensoryEvents, MinActiveSamplesAndMergeGap) {
  // Two bursts (t = 3 and t = 6..7) separated by two quiet samples.
  const Eigen::VectorXd x = fromDiffs({0, 0, 1.0, 0, 0, 1.0, 1.0, 0, 0, 0});
  EXPECT_EQ(lfd::detectSensoryEvents(x, paperLiteral()), (Events{3, 4, 6, 8}));
  SensoryEventConfig merged = paperLiteral();
  merged.merge_gap = 2;
  EXPECT_EQ(lfd::detectSensoryEvents(x, merged), (Events{3, 8}));
  SensoryEventConfig longer = paperLiteral();
  longer.min_active_samples = 2;
  EXPECT_EQ(lfd::detectSensoryEvents(x, longer), (Events{6, 8}));
}

// A contact seen by a chattering sensor: quiet, then 0..3 noise-like chatter for 150 samples with
// a short inertial spike before it. The lagged level difference ignores the spike, and merging
// bursts within 50 samples turns the chatter into one burst: events at contact on and off only.
TEST(SensoryEvents, LaggedLevelDifferenceSeesContactNotSpikesOrChatter) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> chatter(0.0, 3.0);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(400);
  x[60] = 6.0;  // one-sample inertial spike, larger than any chatter step
  for (Eigen::Index i = 150; i < 300; ++i) x[i] = (i % 4 == 0) ? 0.0 : chatter(rng);
  SensoryEventConfig paper;  // lag 1: the spike and every chatter edge are events
  paper.median_window = 1;
  paper.noise_floor_sigmas = 0.0;
  EXPECT_GT(lfd::detectSensoryEvents(x, paper).size(), 6u);
  SensoryEventConfig level;
  level.median_window = 13;
  level.difference_lag = 13;
  level.merge_gap = 50;
  const Events events = lfd::detectSensoryEvents(x, level);
  ASSERT_EQ(events.size(), 2u) << ::testing::PrintToString(events);
  // Within a lag and a half: the median needs half its window of chatter before its level rises.
  EXPECT_NEAR(static_cast<double>(events[0]), 150.0, 20.0);
  EXPECT_NEAR(static_cast<double>(events[1]), 300.0, 20.0);
}

// Hand-made sensor signals at 50 Hz with the settings of config/segmentation.yaml (0.26 s median,
// 0.5 s lag, 1 s merge gap, 5.5 sigma noise floor from 1 s blocks).
SensoryEventConfig configAt50hz(lfd::EventThreshold threshold) {
  SensoryEventConfig c;
  c.threshold = threshold;
  c.median_window = 13;
  c.difference_lag = 25;
  c.merge_gap = 50;
  c.noise_floor_sigmas = 5.5;
  c.noise_block = 50;
  return c;
}

// 18 s of oscillating, chattering contact (level 4, +-1.5 at 1.3 Hz, white chatter of 0.6: three
// quarters of the demo), 2 s free, then a new light contact of level 1 at t = 21 s (sample 1050).
// One noise figure for the whole demo is set by the chatter and hides the light onset; the quiet
// blocks' noise does not. (The paper's 0.4 x max cannot see it either: the first onset is four
// times larger.)
TEST(SensoryEvents, OnsetAfterALongOscillatingContact) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 0.02), chatter(0.0, 0.6);
  Eigen::VectorXd x(1200);
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    const double s = t / 50.0;
    x[t] = g(rng);
    if (s >= 1.0 && s < 19.0) x[t] += 4.0 + 1.5 * std::sin(2 * M_PI * 1.3 * s) + chatter(rng);
    if (t >= 1050) x[t] += 1.0;
  }
  SensoryEventConfig local = configAt50hz(lfd::EventThreshold::kNoise);
  const Events events = lfd::detectSensoryEvents(x, local);
  ASSERT_FALSE(events.empty());
  EXPECT_NEAR(static_cast<double>(events.back()), 1050.0, 3.0) << ::testing::PrintToString(events);
  EXPECT_NEAR(static_cast<double>(events.front()), 50.0, 3.0) << ::testing::PrintToString(events);
  SensoryEventConfig global = local;
  global.noise_block = 0;
  const Events missed = lfd::detectSensoryEvents(x, global);
  EXPECT_TRUE(missed.empty() || missed.back() < 1000) << ::testing::PrintToString(missed);
}

// A force ramping up over 2 s from t = 4 s (sample 200) and holding: events at the start and the
// end of the ramp, not where the threshold happens to be crossed.
TEST(SensoryEvents, SlowForceRampGivesItsStartAndEnd) {
  std::mt19937 rng(6);
  std::normal_distribution<double> g(0.0, 0.01);
  Eigen::VectorXd x(600);
  for (Eigen::Index t = 0; t < x.size(); ++t)
    x[t] = 5.0 * std::clamp((t - 200.0) / 100.0, 0.0, 1.0) + g(rng);
  for (auto mode : {lfd::EventThreshold::kRatioOfMax, lfd::EventThreshold::kNoise}) {
    const Events events = lfd::detectSensoryEvents(x, configAt50hz(mode));
    ASSERT_EQ(events.size(), 2u) << ::testing::PrintToString(events);
    EXPECT_NEAR(static_cast<double>(events[0]), 200.0, 7.5);  // 0.15 s
    EXPECT_NEAR(static_cast<double>(events[1]), 300.0, 7.5);
  }
}

// Contact at t = 3 s (sample 150), then the sensor freezes at its last value from t = 6 s: the
// frozen stretch is not "the quiet noise" (its sigma is 0), so the noise of the live part still
// sets the floor and the noise before the freeze makes no event.
TEST(SensoryEvents, StaleSensorValueIsNotTakenAsTheNoise) {
  std::mt19937 rng(8);
  std::normal_distribution<double> g(0.0, 0.2);
  Eigen::VectorXd x(1000);
  for (Eigen::Index t = 0; t < x.size(); ++t)
    x[t] = t < 300 ? (t >= 150 ? 2.0 : 0.0) + g(rng) : x[299];
  const Events events = lfd::detectSensoryEvents(x, configAt50hz(lfd::EventThreshold::kNoise));
  ASSERT_EQ(events.size(), 1u) << ::testing::PrintToString(events);
  EXPECT_NEAR(static_cast<double>(events[0]), 150.0, 3.0);
}

TEST(SensoryEvents, DeadSensorHasNoEvents) {
  for (auto mode : {lfd::EventThreshold::kRatioOfMax, lfd::EventThreshold::kNoise})
    EXPECT_TRUE(
        lfd::detectSensoryEvents(Eigen::VectorXd::Constant(500, 3.3), configAt50hz(mode)).empty());
  EXPECT_EQ(lfd::parseEventThreshold("noise"), lfd::EventThreshold::kNoise);
  EXPECT_THROW(lfd::parseEventThreshold("max"), std::invalid_argument);
}

TEST(SensoryEvents, RejectsBadConfigAndInput) {
  {
    SensoryEventConfig c;
    c.difference_lag = 0;
    EXPECT_THROW(lfd::detectSensoryEvents(Eigen::VectorXd::Zero(10), c), std::invalid_argument);
  }
  SensoryEventConfig c;
  c.threshold_ratio = 0.0;
  EXPECT_THROW(lfd::detectSensoryEvents(Eigen::VectorXd::Zero(5), c), std::invalid_argument);
  c = SensoryEventConfig{};
  c.hysteresis = 1.5;
  EXPECT_THROW(lfd::detectSensoryEvents(Eigen::VectorXd::Zero(5), c), std::invalid_argument);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(5);
  x[2] = std::nan("");
  EXPECT_THROW(lfd::detectSensoryEvents(x), std::invalid_argument);
}

TEST(SensoryEvents, ABadValueIsNamedByItsSensorColumn) {
  Eigen::MatrixXd sensors = Eigen::MatrixXd::Zero(20, 3);
  sensors(7, 2) = std::numeric_limits<double>::infinity();
  try {
    lfd::detectSensorEvents(sensors, SensoryEventConfig{});
    FAIL() << "an infinite reading was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sensor column 2 has NaN/Inf"), std::string::npos)
        << e.what();
  }
}

TEST(ConfidenceZones, EquationOneWithClippingAndMerging) {
  EXPECT_EQ(lfd::confidenceZones({10, 50}, 20, 100), (Zones{{0, 20}, {40, 60}}));
  EXPECT_EQ(lfd::confidenceZones({3}, 20, 100), (Zones{{0, 13}}));       // clipped at 0
  EXPECT_EQ(lfd::confidenceZones({95}, 20, 100), (Zones{{85, 100}}));    // clipped at len(T)
  EXPECT_EQ(lfd::confidenceZones({25, 10}, 20, 100), (Zones{{0, 35}}));  // overlap merges
  EXPECT_EQ(lfd::confidenceZones({10, 31}, 20, 100), (Zones{{0, 41}}));  // touching merges
  EXPECT_EQ(lfd::confidenceZones({10, 32}, 20, 100), (Zones{{0, 20}, {22, 42}}));
  EXPECT_EQ(lfd::confidenceZones({50}, 21, 100), (Zones{{40, 60}}));  // min_s / 2 = 10
  EXPECT_TRUE(lfd::confidenceZones({}, 20, 100).empty());
}

TEST(ConfidenceZones, ValidationAcceptsInsideAndRejectsOutside) {
  const auto v = lfd::validateWithZones({70, 5, 30, 55, 60, 39}, {{0, 20}, {40, 60}});
  EXPECT_EQ(v.accepted, (Events{5, 55, 60}));  // zone bounds are inclusive
  EXPECT_EQ(v.rejected, (Events{30, 39, 70}));
}

TEST(ConfidenceZones, FullValidationOverSeveralSensors) {
  Eigen::MatrixXd sensors = Eigen::MatrixXd::Zero(300, 2);
  sensors.block(100, 0, 200, 1).setConstant(1.0);  // touch from t = 100 on
  sensors.block(250, 1, 50, 1).setConstant(-3.0);  // force drop at t = 250
  const auto v = lfd::validateChangepoints({90, 160, 240, 280}, sensors, 40);
  EXPECT_EQ(v.events_per_sensor[0], (Events{100, 101}));
  EXPECT_EQ(v.events_per_sensor[1], (Events{250, 251}));
  EXPECT_EQ(v.events, (Events{100, 101, 250, 251}));
  EXPECT_EQ(v.zones, (Zones{{80, 121}, {230, 271}}));
  EXPECT_EQ(v.accepted, (Events{90, 240}));
  EXPECT_EQ(v.rejected, (Events{160, 280}));
  // No sensor at all: nothing can be confirmed.
  const auto none = lfd::validateChangepoints({90}, Eigen::MatrixXd(300, 0), 40);
  EXPECT_TRUE(none.zones.empty());
  EXPECT_EQ(none.rejected, (Events{90}));
}

}  // namespace

namespace {

// The settings of config/segmentation.yaml at 50 Hz: quiet-excursion floor, fitted placement.
// A level made of linear ramps (each from sample `start`, over `samples`, by `height`) with
// Gaussian noise of `sigma` (seeded): contacts made and lost, levels stepping in contact.
struct Ramp {
  double start, samples, height;
};
Eigen::VectorXd rampsWithNoise(Eigen::Index n, const std::vector<Ramp>& ramps, double sigma,
                               unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  Eigen::VectorXd x(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    x[t] = 0.0;
    for (const Ramp& r : ramps) x[t] += r.height * std::clamp((t - r.start) / r.samples, 0.0, 1.0);
    x[t] += g(rng);
  }
  return x;
}

SensoryEventConfig yamlAt50hz() {
  SensoryEventConfig c = configAt50hz(lfd::EventThreshold::kRatioOfMax);
  c.noise_floor_sigmas = 0.0;
  c.noise_floor_excursions = 5.0;
  c.placement = lfd::EventPlacement::kFit;
  return c;
}

// One channel of a sensor that the contact does not reach (a torque axis, the pad on the other
// finger) carries only drift and noise. The paper's 0.4 x max is then 0.4 x the drift's largest
// excursion, and a sigma from the raw differences does not see a drift (its steps are tiny): both
// put events all along. The quiet excursion is measured on the detector's own statistic, and an
// event must clear five of them.
TEST(SensoryEvents, DriftWithoutContactNeedsTheQuietExcursionFloor) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd x(1500);
  double drift = 0.0;
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    drift += 0.03 * g(rng);
    x[t] = drift + 0.05 * g(rng);
  }
  SensoryEventConfig sigma = yamlAt50hz();
  sigma.noise_floor_excursions = 0.0;
  sigma.noise_floor_sigmas = 5.5;
  EXPECT_GE(lfd::detectSensoryEvents(x, sigma).size(), 2u);
  EXPECT_TRUE(lfd::detectSensoryEvents(x, yamlAt50hz()).empty());
  // A real contact on top of the same drift still makes its events.
  Eigen::VectorXd touched = x;
  touched.segment(700, 300).array() += 6.0;
  const Events events = lfd::detectSensoryEvents(touched, yamlAt50hz());
  ASSERT_EQ(events.size(), 2u) << ::testing::PrintToString(events);
  EXPECT_NEAR(static_cast<double>(events[0]), 700.0, 3.0);
  EXPECT_NEAR(static_cast<double>(events[1]), 1000.0, 3.0);
}

// A busy demo: four presses (1.5 s each, 6 to 14 N, noise 0.5 N) with 1.2 s lifts between them,
// from 1.7 s to 11.6 s of a 12.6 s recording at 50 Hz. Only its first second is quiet: one block of
// twelve. The quiet excursion must come from that block (the 10th percentile, the second quietest
// block, held a press edge and put the floor above every press), so each press makes its onset and
// its release.
TEST(SensoryEvents, ABusyDemoWithOneQuietSecondKeepsItsPresses) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 0.5);
  Eigen::VectorXd force(630);
  const std::vector<std::pair<Eigen::Index, double>> presses = {
      {85, 9.0}, {220, 14.0}, {355, 6.0}, {490, 11.0}};
  for (Eigen::Index t = 0; t < force.size(); ++t) {
    force[t] = g(rng);
    for (const auto& [on, level] : presses)
      if (t >= on && t < on + 75) force[t] += level;
  }
  SensoryEventConfig joint = yamlAt50hz();
  joint.merge_gap = 25;  // the joint segmentation's 0.5 s: a lift is a rest of its own
  const Events events = lfd::detectSensoryEvents(force, joint);
  ASSERT_EQ(events.size(), 2 * presses.size()) << ::testing::PrintToString(events);
  for (std::size_t k = 0; k < presses.size(); ++k) {
    EXPECT_NEAR(static_cast<double>(events[2 * k]), static_cast<double>(presses[k].first), 3.0);
    EXPECT_NEAR(static_cast<double>(events[2 * k + 1]), static_cast<double>(presses[k].first + 75),
                3.0);
  }
}

// A contact force building up over 0.8 s (noise a tenth of its height) and fading over 0.6 s: the
// fitted events sit where the force leaves rest and where it is back at rest, within 0.1 s.
TEST(SensoryEvents, FittedEventsAtTheStartAndEndOfSlowRamps) {
  const Eigen::VectorXd x = rampsWithNoise(800, {{200, 40, 3.0}, {500, 30, -3.0}}, 0.3, 12);
  const auto events = lfd::detectSensoryEventDetails(x, yamlAt50hz());
  std::vector<std::size_t> rest_edges;
  for (const lfd::SensoryEvent& e : events)
    if (e.rest_edge) rest_edges.push_back(e.index);
  ASSERT_EQ(rest_edges.size(), 2u) << ::testing::PrintToString(rest_edges);
  EXPECT_NEAR(static_cast<double>(rest_edges[0]), 200.0, 5.0);  // leaves rest
  EXPECT_NEAR(static_cast<double>(rest_edges[1]), 530.0, 5.0);  // back at rest
  for (const lfd::SensoryEvent& e : events)
    EXPECT_EQ(e.away_from_rest, e.index < 400) << e.index;  // building up, then fading
}

// A snap-fit in contact at 50 Hz: pressed at 13 N from 2 s, the force rises (quadratically, as the
// hook deflects) from 6 s to 29 N at 6.9 s, and falls to a 9 N hold as it clicks over. The rise
// and the fall are 0.9 s apart: the merge gap (0.5 s, the joint segmentation's) makes one burst of
// them. Each end of it is fitted on its own change: the rise starts at 6 s (within 0.3 s; a fit
// across the fall put it on the fall), the fall settles by 7 s.
TEST(SensoryEvents, ARiseAndAFallInOneBurstAreTwoChanges) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 0.3);
  Eigen::VectorXd force(450);
  for (Eigen::Index t = 0; t < force.size(); ++t) {
    double f = 13.0 * std::clamp((t - 100.0) / 10.0, 0.0, 1.0);
    if (t >= 300 && t < 345) f = 13.0 + 16.0 * std::pow((t - 300.0) / 45.0, 2.0);
    if (t >= 345) f = 9.0 + 20.0 * std::exp(-(t - 345.0) / 2.5);
    force[t] = f + g(rng);
  }
  SensoryEventConfig joint = yamlAt50hz();
  joint.merge_gap = 25;
  const Events events = lfd::detectSensoryEvents(force, joint);
  ASSERT_EQ(events.size(), 3u) << ::testing::PrintToString(events);
  EXPECT_NEAR(static_cast<double>(events[0]), 100.0, 3.0);  // the press
  // The rise begins: a straight ramp fitted to a quadratic starts a third of the way in.
  EXPECT_NEAR(static_cast<double>(events[1]), 300.0, 15.0);
  EXPECT_NEAR(static_cast<double>(events[2]), 347.0, 10.0);  // the fall has settled
  // Which way each goes: the press and the rise away from rest, the fall back towards it.
  const auto details = lfd::detectSensoryEventDetails(force, joint);
  ASSERT_EQ(details.size(), 3u);
  EXPECT_TRUE(details[0].away_from_rest);
  EXPECT_TRUE(details[1].away_from_rest);
  EXPECT_FALSE(details[2].away_from_rest);
  // The rise and the fall are two changes, not the two ends of one.
  EXPECT_FALSE(details[1].ramp_end);
  EXPECT_FALSE(details[2].ramp_end);
}

// In contact at 10 N from 2 s, a torque-like level falls to 4 N over 0.4 s from 5 s (a twist dying
// out as the turn slows), at 50 Hz: its start and its end are events, and both are flagged as the
// two ends of one change.
TEST(SensoryEvents, TheTwoEndsOfOneRampInContactAreFlaggedAsOneChange) {
  const Eigen::VectorXd x = rampsWithNoise(400, {{100, 5, 10.0}, {250, 20, -6.0}}, 0.1, 9);
  SensoryEventConfig joint = yamlAt50hz();
  joint.merge_gap = 25;
  const auto events = lfd::detectSensoryEventDetails(x, joint);
  std::vector<std::size_t> ends;
  for (const lfd::SensoryEvent& e : events)
    if (e.ramp_end) ends.push_back(e.index);
  ASSERT_EQ(ends.size(), 2u) << ::testing::PrintToString(ends);
  EXPECT_NEAR(static_cast<double>(ends[0]), 250.0, 5.0);
  EXPECT_NEAR(static_cast<double>(ends[1]), 270.0, 5.0);
}

// Two pads of one sensor: pad A touches from 4 s to 7 s, pad B from 6.5 s to 10 s. As one sensor
// the contact starts at 4 s and ends at 10 s: A letting go while B holds is no rest edge. As two
// sensors every edge is one.
TEST(SensoryEvents, OnePadLettingGoWhileTheOtherHoldsIsNoRestEdge) {
  Eigen::MatrixXd pads = Eigen::MatrixXd::Zero(700, 2);
  pads.block(200, 0, 150, 1).setConstant(2.0);
  pads.block(325, 1, 175, 1).setConstant(3.0);
  const auto rest_edges = [](const lfd::SensorEvents& e) {
    std::vector<std::size_t> out;
    for (const lfd::SensoryEvent& d : e.details)
      if (d.rest_edge) out.push_back(d.index);
    return out;
  };
  const lfd::SensorEvents one = lfd::detectSensorEvents(pads, yamlAt50hz(), {0, 0});
  EXPECT_EQ(rest_edges(one), (Events{200, 500}));
  EXPECT_EQ(one.zone_events, (Events{200, 500}));
  EXPECT_EQ(one.all.size(), 4u);
  const lfd::SensorEvents two = lfd::detectSensorEvents(pads, yamlAt50hz(), {0, 1});
  EXPECT_EQ(rest_edges(two), (Events{200, 325, 350, 500}));
  EXPECT_THROW(lfd::detectSensorEvents(pads, yamlAt50hz(), {0}), std::invalid_argument);
}

// A wrist F/T pressing and wiping, at 50 Hz: the press force (10 N) from 2 s, the friction (4 N)
// from 2.2 s. At the release the press force fades from 8 s to 8.6 s and the friction ends at 8.2
// s, when the press force is below the activity threshold (0.4 x 10 N) for most of the next lag.
// The sensor leaves rest with its first channel (2 s) and regains it with its last (8.6 s): the
// friction's own edges are none. (Judged by the other channel's median level alone, the release
// came 0.4 s early and the friction's onset made a second zone edge.)
TEST(SensoryEvents, TheSensorLeavesRestWithItsFirstChannelAndRegainsItWithItsLast) {
  Eigen::MatrixXd wrench = Eigen::MatrixXd::Zero(700, 2);
  for (Eigen::Index t = 100; t < 430; ++t)
    wrench(t, 0) = 10.0 * std::min(1.0, (430.0 - static_cast<double>(t)) / 30.0);
  wrench.block(110, 1, 300, 1).setConstant(4.0);
  const lfd::SensorEvents e = lfd::detectSensorEvents(wrench, yamlAt50hz(), {0, 0});
  EXPECT_EQ(e.zone_events, (Events{100, 430})) << ::testing::PrintToString(e.all);
  const lfd::SensorEvents apart = lfd::detectSensorEvents(wrench, yamlAt50hz(), {0, 1});
  EXPECT_EQ(apart.zone_events, (Events{100, 110, 410, 430}));
}

// A wrist F/T at 50 Hz: the press force (10 N, noise 0.3 N) from 2 s to 9 s, and a torque axis the
// press barely moves (0.06 Nm against 0.02 Nm of noise, so its threshold is its noise floor) whose
// offset drifts by 0.07 Nm meanwhile: after the contact it hovers at the edge of its rest band.
// Such a channel cannot say when the contact ends: the force does (9 s); the torque may add its own
// release there. (Waiting for every channel, the sensor never came back to rest: no release.)
TEST(SensoryEvents, AChannelWithinItsNoiseDoesNotKeepTheSensorFromRest) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd wrench(800, 2);
  for (Eigen::Index t = 0; t < wrench.rows(); ++t) {
    const bool pressed = t >= 100 && t < 450;
    const double drift = 0.07 * std::clamp((static_cast<double>(t) - 100.0) / 350.0, 0.0, 1.0);
    wrench(t, 0) = (pressed ? 10.0 : 0.0) + 0.3 * g(rng);
    wrench(t, 1) = (pressed ? 0.06 : 0.0) + drift + 0.02 * g(rng);
  }
  const lfd::SensorEvents e = lfd::detectSensorEvents(wrench, yamlAt50hz(), {0, 0});
  ASSERT_GE(e.zone_events.size(), 2u) << ::testing::PrintToString(e.all);
  EXPECT_NEAR(static_cast<double>(e.zone_events.front()), 100.0, 3.0);
  for (std::size_t i = 1; i < e.zone_events.size(); ++i)  // the force's, maybe the torque's too
    EXPECT_NEAR(static_cast<double>(e.zone_events[i]), 450.0, 5.0);
}

// A rest shorter than the merge gap is a pause inside the interaction: pad A from 2 s to 4 s and
// pad B of the same sensor from 4.6 s to 6 s leave the sensor at rest for 0.6 s only, less than
// the 1 s merge gap, though each pad rests for longer. With a 2 s pause both ends are rest edges.
TEST(SensoryEvents, AShortPauseOfTheWholeSensorIsNoRestEdge) {
  for (const int pause : {30, 100}) {
    Eigen::MatrixXd pads = Eigen::MatrixXd::Zero(700, 2);
    pads.block(100, 0, 100, 1).setConstant(2.0);
    pads.block(200 + pause, 1, 70, 1).setConstant(2.0);
    const lfd::SensorEvents e = lfd::detectSensorEvents(pads, yamlAt50hz(), {0, 0});
    const Events inner{200, static_cast<std::size_t>(200 + pause)};
    const bool inner_are_rest_edges =
        std::includes(e.zone_events.begin(), e.zone_events.end(), inner.begin(), inner.end());
    EXPECT_EQ(inner_are_rest_edges, pause >= 50)
        << pause << ": " << ::testing::PrintToString(e.zone_events);
  }
}

// A gripper closes at 2 s (it leaves its rest, the open state it started in) and its effort
// changes twice while it holds: those are no rest edges and mark no zone. A sensor with no rest
// edge at all (here one busy over its whole first second, so that it never sits at the level it
// started at) keeps all its events for zones.
TEST(SensoryEvents, ZonesComeFromRestEdgesOrFromEveryEventOfASensorWithout) {
  Eigen::MatrixXd gripper = Eigen::MatrixXd::Zero(600, 1);
  gripper.block(100, 0, 500, 1).setConstant(5.0);
  gripper.block(300, 0, 100, 1).setConstant(8.0);
  const lfd::SensorEvents held = lfd::detectSensorEvents(gripper, yamlAt50hz());
  EXPECT_EQ(held.all, (Events{100, 300, 400}));
  EXPECT_EQ(held.zone_events, (Events{100}));
  Eigen::MatrixXd busy = gripper;
  for (Eigen::Index t = 0; t < 100; ++t) busy(t, 0) = 0.05 * static_cast<double>(t);
  const lfd::SensorEvents without = lfd::detectSensorEvents(busy, yamlAt50hz());
  EXPECT_EQ(without.all, (Events{1, 100, 300, 400}));  // the ramp's start and end, the pulse
  for (const lfd::SensoryEvent& d : without.details) EXPECT_FALSE(d.rest_edge) << d.index;
  EXPECT_EQ(without.zone_events, without.all);
}

// A teleoperated push as the pads feel it at 50 Hz: clipped noise (a pad reads no less than 0 N)
// of 0.4 N, a light first touch of 0.8 N at 3 s that the force builds on only at 3.6 s (the push
// accelerating the box), and a fade to 0.8 N at 7 s before the hand leaves at 7.6 s. The fitted
// ramps start and end at the strong change, 0.6 s off; where the samples stop being consistent
// with rest (CUSUM, one rest sigma above the rest mean) is the touch and the leaving, within
// 0.2 s, in 50 noise draws out of 50.
TEST(SensoryEvents, WeakFirstAndLastContactUnderNoiseByTheRestEdgeCusum) {
  const auto rest_edges = [](const Eigen::VectorXd& x, const SensoryEventConfig& config) {
    std::vector<double> out;
    for (const lfd::SensoryEvent& e : lfd::detectSensoryEventDetails(x, config))
      if (e.rest_edge) out.push_back(static_cast<double>(e.index));
    return out;
  };
  SensoryEventConfig cusum = yamlAt50hz();
  cusum.rest_edge_sigmas = 1.0;
  int fit_late = 0;
  for (unsigned seed = 0; seed < 50; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.4);
    Eigen::VectorXd x(500);
    for (Eigen::Index t = 0; t < x.size(); ++t) {
      double force = 0.0;
      if (t >= 150 && t < 380) force = 0.8;
      if (t >= 180 && t < 350) force = 0.8 + 3.2 * std::min(1.0, (t - 180) / 15.0);
      if (t >= 335 && t < 350) force = 0.8 + 3.2 * (350 - t) / 15.0;
      x[t] = std::max(0.0, force + noise(rng));
    }
    const std::vector<double> found = rest_edges(x, cusum);
    ASSERT_EQ(found.size(), 2u) << seed << ": " << ::testing::PrintToString(found);
    EXPECT_NEAR(found[0], 150.0, 10.0) << seed;  // the touch
    EXPECT_NEAR(found[1], 380.0, 10.0) << seed;  // the hand leaves
    const std::vector<double> fitted = rest_edges(x, yamlAt50hz());
    fit_late += fitted.size() == 2 && fitted[0] > 170.0 && fitted[1] < 360.0;
  }
  EXPECT_GE(fit_late, 45);  // the fit alone places both at the strong change
}

}  // namespace
