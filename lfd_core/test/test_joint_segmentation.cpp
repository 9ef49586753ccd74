// The joint segmentation (joint_segmentation.hpp) through runSegmentationPipeline with the
// procedure kJoint, on small synthetic demos at 50 Hz whose phase durations are drawn from a fixed
// seed: a reach -> press -> retract task with a touch sensor, and pose-only tasks of moves and
// pauses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace {

constexpr double kRate = 50.0;

double minJerk(double tau) {
  tau = std::clamp(tau, 0.0, 1.0);
  return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

// Seconds, the shipped event settings (config/segmentation.yaml: fitted placement, so that a
// sensor leaving or regaining rest is a rest edge, i.e. contact evidence), the joint procedure.
lfd::SegmentationPipelineConfig jointConfig() {
  lfd::SegmentationPipelineConfig config;
  config.seconds = lfd::TimeParameters{};
  config.procedure = lfd::SegmentationProcedure::kJoint;
  config.events.placement = lfd::EventPlacement::kFit;
  config.events.zones_from_rest_edges = true;
  config.events.noise_floor_excursions = 5.0;
  config.events.noise_floor_sigmas = 0.0;
  config.events.rest_edge_sigmas = 1.0;
  return config;
}

// A piecewise motion of the hand (x, y, z): each leg a min-jerk move from the previous point
// to `to`, or a rest (to == the previous point).
struct Leg {
  double seconds = 0.0;
  Eigen::Vector3d to = Eigen::Vector3d::Zero();
};

struct Demo {
  lfd::FeatureMatrix matrix;
  std::vector<double> truth;  // s: the true boundaries
};

// Samples the legs at 50 Hz with pose noise; `touch` (if not null) gives the sensor at time t.
template <typename Touch>
lfd::FeatureMatrix sampleLegs(const Eigen::Vector3d& start, const std::vector<Leg>& legs,
                              std::mt19937* rng, const Touch& touch, bool with_touch) {
  std::normal_distribution<double> noise(0.0, 1.0);
  double total = 0.0;
  for (const Leg& l : legs) total += l.seconds;
  const int n = static_cast<int>(std::floor(total * kRate)) + 1;
  lfd::FeatureMatrix m;
  m.names = {"x", "y", "z"};
  if (with_touch) m.names.push_back("touch");
  m.data.resize(n, static_cast<Eigen::Index>(m.names.size()));
  for (int i = 0; i < n; ++i) {
    const double t = i / kRate;
    m.time.push_back(t);
    Eigen::Vector3d p = start, from = start;
    double t0 = 0.0;
    for (const Leg& l : legs) {
      if (t >= t0) p = from + (l.to - from) * minJerk((t - t0) / l.seconds);
      from = l.to;
      t0 += l.seconds;
    }
    for (int c = 0; c < 3; ++c) m.data(i, c) = p[c] + 0.0002 * noise(*rng);
    if (with_touch) m.data(i, 3) = touch(t, noise(*rng));
  }
  return m;
}

// Reach (the hand moves to the button and stops on it: contact), press (the hand holds still, the
// touch sensor rises to ~5 with noise), retract (the hand leaves: release). Truth: the contact
// onset and the release. With `slide` (m) the hand does not hold still while in contact but
// slides that far along y (a wipe), from the instant of contact to the release. With `snap` the
// press lasts 4-4.5 s and its level steps twice while in contact, 0.6-0.7 s apart (a snap-fit:
// pushed harder until the hook gives, then held lighter), 1.5 s after the onset; both steps are
// boundaries too. The first `slips` demos lose contact for 0.9 s midway through the press (the
// sensor back at rest) and press again: no boundary, a hand slipping off for a moment.
std::vector<Demo> reachPressRetract(int count, unsigned seed, double slide = 0.0, bool snap = false,
                                    int slips = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Demo> demos;
  for (int d = 0; d < count; ++d) {
    const double rest = 0.3 + 0.5 * unit(rng), reach = 2.5 + unit(rng),
                 press = 2.5 + 1.5 * unit(rng), retract = 2.5 + unit(rng),
                 last = 0.3 + 0.5 * unit(rng);
    const Eigen::Vector3d home(0.0, 0.0, 0.3);
    const Eigen::Vector3d button(0.4 + 0.06 * (unit(rng) - 0.5), 0.1 + 0.06 * (unit(rng) - 0.5),
                                 0.05);
    const double hold = snap ? 4.0 + 0.5 * unit(rng) : press;
    const double onset = rest + reach, release = onset + hold;
    const double level = 4.5 + unit(rng);
    const double harder = onset + 1.5, lighter = harder + (snap ? 0.6 + 0.1 * unit(rng) : 0.0);
    const double slip = d < slips ? onset + 0.4 * hold : release + 1.0;
    auto touch = [=](double t, double noise) {
      if (t < onset || t >= release + 0.15 || (t >= slip && t < slip + 0.9)) return 0.0;
      const double ramp = std::min({1.0, (t - onset) / 0.15, (release + 0.15 - t) / 0.15});
      double scale = 1.0;
      if (snap && t >= harder) scale = t < lighter ? 2.0 : 0.6;
      return level * scale * ramp + 0.1 * noise;
    };
    Demo demo;
    const Eigen::Vector3d slid = button + Eigen::Vector3d(0.0, slide, 0.0);
    demo.matrix = sampleLegs(
        home, {{rest, home}, {reach, button}, {hold, slid}, {retract, home}, {last, home}}, &rng,
        touch, true);
    demo.truth = snap ? std::vector<double>{onset, harder, lighter, release}
                      : std::vector<double>{onset, release};
    demos.push_back(std::move(demo));
  }
  return demos;
}

// A snap-fit: reach the seat and stay there pressed (contact, the touch sensor at ~5), push
// harder after 2-3 s (the level rising to 2.2x over 0.7-1.0 s as the hook deflects), then the
// snap: the level falls to 0.3x, the operator's light hold to the end. That hold lies within the
// sensor's rest band (a fraction of its largest change), so the snap reads as contact lost.
// Truth: the contact, the start of the push, the snap.
std::vector<Demo> snapFits(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Demo> demos;
  for (int d = 0; d < count; ++d) {
    const double rest = 0.3 + 0.5 * unit(rng), reach = 2.5 + unit(rng), turn = 2.0 + unit(rng),
                 push = 0.7 + 0.3 * unit(rng), held = 1.5 + unit(rng);
    const Eigen::Vector3d home(0.0, 0.0, 0.3);
    const Eigen::Vector3d seat(0.4 + 0.06 * (unit(rng) - 0.5), 0.1 + 0.06 * (unit(rng) - 0.5),
                               0.05);
    const double onset = rest + reach, harder = onset + turn, snap = harder + push;
    const double level = 4.5 + unit(rng);
    auto touch = [=](double t, double noise) {
      double scale = 0.0;
      if (t >= snap)
        scale = 0.3;
      else if (t >= harder)
        scale = 1.0 + 1.2 * (t - harder) / push;
      else if (t >= onset)
        scale = std::min(1.0, (t - onset) / 0.15);
      return level * scale + 0.1 * noise;
    };
    Demo demo;
    demo.matrix = sampleLegs(home, {{rest, home}, {reach, seat}, {turn + push + held, seat}}, &rng,
                             touch, true);
    demo.truth = {onset, harder, snap};
    demos.push_back(std::move(demo));
  }
  return demos;
}

// Pose only: move -> 2 s pause -> move -> 2 s pause -> move, each move hesitating 0.3 s halfway.
// Truth: where motion resumes after each long pause. `lacking` (>= 0) names a demo without the
// middle move (and its pause): move -> 2 s pause -> move home.
std::vector<Demo> movesAndPauses(int count, unsigned seed, int lacking = -1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Demo> demos;
  for (int d = 0; d < count; ++d) {
    const Eigen::Vector3d home(0.0, 0.0, 0.3);
    const Eigen::Vector3d p1(0.4 + 0.04 * (unit(rng) - 0.5), 0.0, 0.2);
    const Eigen::Vector3d p2(0.4, 0.3 + 0.04 * (unit(rng) - 0.5), 0.2);
    const double rest = 0.3 + 0.4 * unit(rng), last = 0.3 + 0.4 * unit(rng);
    std::vector<Leg> legs = {{rest, home}};
    std::vector<double> truth;
    double t = rest;
    // A move from `from` to `to` in two halves with a 0.3 s hesitation between them.
    auto move = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
      const double half = 0.8 + 0.4 * unit(rng);
      const Eigen::Vector3d mid = 0.5 * (from + to);
      legs.push_back({half, mid});
      legs.push_back({0.3, mid});
      legs.push_back({half, to});
      t += 2.0 * half + 0.3;
    };
    auto pause = [&](const Eigen::Vector3d& at) {
      legs.push_back({2.0, at});
      t += 2.0;
      truth.push_back(t);
    };
    move(home, p1);
    pause(p1);
    if (d != lacking) {
      move(p1, p2);
      pause(p2);
      move(p2, home);
    } else {
      move(p1, home);
    }
    legs.push_back({last, home});
    Demo demo;
    demo.matrix = sampleLegs(
        home, legs, &rng, [](double, double) { return 0.0; }, false);
    demo.truth = truth;
    demos.push_back(std::move(demo));
  }
  return demos;
}

