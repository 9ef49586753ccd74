// Goal generalization: interpolating the DMPs of demos whose goals bracket a new goal.
#include "lfd_core/dmp/dmp_generalization.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace {

constexpr double kDuration = 2.0;

// A family of reach-and-place demos: min-jerk progress toward the goal plus a lift whose height
// grows with the travelled distance (the "shape" the DMPs must carry over to new goals).
Eigen::MatrixXd reach(const Eigen::VectorXd& t, const Eigen::Vector3d& start,
                      const Eigen::Vector3d& goal) {
  Eigen::MatrixXd y(t.size(), 3);
  const double lift = 0.05 + 0.3 * (goal - start).head<2>().norm();
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / kDuration;
    const double mj = 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
    y.row(i) = (start + (goal - start) * mj).transpose();
    y(i, 2) += lift * std::pow(std::sin(M_PI * mj), 2);
  }
  return y;
}

lfd::SegmentDmp learnReach(const Eigen::Vector3d& start, const Eigen::Vector3d& goal,
                           double gripper_goal) {
  lfd::SegmentDemo demo;
  demo.times = Eigen::VectorXd::LinSpaced(400, 0.0, kDuration);
  demo.positions = reach(demo.times, start, goal);
  demo.quaternions.resize(demo.times.size(), 4);
  demo.gripper.resize(demo.times.size());
  const double yaw_goal = std::atan2(goal.y() - start.y(), goal.x() - start.x());
  for (Eigen::Index i = 0; i < demo.times.size(); ++i) {
    const double s = demo.times[i] / kDuration;
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(yaw_goal * s * s * (3 - 2 * s), Eigen::Vector3d::UnitZ()));
    demo.quaternions.row(i) << q.w(), q.x(), q.y(), q.z();
    demo.gripper[i] = 0.08 + (gripper_goal - 0.08) * s * s * (3 - 2 * s);
  }
  return lfd::SegmentDmp::learn(demo);
}

struct DemoSet {
  std::vector<lfd::SegmentDmp> dmps;
  std::vector<Eigen::VectorXd> params;
};

DemoSet bracketingDemos(const Eigen::Vector3d& start) {
  DemoSet set;
  // Goals on the corners of a 40 x 40 cm square on the table plus one off-centre point.
  for (const Eigen::Vector3d& g : {Eigen::Vector3d(0.5, -0.2, 0.8), Eigen::Vector3d(0.9, -0.2, 0.8),
                                   Eigen::Vector3d(0.5, 0.2, 0.8), Eigen::Vector3d(0.9, 0.2, 0.8),
                                   Eigen::Vector3d(0.8, -0.05, 0.8)}) {
    set.dmps.push_back(learnReach(start, g, 0.02));
    set.params.push_back(lfd::goalParameters(set.dmps.back()));
  }
  return set;
}

double rmse(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return std::sqrt((a - b).rowwise().squaredNorm().mean());
}

// A rollout from `start` at rest to `goal`, sampled every dt.
lfd::SegmentTrajectory rolloutBetween(const lfd::SegmentDmp& dmp, const Eigen::Vector3d& start,
                                      const Eigen::Vector3d& goal, double dt) {
  lfd::SegmentRolloutOptions o;
  o.dt = dt;
  o.start_position = start;
  o.goal_position = goal;
  o.start_velocity = Eigen::Vector3d::Zero();
  return dmp.rollout(o);
}

TEST(DmpGeneralization, NewBracketedGoalIsReachedWithTheDemosShape) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  const DemoSet set = bracketingDemos(start);
  const Eigen::Vector3d new_goal(0.65, 0.1, 0.8);  // inside, not a demo goal
  const auto res = lfd::generalizeSegment(set.dmps, set.params, new_goal);
  EXPECT_FALSE(res.outside_demo_range) << res.warning;
  EXPECT_NEAR(res.coefficients.sum(), 1.0, 1e-12);
  EXPECT_NEAR(res.kernel_weights.sum(), 1.0, 1e-12);
  EXPECT_GT(res.bandwidth, 0.0);

  const auto traj = rolloutBetween(res.dmp, start, new_goal, kDuration / 399.0);
  const Eigen::Vector3d end = traj.positions.bottomRows(1).transpose();
  EXPECT_LT((end - new_goal).norm(), 1e-3);

  // Shape: compare against the demo family's trajectory for this goal (never demonstrated).
  const Eigen::MatrixXd truth = reach(traj.times, start, new_goal);
  const double err = rmse(traj.positions, truth);
  RecordProperty("generalization_rmse_m", std::to_string(err));
  // The family's lift grows with |goal - start| (non-linear in the goal), so interpolating 5 demos
  // leaves a few mm: 8 mm bound on a ~36 cm reach with a ~16 cm lift.
  EXPECT_LT(err, 0.008);

  // Plain DMP of the nearest demo, only re-targeted, misses the lift change: LWR must beat it.
  size_t nearest = 0;
  for (size_t j = 1; j < set.params.size(); ++j) {
    if ((set.params[j] - new_goal).norm() < (set.params[nearest] - new_goal).norm()) nearest = j;
  }
  const auto naive = rolloutBetween(set.dmps[nearest], start, new_goal, kDuration / 399.0);
  EXPECT_LT(err, 0.5 * rmse(naive.positions, truth));

  // Gripper and orientation come along on the same phase.
  ASSERT_EQ(traj.gripper.size(), traj.times.size());
  EXPECT_NEAR(traj.gripper[traj.gripper.size() - 1], 0.02, 1e-3);
  ASSERT_EQ(traj.quaternions.rows(), traj.times.size());
}

