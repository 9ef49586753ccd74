// Placing a boundary by the motion around it in sibling demonstrations (motion_match.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "lfd_core/segmentation/motion_match.hpp"

namespace {

constexpr double kStep = 0.02;  // s

double minJerk(double tau) {
  tau = std::clamp(tau, 0.0, 1.0);
  return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

// A hand coming down onto a surface and stroking along it (x, z on a grid of kStep): z falls
// from `height` to 0 over `descent` s, ending at `touch` s; then strokes along x of period
// `period` s whose amplitude grows over 0.5 s. The touch leaves no mark but the motion's.
Eigen::MatrixXd descentThenStrokes(double touch, double descent, double height, double period,
                                   double seconds) {
  const auto rows = static_cast<Eigen::Index>(std::lround(seconds / kStep)) + 1;
  Eigen::MatrixXd m(rows, 2);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double t = static_cast<double>(r) * kStep, after = t - touch;
    m(r, 1) = height * (1.0 - minJerk((t - (touch - descent)) / descent));
    m(r, 0) = after > 0 ? 0.2 * minJerk(after / 0.5) * std::sin(2 * M_PI * after / period) : 0.0;
  }
  return m;
}

TEST(MotionAround, IsRelativeToTheBoundaryAndClippedAtTheEnds) {
  Eigen::MatrixXd grid(10, 2);
  for (Eigen::Index r = 0; r < 10; ++r) grid.row(r) << static_cast<double>(r), 2.0 * r;
  const lfd::MotionAround around = lfd::motionAround(grid, 2, 3);
  ASSERT_EQ(around.before.rows(), 3);  // clipped at the start: rows 0..2
  ASSERT_EQ(around.after.rows(), 4);   // rows 2..5
  EXPECT_DOUBLE_EQ(around.before(0, 0), -2.0);
  EXPECT_DOUBLE_EQ(around.before(2, 1), 0.0);
  EXPECT_DOUBLE_EQ(around.after(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(around.after(3, 1), 6.0);
  EXPECT_EQ(lfd::motionAround(grid, 9, 3).after.rows(), 1);
}

// Siblings touch at other times, descend at other speeds from other heights and stroke at other
// periods; the demo's touch is found to within 0.1 s over its whole length.
TEST(BestMatchingRow, FindsWhereADescentEndsAndTheStrokesBegin) {
  struct Sibling {
    double touch, descent, height, period;
  };
  const std::vector<Sibling> siblings = {
      {2.0, 0.6, 0.25, 1.0}, {2.8, 0.8, 0.3, 1.2}, {2.4, 0.7, 0.2, 0.9}, {3.1, 0.75, 0.28, 1.1}};
  const std::size_t half = 50;  // 1 s
  std::vector<lfd::MotionAround> felt;
  for (const Sibling& s : siblings)
    felt.push_back(lfd::motionAround(descentThenStrokes(s.touch, s.descent, s.height, s.period, 7),
                                     static_cast<std::size_t>(std::lround(s.touch / kStep)), half));
  const double touch = 2.3;
  const Eigen::MatrixXd demo = descentThenStrokes(touch, 0.65, 0.27, 1.05, 6.5);
  const std::size_t row =
      lfd::bestMatchingRow(demo, felt, 0, static_cast<std::size_t>(demo.rows() - 1), half);
  EXPECT_NEAR(static_cast<double>(row) * kStep, touch, 0.1);
}

TEST(BestMatchingRow, BadArgumentsAreErrors) {
  const Eigen::MatrixXd grid = Eigen::MatrixXd::Zero(20, 2);
  const std::vector<lfd::MotionAround> felt = {lfd::motionAround(grid, 10, 5)};
  EXPECT_THROW(lfd::motionAround(grid, 20, 5), std::invalid_argument);
  EXPECT_THROW(lfd::motionAround(grid, 10, 0), std::invalid_argument);
  EXPECT_THROW(lfd::bestMatchingRow(grid, {}, 0, 19, 5), std::invalid_argument);
  EXPECT_THROW(lfd::bestMatchingRow(grid, felt, 12, 11, 5), std::invalid_argument);
  EXPECT_THROW(lfd::bestMatchingRow(grid, felt, 0, 20, 5), std::invalid_argument);
  EXPECT_THROW(lfd::bestMatchingRow(Eigen::MatrixXd::Zero(20, 3), felt, 0, 19, 5),
               std::invalid_argument);
}

}  // namespace
