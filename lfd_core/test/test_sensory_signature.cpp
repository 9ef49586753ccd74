// The sensory signature of a skill: learned from demonstrations, it passes nominal runs
// and flags a reproduction whose sensations differ, naming the segment, the channel and when.
#include "lfd_core/dmp/sensory_signature.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace {

// A press: approach (no force, gripper open), press (the force rises to `level` N, gripper
// closed), retract (no force, gripper open). Durations and level vary like human demos do.
struct Press {
  double approach = 2.0, press = 3.0, retract = 2.0, level = 10.0;
  double rate = 100.0;
  double lose_contact_at = -1.0;  ///< s from the start: the force falls to 0 (a slip)
};

lfd::SegmentedRecording pressRun(const Press& p, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.2);
  const double total = p.approach + p.press + p.retract;
  const auto n = static_cast<Eigen::Index>(std::lround(total * p.rate)) + 1;
  lfd::SegmentedRecording r;
  r.features.names = {"force_z", "gripper"};
  r.features.data.resize(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / p.rate;
    r.features.time.push_back(100.0 + t);
    const double in_press = t - p.approach;
    double force = 0.0;
    if (in_press >= 0 && in_press <= p.press)
      force = p.level * std::min(1.0, in_press / 0.3) * std::min(1.0, (p.press - in_press) / 0.3);
    if (p.lose_contact_at >= 0 && t >= p.lose_contact_at) force = 0.0;
    r.features.data(i, 0) = force + noise(rng);
    r.features.data(i, 1) = (in_press >= 0 && in_press <= p.press) ? 0.03 : 0.08;
  }
  r.boundaries = {p.approach, p.approach + p.press};
  return r;
}

Press varied(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Press p;
  p.approach *= 1.0 + 0.1 * u(rng);
  p.press *= 1.0 + 0.1 * u(rng);
  p.retract *= 1.0 + 0.1 * u(rng);
  p.level *= 1.0 + 0.08 * u(rng);
  return p;
}

lfd::SensorySignature learned(std::size_t demos) {
  std::vector<lfd::SegmentedRecording> d;
  for (unsigned k = 0; k < demos; ++k) d.push_back(pressRun(varied(k), 1000 + k));
  return lfd::learnSignature(d, {"force_z", "gripper"});
}

// A spread floor of half the range (the levels alone cannot tell a missing press) with the
// missing-contact check on, as the learner's configuration turns it on.
lfd::SignatureOptions wideSpreadWithRestBands() {
  lfd::SignatureOptions o;
  o.min_spread_fraction = 0.5;
  o.rest_band_fraction = 0.05;
  return o;
}

double worstScore(const std::vector<std::vector<double>>& scores) {
  double worst = 0.0;
  for (const auto& s : scores)
    for (double v : s) worst = std::max(worst, v);
  return worst;
}

TEST(SensorySignature, NominalRunsRaiseNoAlarm) {
  const lfd::SensorySignature sig = learned(5);
  for (unsigned k = 0; k < 40; ++k) {
    const auto scores = lfd::scoreRecording(sig, pressRun(varied(50 + k), 5000 + k));
    EXPECT_LT(worstScore(scores), 1.0) << "nominal run " << k;
  }
}

// The segmentation validates a boundary at a sensory event, so a segment may start at full force.
// Live, the segment's start comes from the plan: contact 0.4 s later than planned shows the
// approach's level in the press segment, which the slack must accept across the boundary.
TEST(SensorySignature, AnEventLateByLessThanTheTimeSlackAtABoundaryIsNoAlarm) {
  std::vector<lfd::SegmentedRecording> demos;
  for (unsigned k = 0; k < 5; ++k) {
    demos.push_back(pressRun(varied(k), 1000 + k));
    for (double& b : demos.back().boundaries) b += 0.3;  // after the ramp: at full force / rest
  }
  const lfd::SensorySignature sig = lfd::learnSignature(demos, {"force_z", "gripper"});
  ASSERT_GE(sig.options.time_slack, 0.45);
  for (unsigned k = 0; k < 10; ++k) {
    lfd::SegmentedRecording run = pressRun(varied(60 + k), 6000 + k);
    for (double& b : run.boundaries) b += 0.3 - 0.4;  // the plan's boundary, 0.4 s early
    EXPECT_LT(worstScore(lfd::scoreRecording(sig, run)), 1.0) << "run " << k;
    Press missed = varied(60 + k);
    missed.level = 0.0;
    lfd::SegmentedRecording no_force = pressRun(missed, 6000 + k);
    for (double& b : no_force.boundaries) b += 0.3 - 0.4;
    EXPECT_GT(lfd::scoreRecording(sig, no_force)[1][0], 1.0) << "run " << k;
  }
}