std::vector<lfd::FeatureMatrix> matrices(const std::vector<Demo>& demos) {
  std::vector<lfd::FeatureMatrix> out;
  for (const Demo& d : demos) out.push_back(d.matrix);
  return out;
}

std::string listed(const std::vector<double>& v) {
  std::string out;
  for (double x : v) out += (out.empty() ? "" : ", ") + std::to_string(x);
  return "[" + out + "]";
}

std::string allWarnings(const lfd::SegmentationPipelineResult& r) {
  std::string out;
  for (const std::string& w : r.warnings) out += "\n  " + w;
  return out;
}

// The warnings naming demonstration d that contain `needle`.
std::size_t warningsAbout(const lfd::SegmentationPipelineResult& r, std::size_t d,
                          const std::string& needle) {
  const std::string name = "demonstration " + std::to_string(d) + ":";
  return static_cast<std::size_t>(
      std::count_if(r.warnings.begin(), r.warnings.end(), [&](const std::string& w) {
        return w.find(name) != std::string::npos && w.find(needle) != std::string::npos;
      }));
}

// Each changepoint time of demo d within `tolerance` of its true boundary, as many as the truth.
void expectBoundaries(const lfd::SegmentationPipelineResult& result, const Demo& demo,
                      std::size_t d, double tolerance) {
  const auto& r = result.demos[d];
  ASSERT_EQ(r.changepoint_times.size(), demo.truth.size())
      << "demo " << d << ": got " << listed(r.changepoint_times) << ", truth " << listed(demo.truth)
      << allWarnings(result);
  for (std::size_t k = 0; k < demo.truth.size(); ++k)
    EXPECT_NEAR(r.changepoint_times[k], demo.truth[k], tolerance)
        << "demo " << d << " boundary " << k << ": got " << listed(r.changepoint_times)
        << ", truth " << listed(demo.truth);
}

