// Repeated and stale sensor readings (stale_readings.hpp): a noisy sensor's cached reading is found
// with its exact extent, a noise-free sensor's resting zeros are not stale, a single channel that
// repeats is not the sensor repeating, and bad arguments are errors; and the joint segmentation's
// sensor steps built on them (contact_sensors.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_core/segmentation/contact_sensors.hpp"
#include "lfd_core/segmentation/stale_readings.hpp"

namespace {

// A noisy 3-channel wrench of `rows` samples; rows [from, to) repeat the reading at `from`.
Eigen::MatrixXd noisyWrench(Eigen::Index rows, Eigen::Index from, Eigen::Index to, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.5);
  Eigen::MatrixXd m(rows, 3);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < 3; ++c) m(r, c) = (r > rows / 2 ? 8.0 : 0.0) + noise(rng);
  for (Eigen::Index r = from + 1; r < to; ++r) m.row(r) = m.row(from);
  return m;
}

// A noise-free touch pad: exactly 0 at rest, a smooth press in the middle.
Eigen::MatrixXd touchPad(Eigen::Index rows) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(rows, 1);
  for (Eigen::Index r = rows / 3; r < 2 * rows / 3; ++r)
    m(r, 0) = 5.0 + std::sin(0.1 * static_cast<double>(r));
  return m;
}

TEST(RepeatedReadings, FindsTheRepeatedStretchExactly) {
  const auto runs = lfd::repeatedReadings(noisyWrench(500, 0, 180, 1), 50);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].begin, 0u);
  EXPECT_EQ(runs[0].end, 180u);
}

TEST(RepeatedReadings, OneChannelRepeatingIsNotTheSensorRepeating) {
  Eigen::MatrixXd m = noisyWrench(500, 0, 0, 2);
  m.col(1).segment(100, 200).setConstant(3.0);  // a saturated or clipped axis
  EXPECT_TRUE(lfd::repeatedReadings(m, 50).empty());
}

TEST(RepeatedReadings, ShorterRepeatsAreChance) {
  EXPECT_TRUE(lfd::repeatedReadings(noisyWrench(500, 200, 240, 3), 50).empty());
}

TEST(StaleReadings, ANoisySensorsCachedReadingIsStale) {
  const std::vector<Eigen::MatrixXd> demos = {noisyWrench(500, 0, 200, 4),
                                              noisyWrench(450, 0, 0, 5), noisyWrench(480, 0, 0, 6)};
  const auto stale = lfd::staleReadings(demos, {50, 50, 50});
  ASSERT_EQ(stale.size(), 3u);
  ASSERT_EQ(stale[0].size(), 1u);
  EXPECT_EQ(stale[0][0].end, 200u);
  EXPECT_TRUE(stale[1].empty());
  EXPECT_TRUE(stale[2].empty());
}

TEST(StaleReadings, ADeadDemoDoesNotOutvoteTheNoise) {
  const Eigen::MatrixXd dead = Eigen::MatrixXd::Constant(400, 3, 0.3);
  const std::vector<Eigen::MatrixXd> demos = {
      noisyWrench(500, 0, 200, 7), dead,
      noisyWrench(500, 0, 150, 8), noisyWrench(450, 0, 0, 9),
      noisyWrench(480, 0, 0, 10),  noisyWrench(470, 0, 0, 11)};
  const auto stale = lfd::staleReadings(demos, {50, 50, 50, 50, 50, 50});
  EXPECT_EQ(stale[0].size(), 1u);
  EXPECT_EQ(stale[2].size(), 1u);
  EXPECT_EQ(stale[1].size(), 1u);  // the whole demo: the caller reports it as dead
}

TEST(StaleReadings, ANoiseFreeSensorsRestIsNotStale) {
  const std::vector<Eigen::MatrixXd> demos = {touchPad(300), touchPad(320), touchPad(310)};
  for (const auto& spans : lfd::staleReadings(demos, {20, 20, 20})) EXPECT_TRUE(spans.empty());
}

