// Periodic back-and-forth motion (reciprocating_motion.hpp) on hand-made 2-D paths at 100 Hz, and
// the periodic phases of a task's demos (periodic_phases.hpp) on hand-made poses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_core/segmentation/boundary_evidence.hpp"
#include "lfd_core/segmentation/periodic_phases.hpp"
#include "lfd_core/segmentation/reciprocating_motion.hpp"
#include "lfd_core/segmentation/state_features.hpp"

namespace {

constexpr double kRate = 100.0;
constexpr double kPi = 3.14159265358979323846;

double minJerk(double tau) {
  tau = std::min(1.0, std::max(0.0, tau));
  return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

struct Path {
  std::vector<Eigen::Vector2d> points;
  void move(const Eigen::Vector2d& to, double seconds) {
    const Eigen::Vector2d from = points.empty() ? to : points.back();
    const int n = static_cast<int>(seconds * kRate);
    for (int i = 1; i <= n; ++i) points.push_back(from + (to - from) * minJerk(i / double(n)));
  }
  // Strokes out along `along` and back, each cycle its own amplitude (m) and period (s), ending
  // where it started.
  void grate(const Eigen::Vector2d& along, const std::vector<std::pair<double, double>>& cycles) {
    const Eigen::Vector2d at = points.back();
    for (const auto& [amplitude, period] : cycles) {
      const int n = static_cast<int>(period * kRate);
      for (int i = 1; i <= n; ++i)
        points.push_back(at + along * amplitude * (1.0 - std::cos(2.0 * kPi * i / n)) / 2.0);
    }
  }
  double now() const { return static_cast<double>(points.size()) / kRate; }
};

std::vector<double> clock(std::size_t n) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / kRate;
  return t;
}

// Scaled to unit range per axis, with sensor noise.
Eigen::MatrixXd states(const Path& path, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.002);
  Eigen::MatrixXd m(static_cast<Eigen::Index>(path.points.size()), 2);
  for (std::size_t i = 0; i < path.points.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) = path.points[i].transpose();
  for (Eigen::Index c = 0; c < 2; ++c) {
    const double lo = m.col(c).minCoeff(), range = m.col(c).maxCoeff() - lo;
    m.col(c) = (m.col(c).array() - lo) / range;
  }
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index c = 0; c < 2; ++c) m(i, c) += noise(rng);
  return m;
}

// Reach (2.5 s, 30 cm), grate 4 cycles of 3-6 cm and 0.6-1.0 s, retract: one periodic phase, from
// the end of the reach to the start of the retract (within 0.2 s: the smoothed speed's dips).
TEST(ReciprocatingMotion, AGratingBetweenAReachAndARetractIsOnePeriodicPhase) {
  Path path;
  path.move({0.0, 0.0}, 0.5);
  path.move({0.3, 0.1}, 2.5);
  const double begin = path.now();
  path.grate(Eigen::Vector2d(0.6, 0.8), {{0.04, 0.8}, {0.06, 0.9}, {0.03, 0.6}, {0.05, 1.0}});
  const double end = path.now();
  path.move({0.0, 0.05}, 2.0);
  path.move({0.0, 0.05}, 0.5);
  const Eigen::MatrixXd x = states(path, 1);
  const auto runs = lfd::reciprocatingRuns(x, clock(path.points.size()), 0.1);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_NEAR(runs[0].begin / kRate, begin, 0.2);
  EXPECT_NEAR(runs[0].end / kRate, end, 0.2);
}

// Moves between places, some back where the hand came from (out and back once, twice in a row
// to different places): no periodic phase. Neither is a single out-and-back cycle.
TEST(ReciprocatingMotion, MovesToPlacesAndOneOutAndBackAreNoPeriodicPhase) {
  Path path;
  path.move({0.0, 0.0}, 0.5);
  path.move({0.3, 0.0}, 1.5);
  path.move({0.0, 0.0}, 1.5);
  path.move({0.0, 0.3}, 1.2);
  path.move({0.2, 0.2}, 1.0);
  path.grate(Eigen::Vector2d(1.0, 0.0), {{0.05, 0.8}});
  path.move({0.0, 0.0}, 1.5);
  path.move({0.0, 0.0}, 0.5);
  const auto runs = lfd::reciprocatingRuns(states(path, 2), clock(path.points.size()), 0.1);
  EXPECT_TRUE(runs.empty()) << runs.size() << " runs, the first from " << runs[0].begin / kRate;
}