TEST(DmpGeneralization, LocalLinearBeatsKernelAverageOnLinearTrends) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  const DemoSet set = bracketingDemos(start);
  const Eigen::Vector3d new_goal(0.6, -0.12, 0.8);
  lfd::GeneralizationOptions nw;
  nw.local_linear = false;
  lfd::SegmentRolloutOptions o;
  o.dt = 0.01;
  o.start_position = start;
  o.goal_position = new_goal;
  const Eigen::MatrixXd truth = reach(
      Eigen::VectorXd::LinSpaced(static_cast<int>(kDuration / o.dt + 1e-9) + 1, 0.0, kDuration),
      start, new_goal);
  const double e_lwr =
      rmse(lfd::generalizeSegment(set.dmps, set.params, new_goal).dmp.rollout(o).positions, truth);
  const double e_nw = rmse(
      lfd::generalizeSegment(set.dmps, set.params, new_goal, nw).dmp.rollout(o).positions, truth);
  EXPECT_LT(e_lwr, e_nw);
}

TEST(DmpGeneralization, QueryOnADemoReproducesThatDemo) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  const DemoSet set = bracketingDemos(start);
  lfd::GeneralizationOptions narrow;
  narrow.bandwidth = 0.02;  // kernel concentrated on the demo itself
  const auto res = lfd::generalizeSegment(set.dmps, set.params, set.params[1], narrow);
  EXPECT_GT(res.kernel_weights[1], 0.999);
  EXPECT_LT((res.dmp.position->weights() - set.dmps[1].position->weights()).norm(),
            1e-3 * set.dmps[1].position->weights().norm());
}

// A segment that starts as the gripper closes on an object: in one demo the segment began with the
// fingers still open (they close within 0.2 s), in the others they were already closed. No demo
// opens the gripper, so no mix may: the gripper's shape has nothing to do with where the segment
// goes and is mixed as a convex average (the kernel weights). An affine (local linear) mix gave
// that demo a negative coefficient at goals away from it and turned its closing into an opening
// past the open/close threshold (teleop grasp: the stick dropped in 2 of 10 reproductions).
const std::vector<double> kRidges = {1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0};

TEST(DmpGeneralization, LeaveOneOutKeepsTheLinearTrendOfCleanDemos) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  const DemoSet set = bracketingDemos(start);
  lfd::GeneralizationOptions cv;
  cv.slope_ridge_candidates = kRidges;
  const Eigen::Vector3d new_goal(0.65, 0.1, 0.8);
  const auto res = lfd::generalizeSegment(set.dmps, set.params, new_goal, cv);
  ASSERT_EQ(res.loo_rms.size(), kRidges.size());
  // The lift follows the goal: the held-out demos are predicted best by the local linear fit.
  EXPECT_LE(res.slope_ridge, 0.1);
  EXPECT_LT(res.loo_rms.front(), 0.5 * res.loo_rms.back());
  const auto traj = rolloutBetween(res.dmp, start, new_goal, kDuration / 399.0);
  EXPECT_LT(rmse(traj.positions, reach(traj.times, start, new_goal)), 0.008);
}

// A stroke pressed into the table, the same 12 cm along x wherever it is made, to a depth that
// varies from demo to demo, not with where, and with an operator's slow wobble (a few mm on each
// axis, random phases): a teleoperated wipe's stroke.
const Eigen::Vector3d kStroke(0.12, 0.0, 0.0);