// A noise-free touch pad that never changes in one demo while it feels contact in the others did
// not measure there (dead); constant in every demo, it is a sensor the task does not use.
TEST(StaleReadings, ANoiseFreeSensorDeadInOneDemoIsStaleThroughout) {
  const Eigen::MatrixXd dead = Eigen::MatrixXd::Zero(290, 1);
  const auto stale = lfd::staleReadings({touchPad(300), dead, touchPad(310)}, {20, 20, 20});
  EXPECT_TRUE(stale[0].empty());
  ASSERT_EQ(stale[1].size(), 1u);
  EXPECT_EQ(stale[1][0].begin, 0u);
  EXPECT_EQ(stale[1][0].end, 290u);
  EXPECT_TRUE(stale[2].empty());
  for (const auto& spans : lfd::staleReadings({dead, dead}, {20, 20})) EXPECT_TRUE(spans.empty());
}

TEST(StaleReadings, BadArgumentsAreErrors) {
  EXPECT_THROW(lfd::repeatedReadings(touchPad(10), 1), std::invalid_argument);
  EXPECT_THROW(lfd::staleReadings({touchPad(10)}, {5, 5}), std::invalid_argument);
}

}  // namespace

// ---- the joint segmentation's sensor steps (contact_sensors.hpp) --------------------------------

// A wrench cached for its first 300 samples (a driver's stale start), stepping by 8 N at 500: the
// events are found on the rows it measured, at the demo's own indices; the noise's onset where the
// cache ends is no event.
TEST(MeasuredEvents, AStalePrefixIsLeftOutAndTheEventsKeepTheDemosIndices) {
  const Eigen::MatrixXd wrench = noisyWrench(1000, 0, 300, 7);
  lfd::SensoryEventConfig config;
  config.noise_block = 100;
  const lfd::SensorEvents events =
      lfd::measuredEvents(wrench, config, {0, 0, 0}, {lfd::SampleSpan{0, 300}});
  ASSERT_FALSE(events.all.empty());
  for (std::size_t i : events.all) EXPECT_GE(i, 495u);  // nothing where the cached reading ends
  EXPECT_TRUE(std::any_of(events.all.begin(), events.all.end(), [](std::size_t i) {
    return i >= 495 && i <= 510;
  })) << events.all.front();
}

TEST(DropStaleEvents, DropsTheEventsWithinTheMarginOfAStaleStretch) {
  lfd::SensorEvents events;
  events.all = {100, 290, 315, 330, 600};
  for (std::size_t i : events.all) events.details.push_back(lfd::SensoryEvent{i});
  lfd::dropStaleEvents({lfd::SampleSpan{0, 300}}, 20, &events);
  EXPECT_EQ(events.all, (std::vector<std::size_t>{330, 600}));
  ASSERT_EQ(events.details.size(), 2u);
  EXPECT_EQ(events.details[0].index, 330u);
}

// A tracking error that rises and falls with the robot's speed is motion, not contact: left out
// and named; a pad pressed while the arm stands still is kept, renumbered.
TEST(ContactSensors, ASensorThatFollowsTheRobotsSpeedIsNotAContactSensor) {
  std::vector<Eigen::MatrixXd> magnitudes;
  std::vector<Eigen::VectorXd> speeds;
  for (int d = 0; d < 3; ++d) {
    const Eigen::Index n = 400;
    Eigen::VectorXd speed(n);
    Eigen::MatrixXd m(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
      speed[i] = std::max(0.0, std::sin(0.03 * static_cast<double>(i + 10 * d)));
      m(i, 0) = 0.8 * speed[i] + 0.01 * std::cos(0.7 * static_cast<double>(i));
      m(i, 1) = (i > 150 && i < 250 && speed[i] < 0.2) ? 1.0 : 0.0;
    }
    magnitudes.push_back(m);
    speeds.push_back(speed);
  }
  std::vector<std::string> warnings;
  const lfd::SensorSelection contact = lfd::contactSensors({"error_a", "error_b", "pad"}, {0, 0, 1},
                                                           magnitudes, speeds, 0.4, &warnings);
  EXPECT_EQ(contact.names, (std::vector<std::string>{"pad"}));
  EXPECT_EQ(contact.groups, (std::vector<std::size_t>{0}));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("error_a, error_b follows the robot's own speed"), std::string::npos)
      << warnings[0];
}