TEST(ReciprocatingMotion, RejectsAClockOfTheWrongLength) {
  EXPECT_THROW(lfd::reciprocatingRuns(Eigen::MatrixXd::Zero(10, 2), clock(9), 0.1),
               std::invalid_argument);
  EXPECT_TRUE(lfd::reciprocatingRuns(Eigen::MatrixXd::Zero(10, 2), clock(10), 0.1).empty());
  EXPECT_THROW(lfd::reciprocatingRuns(Eigen::MatrixXd::Zero(10, 2), Eigen::VectorXd::Zero(9)),
               std::invalid_argument);
}

// A pair's speed from the features' velocities, each smoothed once, is the speed of the pair.
TEST(ReciprocatingMotion, APairsSpeedFromTheFeaturesVelocitiesIsThePairsSpeed) {
  Path path;
  path.move({0.0, 0.0}, 0.5);
  path.move({0.3, 0.1}, 2.5);
  path.grate(Eigen::Vector2d(0.6, 0.8), {{0.04, 0.8}, {0.06, 0.9}, {0.03, 0.6}, {0.05, 1.0}});
  const Eigen::MatrixXd x = states(path, 3);
  const std::vector<double> t = clock(path.points.size());
  const Eigen::MatrixXd v = lfd::stateVelocities(x, t, 0.1);
  EXPECT_LT((v.rowwise().norm() - lfd::stateSpeed(x, t, 0.1)).cwiseAbs().maxCoeff(), 1e-9);
  const auto given = lfd::reciprocatingRuns(x, Eigen::VectorXd(v.rowwise().norm()));
  const auto computed = lfd::reciprocatingRuns(x, t, 0.1);
  ASSERT_EQ(given.size(), computed.size());
  for (std::size_t k = 0; k < given.size(); ++k) {
    EXPECT_EQ(given[k].begin, computed[k].begin);
    EXPECT_EQ(given[k].end, computed[k].end);
  }
}

// ---- periodic phases of a task (periodic_phases.hpp)
// ---------------------------------------------

// A demo's pose as features x, y, z (m) and two quaternion components: qx drifting with a slow
// turn of the wrist over a range of 0.01, qz still; all with 2e-4 of noise.
lfd::FeatureMatrix pose(const std::vector<Eigen::Vector3d>& points, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 2e-4);
  std::uniform_real_distribution<double> phase(0.0, kPi);
  lfd::FeatureMatrix demo;
  demo.names = {"x", "y", "z", "qx", "qz"};
  const auto n = static_cast<Eigen::Index>(points.size());
  demo.data.resize(n, 5);
  demo.time = clock(points.size());
  const double turn = phase(rng), seconds = static_cast<double>(n) / kRate;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kRate;
    const Eigen::Vector3d& p = points[static_cast<std::size_t>(i)];
    demo.data.row(i) << p.x(), p.y(), p.z(),
        0.99 + 0.005 * std::sin(2 * kPi * t / (1.3 * seconds) + turn), 0.0;
    for (Eigen::Index c = 0; c < 5; ++c) demo.data(i, c) += noise(rng);
  }
  return demo;
}

struct Path3 {
  std::vector<Eigen::Vector3d> points;
  void move(Eigen::Vector3d to, double seconds) {  // by value: `to` may be points.back()
    const Eigen::Vector3d from = points.empty() ? to : points.back();
    const int n = static_cast<int>(seconds * kRate);
    for (int i = 1; i <= n; ++i) points.push_back(from + (to - from) * minJerk(i / double(n)));
  }
  void grateAlongX(int cycles, double amplitude, double period) {
    const Eigen::Vector3d at = points.back();
    const int n = static_cast<int>(period * kRate);
    for (int c = 0; c < cycles; ++c)
      for (int i = 1; i <= n; ++i)
        points.push_back(at + Eigen::Vector3d::UnitX() * amplitude *
                                  (1.0 - std::cos(2.0 * kPi * i / n)) / 2.0);
  }
  double now() const { return static_cast<double>(points.size()) / kRate; }
};

std::vector<std::vector<lfd::Pause>> pausesOf(const std::vector<lfd::FeatureMatrix>& demos) {
  const auto moving = lfd::movingStates(demos, demos.front().names);
  const auto scaled = lfd::scaledStates(demos, moving);
  std::vector<std::vector<lfd::Pause>> out;
  for (std::size_t d = 0; d < demos.size(); ++d) {
    const std::vector<double> clock = demos[d].clock();
    out.push_back(lfd::findPauses(lfd::stateSpeed(scaled[d], clock, 0.1), clock, {}));
  }
  return out;
}