TEST(JointSegmentation, FindsTheContactOnsetAndReleaseOfEveryDemo) {
  const auto demos = reachPressRetract(6, 11);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) {
    expectBoundaries(result, demos[d], d, 0.2);
    EXPECT_EQ(result.demos[d].changepoint_evidence.size(), result.demos[d].changepoints.size());
    EXPECT_EQ(warningsAbout(result, d, "lack"), 0u) << allWarnings(result);
  }
}

// Kills demo `dead`'s touch sensor and segments: every other demo finds its boundaries, and the
// dead one places each boundary on its own motion near the truth or reports it as lacking.
lfd::SegmentationPipelineResult segmentWithADeadSensor(std::vector<Demo> demos, std::size_t dead) {
  demos[dead].matrix.data.col(3).setConstant(0.0);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  for (std::size_t d = 0; d < demos.size(); ++d)
    if (d != dead) expectBoundaries(result, demos[d], d, 0.2);
  const auto& r = result.demos[dead];
  EXPECT_EQ(r.changepoints.size() + warningsAbout(result, dead, "lack"), 2u)
      << "each of the 2 boundaries is placed or reported: got " << listed(r.changepoint_times)
      << allWarnings(result);
  for (double t : r.changepoint_times) {
    const auto& truth = demos[dead].truth;
    const double off = std::min(std::abs(t - truth[0]), std::abs(t - truth[1]));
    EXPECT_LT(off, 0.5) << "changepoint at " << t << " s, truth " << listed(truth);
  }
  return result;
}