Eigen::MatrixXd press(const Eigen::VectorXd& t, const Eigen::Vector3d& start, double depth,
                      std::mt19937& rng) {
  std::uniform_real_distribution<double> amplitude(-0.003, 0.003), phase(0.0, 2.0 * M_PI);
  Eigen::Matrix<double, 3, 2> a, p;
  for (int k = 0; k < 6; ++k) a(k % 3, k / 3) = amplitude(rng), p(k % 3, k / 3) = phase(rng);
  Eigen::MatrixXd y(t.size(), 3);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / kDuration;
    const double mj = 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
    y.row(i) = (start + kStroke * mj).transpose();
    y(i, 2) -= depth * std::pow(std::sin(M_PI * mj), 2);
    for (int d = 0; d < 3; ++d)  // zero at both ends: the wobble leaves start and goal alone
      for (int f = 0; f < 2; ++f)
        y(i, d) += a(d, f) * std::sin(M_PI * s) * std::sin((f + 2) * M_PI * s + p(d, f));
  }
  return y;
}

double pressedDepth(const lfd::SegmentDmp& dmp, const Eigen::Vector3d& start) {
  return start.z() - rolloutBetween(dmp, start, start + kStroke, 0.005).positions.col(2).minCoeff();
}

TEST(DmpGeneralization, LeaveOneOutDoesNotFitTheNoiseOfTheDemos) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> depth(0.038, 0.048), side(-0.06, 0.06);
  lfd::GeneralizationOptions fixed, cv;
  cv.slope_ridge_candidates = kRidges;
  int fixed_outside = 0;
  double fixed_error = 0.0, cv_error = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    DemoSet set;
    std::vector<double> depths;
    for (int j = 0; j < 6; ++j) {
      const Eigen::Vector3d start(0.45 + side(rng), -0.3 + side(rng), 0.8);
      depths.push_back(depth(rng));
      lfd::SegmentDemo demo;
      demo.times = Eigen::VectorXd::LinSpaced(400, 0.0, kDuration);
      demo.positions = press(demo.times, start, depths.back(), rng);
      set.dmps.push_back(lfd::SegmentDmp::learn(demo));
      set.params.push_back(start + kStroke);
    }
    const auto [lo, hi] = std::minmax_element(depths.begin(), depths.end());
    const double mean = std::accumulate(depths.begin(), depths.end(), 0.0) / depths.size();
    for (const Eigen::Vector3d& start :
         {Eigen::Vector3d(0.46, -0.27, 0.8), Eigen::Vector3d(0.43, -0.33, 0.8)}) {
      const Eigen::Vector3d goal = start + kStroke;
      const auto with_cv = lfd::generalizeSegment(set.dmps, set.params, goal, cv);
      const double d_fixed =
          pressedDepth(lfd::generalizeSegment(set.dmps, set.params, goal, fixed).dmp, start);
      const double d_cv = pressedDepth(with_cv.dmp, start);
      EXPECT_GE(with_cv.slope_ridge, 1.0) << "trial " << trial;
      EXPECT_GE(d_cv, *lo - 1e-4) << "trial " << trial;
      EXPECT_LE(d_cv, *hi + 1e-4) << "trial " << trial;
      fixed_outside += d_fixed < *lo - 1e-4 || d_fixed > *hi + 1e-4;
      fixed_error += std::abs(d_fixed - mean);
      cv_error += std::abs(d_cv - mean);
    }
  }
  // The nearly unregularized fit follows the noise of six demos, past their range at times.
  EXPECT_GT(fixed_outside, 0);
  EXPECT_LT(cv_error, 0.5 * fixed_error);
}

TEST(DmpGeneralization, LeaveOneOutNeedsThreeDemos) {
  const DemoSet set = bracketingDemos(Eigen::Vector3d(0.3, 0.0, 0.9));
  const std::vector<lfd::SegmentDmp> two(set.dmps.begin(), set.dmps.begin() + 2);
  const std::vector<Eigen::VectorXd> params(set.params.begin(), set.params.begin() + 2);
  lfd::GeneralizationOptions cv;
  cv.slope_ridge_candidates = kRidges;
  const auto res = lfd::generalizeSegment(two, params, Eigen::Vector3d(0.7, -0.2, 0.8), cv);
  EXPECT_TRUE(res.loo_rms.empty());
  EXPECT_EQ(res.slope_ridge, cv.slope_ridge);
  EXPECT_THROW(lfd::leaveOneOutRms(two, params, 0.1, 1.0), std::invalid_argument);
  cv.slope_ridge_candidates = {1.0, -1.0};
  EXPECT_THROW(lfd::generalizeSegment(set.dmps, set.params, set.params[0], cv),
               std::invalid_argument);
}