// A grater reached along y and z and worked along x, 3-6 strokes of 3-6 cm per demo: II-B would
// keep y and z (x differs from demo to demo), on which the strokes do not show.
struct Grating {
  std::vector<lfd::FeatureMatrix> demos;
  std::vector<std::pair<double, double>> truth;  // per demo, the grating's start and end (s)
};

Grating grating() {
  Grating g;
  for (int d = 0; d < 5; ++d) {
    Path3 path;
    path.move({0.3, 0.2 + 0.01 * d, 0.35}, 0.5);
    path.move({0.32, 0.0, 0.2}, 2.0 + 0.2 * d);
    const double begin = path.now();
    path.grateAlongX(3 + d % 4, 0.03 + 0.008 * d, 0.6 + 0.1 * d);
    g.truth.emplace_back(begin, path.now());
    path.move({0.3, 0.2, 0.4}, 2.0);
    path.move({0.3, 0.2, 0.4}, 0.5);
    g.demos.push_back(pose(path.points, 10u + static_cast<unsigned>(d)));
  }
  return g;
}

TEST(PeriodicPhases, StrokesAlongAFeatureIIBLeftOutAreFoundOnAPairWithoutAContactSensor) {
  const Grating g = grating();
  const auto moving = lfd::movingStates(g.demos, g.demos.front().names);
  const auto runs = lfd::periodicPhases(g.demos, moving, {"y", "z"}, pausesOf(g.demos), false, {});
  for (std::size_t d = 0; d < g.demos.size(); ++d) {
    ASSERT_EQ(runs[d].size(), 1u) << "demo " << d;
    EXPECT_NEAR(runs[d][0].begin / kRate, g.truth[d].first, 0.25) << "demo " << d;
    EXPECT_NEAR(runs[d][0].end / kRate, g.truth[d].second, 0.25) << "demo " << d;
  }
}

// With a contact sensor its events mark the strokes; the pairs are not searched.
TEST(PeriodicPhases, WithAContactSensorOnlyTheSelectedFeaturesAreSearched) {
  const Grating g = grating();
  const auto moving = lfd::movingStates(g.demos, g.demos.front().names);
  const auto runs = lfd::periodicPhases(g.demos, moving, {"y", "z"}, pausesOf(g.demos), true, {});
  for (const auto& demo : runs) EXPECT_TRUE(demo.empty());
}

// Out and back between two places four times, with a still pause of 1 s at each end: an
// operator's separate motions, no periodic phase (each stroke alike, each reversal straight back).
TEST(PeriodicPhases, StrokesSeparatedByPausesAreNoPeriodicPhase) {
  std::vector<lfd::FeatureMatrix> demos;
  for (unsigned d = 0; d < 3; ++d) {
    Path3 path;
    path.move({0.0, 0.0, 0.2}, 0.5);
    for (int k = 0; k < 6; ++k) {
      path.move(k % 2 ? Eigen::Vector3d(0.0, 0.0, 0.2) : Eigen::Vector3d(0.2, 0.1, 0.2), 1.0);
      path.move(path.points.back(), 1.0);
    }
    demos.push_back(pose(path.points, 20u + d));
  }
  const auto moving = lfd::movingStates(demos, demos.front().names);
  const auto runs = lfd::periodicPhases(demos, moving, {"x", "y"}, pausesOf(demos), false, {});
  for (const auto& demo : runs) EXPECT_TRUE(demo.empty()) << demo.size() << " runs";
}

TEST(PeriodicPhases, RejectsDemosWithoutTheirPauses) {
  const Grating g = grating();
  EXPECT_THROW(lfd::periodicPhases(g.demos, {"x", "y"}, {}, {}, false, {}), std::invalid_argument);
}

TEST(StateFeatures, AFeatureThatOnlyJittersIsNotAboveItsNoise) {
  const Grating g = grating();
  const auto moving = lfd::movingStates(g.demos, g.demos.front().names);
  EXPECT_EQ(moving.size(), 5u);  // qz's noise moves it
  EXPECT_EQ(lfd::featuresAboveNoise(g.demos, moving, 20.0),
            (std::vector<std::string>{"x", "y", "z", "qx"}));
}

}  // namespace
