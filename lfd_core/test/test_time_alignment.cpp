// Time alignment of a segment's demos: DTW warps to the medoid, the common timing their mean, and
// what it is for: the mix of demos timed differently keeps their sub-motions.
#include "lfd_core/dmp/dmp_generalization.hpp"
#include "lfd_core/segmentation/dtw.hpp"
#include "lfd_core/segmentation/time_alignment.hpp"
#include "strokes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

double minJerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10 - 15 * u + 6 * u * u);
}

// Three wipe strokes between x = -0.08 and +0.08 (a 16 cm stroke), each `stroke[s]` s long and
// starting after a hesitation of `pause[s]` s, turned by `yaw` about z and moved to `at`.
lfd::SegmentDemo strokes(const std::vector<double>& stroke, const std::vector<double>& pause,
                         double yaw = 0.0, const Eigen::Vector3d& at = Eigen::Vector3d::Zero()) {
  double total = 0.0;
  for (int s = 0; s < 3; ++s) total += stroke[s] + pause[s];
  lfd::SegmentDemo d;
  const int m = static_cast<int>(std::lround(total / 0.01)) + 1;  // 100 Hz
  d.times = Eigen::VectorXd::LinSpaced(m, 0.0, total);
  d.positions.resize(m, 3);
  d.gripper.resize(m);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (int k = 0; k < m; ++k) {
    double t = d.times[k], x = -0.08;
    for (int s = 0; s < 3; ++s) {
      const double from = s % 2 == 0 ? -0.08 : 0.08;
      const double u = minJerk((t - pause[s]) / stroke[s]);
      x = from + (-2.0 * from) * u;
      if (t < pause[s] + stroke[s]) break;
      t -= pause[s] + stroke[s];
    }
    d.positions.row(k) = (at + r * Eigen::Vector3d(x, 0.0, 0.002 * std::sin(20.0 * x))).transpose();
    d.gripper[k] = 0.01;
  }
  return d;
}

using lfd_testing::Strokes;

// The strokes along x (the first column; three 16 cm strokes: 2 reversals, 0.16 m).
Strokes countStrokes(const Eigen::MatrixXd& y) {
  const Eigen::VectorXd x = y.col(0);
  return lfd_testing::countStrokes(std::vector<double>(x.data(), x.data() + x.size()));
}

// The two demos learned (after alignment or not) and mixed half and half, rolled out.
Eigen::MatrixXd mixedRollout(const std::vector<lfd::SegmentDemo>& demos) {
  lfd::DmpParameters params;
  params.num_basis = 50;
  std::vector<lfd::SegmentDmp> dmps;
  std::vector<Eigen::VectorXd> where;
  for (size_t j = 0; j < demos.size(); ++j) {
    dmps.push_back(lfd::SegmentDmp::learn(demos[j], params));
    where.push_back(Eigen::VectorXd::Constant(1, static_cast<double>(j)));
  }
  lfd::GeneralizationOptions g;
  g.local_linear = false;
  const Eigen::VectorXd middle = Eigen::VectorXd::Constant(1, 0.5 * (demos.size() - 1.0));
  const lfd::GeneralizationResult mix = lfd::generalizeSegment(dmps, where, middle, g);
  lfd::SegmentRolloutOptions ro;
  ro.dt = 0.005;
  return mix.dmp.rollout(ro).positions;
}

TEST(DtwRows, OneColumnIsTheScalarDtw) {
  const std::vector<double> a = {0, 1, 2, 2, 3, 1, 0}, b = {0, 2, 3, 3, 1, 1};
  const lfd::DtwResult scalar = lfd::dtw(a, b);
  std::vector<std::pair<int, int>> path;
  const double cost = lfd::dtwRows(Eigen::Map<const Eigen::VectorXd>(a.data(), 7),
                                   Eigen::Map<const Eigen::VectorXd>(b.data(), 6), &path);
  EXPECT_DOUBLE_EQ(cost, scalar.cost);
  EXPECT_EQ(path, scalar.path);
}