TEST(SensorySignature, APressWithoutForceIsFlaggedInThePressSegment) {
  const lfd::SensorySignature sig = learned(5);
  Press p = varied(77);
  p.level = 0.0;  // the tool missed the button
  std::vector<lfd::Deviation> worst;
  const auto scores = lfd::scoreRecording(sig, pressRun(p, 77), &worst);
  EXPECT_GT(scores[1][0], 1.0);
  EXPECT_LT(scores[0][0], 1.0);
  ASSERT_EQ(worst.size(), 3u);
  EXPECT_EQ(worst[1].channel_name, "force_z");
  EXPECT_NEAR(worst[1].expected, 10.0, 1.5);
  EXPECT_NEAR(worst[1].measured, 0.0, 1.0);
  EXPECT_GT(worst[1].time, p.approach);
  EXPECT_LT(worst[1].time, p.approach + p.press);
}

// A wide spread floor (reproductions toward new goals press harder or softer than the demos) keeps
// a missing press under the level's threshold: 10 N against a 5 N spread. Every demonstration held
// the contact, so a reading at rest is a missing contact anyway; half the force is not.
TEST(SensorySignature, AMissingContactIsAnAlarmWhateverTheLevelsSpread) {
  std::vector<lfd::SegmentedRecording> demos;
  for (unsigned k = 0; k < 5; ++k) demos.push_back(pressRun(varied(k), 1000 + k));
  lfd::SignatureOptions wide = wideSpreadWithRestBands();
  const auto sig = lfd::learnSignature(demos, {"force_z", "gripper"}, wide);
  wide.rest_band_fraction = 0.0;
  const auto levels_only = lfd::learnSignature(demos, {"force_z", "gripper"}, wide);
  for (unsigned k = 0; k < 10; ++k) {
    Press missed = varied(70 + k), softer = varied(70 + k);
    missed.level = 0.0;
    softer.level *= 0.5;
    const lfd::SegmentedRecording no_force = pressRun(missed, 7000 + k);
    EXPECT_GT(lfd::scoreRecording(sig, no_force)[1][0], 1.0) << "run " << k;
    EXPECT_LT(lfd::scoreRecording(levels_only, no_force)[1][0], 1.0) << "run " << k;
    EXPECT_LT(worstScore(lfd::scoreRecording(sig, pressRun(softer, 7000 + k))), 1.0) << "run " << k;
    EXPECT_LT(worstScore(lfd::scoreRecording(sig, pressRun(varied(90 + k), 9000 + k))), 1.0);
  }
  // Live: the rest is the run's first reading, whatever the sensor's offset.
  Press missed = varied(99);
  missed.level = 0.0;
  lfd::SegmentedRecording offset = pressRun(missed, 99);
  offset.features.data.col(0).array() += 3.0;
  lfd::SignatureMonitor monitor(sig);
  monitor.start();
  double alarm = -1.0;
  for (Eigen::Index i = 0; i < offset.features.rows() && alarm < 0; ++i) {
    const double t = offset.features.timeAt(i) - offset.features.timeAt(0);
    const std::size_t s = t < offset.boundaries[0] ? 0 : t < offset.boundaries[1] ? 1 : 2;
    const double begin = s == 0 ? 0.0 : offset.boundaries[s - 1];
    const double end =
        s == 2 ? offset.features.timeAt(offset.features.rows() - 1) - 100.0 : offset.boundaries[s];
    if (monitor.observe(s, (t - begin) / (end - begin), t, offset.features.data.row(i)).score > 1)
      alarm = t;
  }
  EXPECT_GT(alarm, missed.approach);
  EXPECT_LT(alarm, missed.approach + missed.press);
}