// A dead touch sensor in one demo (constant): the header promises that demo still has its motion
// and ClaSP evidence, and that a boundary it shows no evidence of is reported as lacking, never
// forced. So every agreed boundary is either placed near the truth or named in a warning.
TEST(JointSegmentation, ADemoWithADeadSensorIsSegmentedFromItsMotionOrWarned) {
  const auto result = segmentWithADeadSensor(reachPressRetract(6, 11), 2);
  EXPECT_EQ(warningsAbout(result, 2, "sensor 'touch' is constant"), 1u) << allWarnings(result);
}

// The same task with the hand sliding 25 cm along the surface while in contact (a wipe): the
// contact is no pause of the hand, so nothing folds the onset into the release.
TEST(JointSegmentation, FindsTheContactOnsetAndReleaseOfAWipe) {
  const auto demos = reachPressRetract(6, 11, 0.25);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) expectBoundaries(result, demos[d], d, 0.2);
}

// The dead demo's only evidence near its contact onset of its own is the slide starting after a
// 0.3 s stop (weight 0.22, below min_piece_weight): its onset went to a ClaSP changepoint
// mid-slide, 1.9 s off. Its siblings' motion around their onset places it (motion_match.hpp).
TEST(JointSegmentation, AWipeWithADeadSensorIsSegmentedFromItsMotionOrWarned) {
  const auto result = segmentWithADeadSensor(reachPressRetract(6, 11, 0.25), 2);
  EXPECT_EQ(warningsAbout(result, 2, "placed by the motion around it"), 2u) << allWarnings(result);
}

// A touch sensor with noise at rest too (a strain gauge), whose driver repeats its first reading
// in demo 3 until 0.3 s after the contact onset (a driver that publishes its cached value until
// the device answers): no contact edge there, and its events within a lag of the wake-up are
// dropped. Its onset is placed by its siblings' motion, its release on its own sensor.
TEST(JointSegmentation, AStaleSensorsMissedTouchIsPlacedByTheSiblingsMotion) {
  auto demos = reachPressRetract(6, 11, 0.25);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (Demo& demo : demos)
    for (Eigen::Index i = 0; i < demo.matrix.rows(); ++i) demo.matrix.data(i, 3) += noise(rng);
  const auto wakes = static_cast<Eigen::Index>(std::lround((demos[3].truth[0] + 0.3) * kRate));
  demos[3].matrix.data.col(3).head(wakes).setConstant(demos[3].matrix.data(0, 3));
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  for (std::size_t d = 0; d < demos.size(); ++d) expectBoundaries(result, demos[d], d, 0.5);
  EXPECT_EQ(warningsAbout(result, 3, "placed by the motion around it"), 1u) << allWarnings(result);
  EXPECT_EQ(warningsAbout(result, 3, "repeats one reading"), 1u) << allWarnings(result);
}

// Two demos of six slip off for 0.9 s midway through a wipe and press again: no boundary there.
TEST(JointSegmentation, AContactLostMidwayInTwoDemosIsNoBoundary) {
  const auto demos = reachPressRetract(6, 11, 0.25, false, 2);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) expectBoundaries(result, demos[d], d, 0.2);
}

// Two level steps 0.6-0.7 s apart while the hand presses and slides 40 cm (the snap-fit class's
// insertion and snap; a hand holding still, or sliding slowly, would make the press a pause whose
// inner evidence is gathered to its end): four boundaries in every demo. The demos' evidence is
// added up with a spread narrower than the steps' distance (agreement_spread 0.35 s): with the
// placement's 0.5 s the two steps made one plateau and no demo got both (measured: 0 of 6).
TEST(JointSegmentation, TwoLevelStepsInContactLessThanASecondApartAreTwoBoundaries) {
  const auto demos = reachPressRetract(6, 7, 0.4, true);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) expectBoundaries(result, demos[d], d, 0.3);
}