TEST(TimeAlignment, DemosTimedAlikeAreLeftAsTheyAre) {
  const std::vector<lfd::SegmentDemo> demos = {strokes({1.6, 1.6, 1.6}, {0, 0, 0}),
                                               strokes({1.6, 1.6, 1.6}, {0, 0, 0}, 0.3)};
  const lfd::TimeAlignment a = lfd::alignDemoTiming(demos);
  ASSERT_EQ(a.demos.size(), 2u);
  EXPECT_NEAR(a.yaw[a.reference == 0 ? 1 : 0], a.reference == 0 ? -0.3 : 0.3, 1e-6);
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_LT((a.warps[j] - a.progress).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((a.demos[j].positions - demos[j].positions).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_EQ(a.demos[j].times, demos[j].times);
  }
}

// The acceptance case: the same three strokes, one demo hesitating before its first stroke, the
// other before its third (and elsewhere on the table). Mixed as learned, the strokes of one fall on
// the returns of the other: the middle stroke shrinks to half. Aligned first, the mix keeps three
// full strokes.
TEST(TimeAlignment, TheMixOfStrokesTimedDifferentlyKeepsThreeFullStrokes) {
  const lfd::SegmentDemo first = strokes({1.6, 1.6, 1.6}, {1.6, 0, 0});
  const lfd::SegmentDemo third =
      strokes({1.6, 1.6, 1.6}, {0, 0, 1.6}, 0.0, Eigen::Vector3d(0.05, -0.02, 0.0));
  // Either demo the reference (a tie of two goes to the first): a pause at one end of a demo is
  // matched to the other's first or last sample.
  for (const std::vector<lfd::SegmentDemo>& raw :
       {std::vector<lfd::SegmentDemo>{first, third}, std::vector<lfd::SegmentDemo>{third, first}}) {
    const Strokes before = countStrokes(mixedRollout(raw));
    EXPECT_LT(before.shortest, 0.12) << before.reversals << " reversals";  // what alignment fixes

    const lfd::TimeAlignment aligned = lfd::alignDemoTiming(raw);
    for (size_t j = 0; j < raw.size(); ++j) {  // durations, ends and path kept
      EXPECT_EQ(aligned.demos[j].times, raw[j].times);
      EXPECT_LT((aligned.demos[j].positions.row(0) - raw[j].positions.row(0)).norm(), 1e-12);
      EXPECT_LT((aligned.demos[j].positions.bottomRows(1) - raw[j].positions.bottomRows(1)).norm(),
                1e-12);
      EXPECT_NEAR(aligned.demos[j].positions.col(0).minCoeff(), raw[j].positions.col(0).minCoeff(),
                  1e-3);
    }
    // At any common progress both demos are at the same point of their strokes.
    double sum_sq = 0.0, worst = 0.0;
    const int steps = 200;
    for (int i = 0; i <= steps; ++i) {
      double x[2];
      for (size_t j = 0; j < 2; ++j) {
        const lfd::SegmentDemo& d = aligned.demos[j];
        const Eigen::Index k = std::lround(i * (d.times.size() - 1.0) / steps);
        x[j] = d.positions(k, 0) - raw[j].positions(0, 0);
      }
      sum_sq += (x[0] - x[1]) * (x[0] - x[1]);
      worst = std::max(worst, std::abs(x[0] - x[1]));
    }
    EXPECT_LT(std::sqrt(sum_sq / (steps + 1)), 0.002);
    EXPECT_LT(worst, 0.01);
    const Strokes after = countStrokes(mixedRollout(aligned.demos));
    EXPECT_EQ(after.reversals, 2);
    EXPECT_GT(after.shortest, 0.155);  // the demos' 16 cm
  }
}

// A demo turned about z and moved is compared in its own frame: the same warp as unturned.
TEST(TimeAlignment, DemosInOtherHeadingsAlignAsInTheSameHeading) {
  const lfd::SegmentDemo a = strokes({1.6, 1.6, 1.6}, {0, 0, 0});
  const lfd::SegmentDemo b = strokes({1.0, 1.6, 2.2}, {0, 1.2, 0});
  const lfd::SegmentDemo b_turned =
      strokes({1.0, 1.6, 2.2}, {0, 1.2, 0}, 2.0, Eigen::Vector3d(0.3, -0.2, 0.1));
  const lfd::TimeAlignment same = lfd::alignDemoTiming({a, b});
  const lfd::TimeAlignment turned = lfd::alignDemoTiming({a, b_turned});
  EXPECT_EQ(same.reference, turned.reference);
  EXPECT_NEAR(std::remainder(turned.yaw[1] - same.yaw[1] + 2.0, 2.0 * M_PI), 0.0, 1e-6);
  for (size_t j = 0; j < 2; ++j)
    EXPECT_LT((same.warps[j] - turned.warps[j]).cwiseAbs().maxCoeff(), 1e-6);
  lfd::TimeAlignmentOptions fixed;
  fixed.yaw_invariant = false;  // compared as they are, the turned stroke matches badly
  const lfd::TimeAlignment as_is = lfd::alignDemoTiming({a, b_turned}, fixed);
  EXPECT_GT((same.warps[1] - as_is.warps[1]).cwiseAbs().maxCoeff(), 0.02);
}

// The reference is the medoid, and the common timing is the mean of everyone's: no demo's own
// timing is kept, a hesitation of one demo is spread over the others.
TEST(TimeAlignment, TheCommonTimingIsTheMeanOfTheWarps) {
  const std::vector<lfd::SegmentDemo> demos = {strokes({1.6, 1.6, 1.6}, {0, 0, 0}),
                                               strokes({1.6, 1.6, 1.6}, {0, 0.9, 0}),
                                               strokes({1.2, 1.6, 1.6}, {0, 0, 0})};
  const lfd::TimeAlignment a = lfd::alignDemoTiming(demos);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(a.progress.size());
  for (const Eigen::VectorXd& w : a.warps) {
    EXPECT_DOUBLE_EQ(w[0], 0.0);
    EXPECT_DOUBLE_EQ(w[w.size() - 1], 1.0);
    for (Eigen::Index i = 1; i < w.size(); ++i) EXPECT_GE(w[i], w[i - 1]);
    mean += w / 3.0;
  }
  // The warps' mean progress is the common progress (the timing is everyone's average).
  EXPECT_LT((mean - a.progress).cwiseAbs().maxCoeff(), 0.02);
  // The reference is re-timed too.
  EXPECT_GT((a.warps[a.reference] - a.progress).cwiseAbs().maxCoeff(), 0.03);
}

TEST(TimeAlignment, OneDemoOrNoPositionIsUnchangedAndBadInputIsRefused) {
  const lfd::SegmentDemo d = strokes({1.6, 1.6, 1.6}, {0, 0, 0});
  EXPECT_EQ(lfd::alignDemoTiming({d}).demos[0].positions, d.positions);
  lfd::SegmentDemo grip_only = d;
  grip_only.positions.resize(d.times.size(), 0);
  EXPECT_EQ(lfd::alignDemoTiming({grip_only, grip_only}).demos[1].gripper, d.gripper);
  lfd::TimeAlignmentOptions bad;
  bad.sample_seconds = 0.0;
  EXPECT_THROW(lfd::alignDemoTiming({d, d}, bad), std::invalid_argument);
  bad = {};
  bad.warp_sigma = -1.0;
  EXPECT_THROW(lfd::alignDemoTiming({d, d}, bad), std::invalid_argument);
  lfd::SegmentDemo short_rows = d;
  short_rows.positions.conservativeResize(d.times.size() - 1, 3);
  EXPECT_THROW(lfd::alignDemoTiming({d, short_rows}), std::invalid_argument);
  lfd::SegmentDemo two_d = d;
  two_d.positions.conservativeResize(Eigen::NoChange, 2);
  EXPECT_THROW(lfd::alignDemoTiming({d, two_d}), std::invalid_argument);
}

}  // namespace
