// Periodic back-and-forth motion (reciprocating_motion.hpp) on hand-made 2-D paths at 100 Hz.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lfd_core/segmentation/reciprocating_motion.hpp"

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
}

}  // namespace