// The push that ends in the snap is a phase of its own, though the snap reads as contact lost
// less than a second after the push began: a level step joins a contact edge within the ramp
// fold only when it goes the way the edge goes (measured without that rule: the push's start
// was folded onto the snap, two boundaries per demo instead of three).
TEST(JointSegmentation, ARisingPushBeforeASnapThatReadsAsContactLostIsItsOwnPhase) {
  const auto demos = snapFits(6, 11);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) expectBoundaries(result, demos[d], d, 0.3);
}

// Pose only: the long pauses end where a new skill starts; a 0.3 s hesitation inside a move is
// no boundary.
TEST(JointSegmentation, BoundariesAreWhereMotionResumesAfterTheLongPauses) {
  const auto demos = movesAndPauses(6, 5);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) expectBoundaries(result, demos[d], d, 0.3);
}

// Each demo's pauses are reported: the first rest, the last, and the 2 s waits, each ending where
// its boundary is (the 0.3 s hesitations are short pauses, longer than min_pause).
TEST(JointSegmentation, ReportsThePausesOfEachDemo) {
  const auto demos = movesAndPauses(6, 5);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {}, jointConfig());
  for (std::size_t d = 0; d < demos.size(); ++d) {
    const auto& r = result.demos[d];
    const auto seconds = [&](std::size_t row) {
      return demos[d].matrix.timeAt(static_cast<Eigen::Index>(row));
    };
    ASSERT_GE(r.pauses.size(), 2u + demos[d].truth.size()) << "demo " << d;
    EXPECT_EQ(r.pauses.front().begin, 0u);
    EXPECT_EQ(r.pauses.back().end, r.num_samples - 1);
    std::size_t long_waits = 0;
    for (std::size_t k = 1; k + 1 < r.pauses.size(); ++k) {
      const double begin = seconds(r.pauses[k].begin), end = seconds(r.pauses[k].end);
      if (end - begin < 1.0) {
        EXPECT_LT(end - begin, 0.5) << "demo " << d << ": a hesitation is 0.3 s";
        continue;
      }
      ASSERT_LT(long_waits, demos[d].truth.size()) << "demo " << d;
      EXPECT_NEAR(end - begin, 2.0, 0.3) << "demo " << d << " pause " << k;
      EXPECT_NEAR(end, demos[d].truth[long_waits++], 0.3) << "demo " << d << " pause " << k;
    }
    EXPECT_EQ(long_waits, demos[d].truth.size()) << "demo " << d;
  }
}

// One demo skips the middle move: it is reported as lacking that boundary, not given one.
TEST(JointSegmentation, ADemoLackingAPhaseIsReportedNotForced) {
  const std::size_t odd = 3;
  const auto demos = movesAndPauses(6, 5, static_cast<int>(odd));
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {}, jointConfig());
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d)
    if (d != odd) expectBoundaries(result, demos[d], d, 0.3);
  const auto& r = result.demos[odd];
  EXPECT_LT(r.changepoints.size(), 2u) << listed(r.changepoint_times) << allWarnings(result);
  EXPECT_GE(warningsAbout(result, odd, "lack"), 1u) << allWarnings(result);
  // What it has is its one pause's end.
  ASSERT_EQ(r.changepoint_times.size(), 1u) << allWarnings(result);
  EXPECT_NEAR(r.changepoint_times[0], demos[odd].truth[0], 0.3);
}

TEST(JointSegmentation, NeedsAClock) {
  const auto demos = matrices(reachPressRetract(3, 11));
  auto config = jointConfig();
  config.seconds.reset();
  EXPECT_THROW(lfd::runSegmentationPipeline(demos, {"touch"}, config), std::invalid_argument);
  try {
    lfd::runSegmentationPipeline(demos, {"touch"}, config);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("seconds"), std::string::npos) << e.what();
  }
}

}  // namespace