// Two pads of one sensor: every demonstration pressed on the left pad (some on both). A push toward
// a new goal may meet the box with the right pad only: the sensor still feels the contact. Judged
// pad by pad (no sources), the left pad at rest would be a missing contact; on neither pad it is.
TEST(SensorySignature, AContactIsMissingOnlyWhenEveryChannelOfItsSensorIsAtRest) {
  const auto two_pads = [](const lfd::SegmentedRecording& press, bool left, bool right) {
    lfd::SegmentedRecording r = press;
    r.features.names = {"pad_left", "pad_right"};
    r.features.data.resize(press.features.rows(), 2);
    r.features.data.col(0) = press.features.data.col(0) * (left ? 1.0 : 0.0);
    r.features.data.col(1) = press.features.data.col(0) * (right ? 1.0 : 0.0);
    return r;
  };
  std::vector<lfd::SegmentedRecording> demos;
  for (unsigned k = 0; k < 6; ++k)
    demos.push_back(two_pads(pressRun(varied(k), 1000 + k), true, k % 2 == 1));
  const std::vector<std::string> pads = {"pad_left", "pad_right"};
  lfd::SignatureOptions wide = wideSpreadWithRestBands();  // the levels alone could not tell
  const auto one_sensor = lfd::learnSignature(demos, pads, wide, {"/touch", "/touch"});
  const auto two_sensors = lfd::learnSignature(demos, pads, wide);
  EXPECT_EQ(lfd::sensorOf(one_sensor), (std::vector<std::size_t>{0, 0}));
  EXPECT_EQ(lfd::sensorOf(two_sensors), (std::vector<std::size_t>{0, 1}));
  for (unsigned k = 0; k < 6; ++k) {
    const lfd::SegmentedRecording press = pressRun(varied(80 + k), 8000 + k);
    EXPECT_LT(worstScore(lfd::scoreRecording(one_sensor, two_pads(press, true, false))), 1.0);
    EXPECT_LT(worstScore(lfd::scoreRecording(one_sensor, two_pads(press, false, true))), 1.0);
    EXPECT_GT(lfd::scoreRecording(two_sensors, two_pads(press, false, true))[1][0], 1.0);
    EXPECT_GT(lfd::scoreRecording(one_sensor, two_pads(press, false, false))[1][0], 1.0);
  }
  EXPECT_THROW(lfd::learnSignature(demos, pads, wide, {"/touch"}), std::invalid_argument);
}

// A noisy pad (teleop-like: a reading at rest is |N(0, 0.45)| N, clipped at 0) strays beyond its
// rest band in one reading of three, its mean over the persistence window does not: a press
// without force is still a missing contact, a nominal press is not.
TEST(SensorySignature, ANoisyPadAtRestIsJudgedOnItsMeanOverThePersistenceWindow) {
  const auto noisy_pad = [](Press p, unsigned seed) {
    p.level *= 0.4;
    lfd::SegmentedRecording r = pressRun(p, seed);
    std::mt19937 rng(seed + 17);
    std::normal_distribution<double> noise(0.0, 0.45);
    for (Eigen::Index i = 0; i < r.features.rows(); ++i)
      r.features.data(i, 0) = std::max(0.0, r.features.data(i, 0) + noise(rng));
    return r;
  };
  std::vector<lfd::SegmentedRecording> demos;
  for (unsigned k = 0; k < 6; ++k) demos.push_back(noisy_pad(varied(k), 1000 + k));
  lfd::SignatureOptions wide = wideSpreadWithRestBands();
  const auto sig = lfd::learnSignature(demos, {"force_z", "gripper"}, wide);
  for (unsigned k = 0; k < 6; ++k) {
    Press missed = varied(40 + k);
    missed.level = 0.0;
    EXPECT_GT(lfd::scoreRecording(sig, noisy_pad(missed, 4000 + k))[1][0], 1.0) << "run " << k;
    EXPECT_LT(worstScore(lfd::scoreRecording(sig, noisy_pad(varied(50 + k), 5000 + k))), 1.0);
  }
}