TEST(DmpGeneralization, NoMixOpensAGripperThatNoDemoOpens) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  DemoSet set;
  const Eigen::Vector3d goals[] = {
      {0.5, -0.2, 0.8}, {0.9, -0.2, 0.8}, {0.5, 0.2, 0.8}, {0.9, 0.2, 0.8}, {0.8, -0.05, 0.8}};
  for (int j = 0; j < 5; ++j) {
    lfd::SegmentDemo demo;
    demo.times = Eigen::VectorXd::LinSpaced(400, 0.0, kDuration);
    demo.positions = reach(demo.times, start, goals[j]);
    demo.gripper.resize(demo.times.size());
    for (Eigen::Index i = 0; i < demo.times.size(); ++i)  // 0.2 s: four time constants
      demo.gripper[i] = 0.028 + (j == 1 ? 0.052 * std::exp(-demo.times[i] / 0.05) : 0.0);
    set.dmps.push_back(lfd::SegmentDmp::learn(demo));
    set.params.push_back(lfd::goalParameters(set.dmps.back()));
  }
  // Goals where the local linear fit weighs the closing demo negatively (-0.09, -0.05, -0.03).
  for (const Eigen::Vector3d& query :
       {Eigen::Vector3d(0.55, 0.15, 0.8), Eigen::Vector3d(0.7, 0.2, 0.8),
        Eigen::Vector3d(0.5, 0.0, 0.8)}) {
    const lfd::SegmentTrajectory traj =
        lfd::generalizeSegment(set.dmps, set.params, query).dmp.rollout();
    double rise = 0.0;  // the most the gripper opens past its lowest opening so far
    double lowest = traj.gripper[0];
    for (Eigen::Index i = 0; i < traj.gripper.size(); ++i) {
      lowest = std::min(lowest, traj.gripper[i]);
      rise = std::max(rise, traj.gripper[i] - lowest);
    }
    EXPECT_LT(rise, 5e-4) << query.transpose();
  }
}

TEST(DmpGeneralization, FlagsGoalsOutsideTheDemonstratedRange) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  const DemoSet set = bracketingDemos(start);
  const auto far = lfd::generalizeSegment(set.dmps, set.params, Eigen::Vector3d(1.3, 0.0, 0.8));
  EXPECT_TRUE(far.outside_demo_range);
  EXPECT_NEAR(far.hull_distance, 0.4, 1e-6);
  EXPECT_FALSE(far.warning.empty());
  EXPECT_TRUE(far.dmp.position->weights().allFinite());
  // Slightly above the table plane but within the margin: still covered.
  const auto near = lfd::generalizeSegment(set.dmps, set.params, Eigen::Vector3d(0.7, 0.0, 0.82));
  EXPECT_FALSE(near.outside_demo_range);
  EXPECT_NEAR(near.hull_distance, 0.02, 1e-6);
}

TEST(DmpGeneralization, ConvexHullDistance) {
  Eigen::MatrixXd tri(2, 3);
  tri << 0, 1, 0, 0, 0, 1;
  EXPECT_NEAR(lfd::convexHullDistance(tri, Eigen::Vector2d(0.2, 0.2)), 0.0, 1e-9);
  EXPECT_NEAR(lfd::convexHullDistance(tri, Eigen::Vector2d(1, 1)), std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(lfd::convexHullDistance(tri, Eigen::Vector2d(-1, -1)), std::sqrt(2.0), 1e-9);
}

TEST(DmpGeneralization, RejectsIncompatibleDemos) {
  const Eigen::Vector3d start(0.3, 0.0, 0.9);
  DemoSet set = bracketingDemos(start);
  EXPECT_THROW(lfd::generalizeSegment({}, {}, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(lfd::generalizeSegment(set.dmps, set.params, Eigen::Vector2d::Zero()),
               std::invalid_argument);
  std::vector<Eigen::VectorXd> short_params(set.params.begin(), set.params.end() - 1);
  EXPECT_THROW(lfd::generalizeSegment(set.dmps, short_params, set.params[0]),
               std::invalid_argument);
  lfd::SegmentDemo only_pos;
  only_pos.times = Eigen::VectorXd::LinSpaced(100, 0.0, 1.0);
  only_pos.positions = reach(only_pos.times, start, set.params[0]);
  set.dmps.push_back(lfd::SegmentDmp::learn(only_pos));  // lacks orientation and gripper
  set.params.push_back(set.params[0]);
  EXPECT_THROW(lfd::generalizeSegment(set.dmps, set.params, set.params[0]), std::invalid_argument);
  Eigen::Vector3d nan_query(0.5, std::nan(""), 0.8);
  set.dmps.pop_back();
  set.params.pop_back();
  EXPECT_THROW(lfd::generalizeSegment(set.dmps, set.params, nan_query), std::invalid_argument);
}

}  // namespace

// catkin_add_gtest links gtest without gtest_main (and the static gtest_main archive is then simply
// not pulled in by the standalone build).
int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