TEST(SensorySignature, TheLiveMonitorRaisesASlipWithinAFifthOfASecond) {
  const lfd::SensorySignature sig = learned(5);
  Press p = varied(91);
  p.lose_contact_at = p.approach + 1.5;
  const lfd::SegmentedRecording run = pressRun(p, 91);
  lfd::SignatureMonitor monitor(sig);
  double alarm = -1.0;
  for (Eigen::Index i = 0; i < run.features.rows() && alarm < 0; ++i) {
    const double t = run.features.timeAt(i) - run.features.timeAt(0);
    std::size_t s = 0;
    while (s < run.boundaries.size() && t > run.boundaries[s]) ++s;
    const double start = s ? run.boundaries[s - 1] : 0.0;
    const double end =
        s < run.boundaries.size() ? run.boundaries[s] : p.approach + p.press + p.retract;
    const lfd::Deviation d =
        monitor.observe(s, (t - start) / (end - start), t, run.features.data.row(i).transpose());
    if (d.score > 1.0) {
      alarm = t;
      EXPECT_EQ(d.segment, 1u);
      EXPECT_EQ(d.channel_name, "force_z");
    }
  }
  ASSERT_GT(alarm, 0.0) << "the slip was never raised";
  EXPECT_GE(alarm, p.lose_contact_at);
  EXPECT_LE(alarm - p.lose_contact_at, 0.2);
}

TEST(SensorySignature, AGripperThatClosesOnNothingIsFlagged) {
  const lfd::SensorySignature sig = learned(4);
  lfd::SegmentedRecording run = pressRun(varied(33), 33);
  for (Eigen::Index i = 0; i < run.features.rows(); ++i)
    if (run.features.data(i, 1) < 0.05) run.features.data(i, 1) = 0.0;  // closed fully: empty
  const auto scores = lfd::scoreRecording(sig, run);
  EXPECT_GT(scores[1][1], 1.0);
}

TEST(SensorySignature, TheRecordingRateDoesNotMatter) {
  std::vector<lfd::SegmentedRecording> demos;
  for (unsigned k = 0; k < 4; ++k) {
    Press p = varied(k);
    p.rate = 50.0;
    demos.push_back(pressRun(p, 200 + k));
  }
  const auto sig = lfd::learnSignature(demos, {"force_z", "gripper"});
  Press fast = varied(21);
  fast.rate = 400.0;
  EXPECT_LT(worstScore(lfd::scoreRecording(sig, pressRun(fast, 21))), 1.0);
}

TEST(SensorySignature, ThresholdsAreStatisticsOfTheDemonstrations) {
  const lfd::SensorySignature sig = learned(5);
  for (const lfd::SegmentSignature& s : sig.segments) {
    EXPECT_GT(s.channels[0].nominal_score, 0.0);  // a noisy force: the held-out demo strays
    for (const lfd::ChannelSignature& c : s.channels) {
      EXPECT_GE(c.nominal_score, 0.0);
      EXPECT_DOUBLE_EQ(c.threshold, std::max(sig.options.min_threshold,
                                             sig.options.threshold_margin * c.nominal_score));
    }
  }
  EXPECT_NEAR(sig.segments[1].duration_mean, 3.0, 0.3);
}

TEST(SensorySignature, BadDemonstrationsAreRefusedWithTheReason) {
  const auto one = pressRun(varied(1), 1);
  auto expect_refused = [](const std::vector<lfd::SegmentedRecording>& demos,
                           const std::vector<std::string>& channels, const std::string& words) {
    try {
      lfd::learnSignature(demos, channels);
      ADD_FAILURE() << "accepted; expected an error with '" << words << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_refused({one}, {"force_z"}, "at least 2");
  auto fewer = pressRun(varied(2), 2);
  fewer.boundaries.pop_back();
  expect_refused({one, fewer}, {"force_z"}, "boundaries");
  expect_refused({one, one}, {"torque_x"}, "torque_x");
  auto backwards = pressRun(varied(3), 3);
  std::swap(backwards.boundaries[0], backwards.boundaries[1]);
  expect_refused({one, backwards}, {"force_z"}, "increase");
}

TEST(SensorySignature, TheMonitorRefusesAReadingItCannotJudge) {
  const lfd::SensorySignature sig = learned(3);
  lfd::SignatureMonitor monitor(sig);
  EXPECT_THROW(monitor.observe(3, 0.5, 0.0, Eigen::VectorXd::Zero(2)), std::invalid_argument);
  EXPECT_THROW(monitor.observe(0, 0.5, 0.0, Eigen::VectorXd::Zero(3)), std::invalid_argument);
}

}  // namespace
