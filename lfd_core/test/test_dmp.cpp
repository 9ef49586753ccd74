// Position / gripper DMP tests: reproduction accuracy, settling past the duration, start ~ goal,
// moving goals, bad input.
#include "dmp_test_curves.hpp"
#include "lfd_core/dmp/dmp_canonical.hpp"
#include "lfd_core/dmp/position_dmp.hpp"
#include "lfd_core/dmp/segment_dmp.hpp"
#include "lfd_core/segmentation/smooth_derivatives.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using lfd::DmpParameters;
using lfd::PositionDmp;
using lfd::PositionRolloutOptions;

constexpr double kDuration = 2.0;
constexpr int kSamples = 1000;

Eigen::VectorXd demoTimes(int samples = kSamples, double duration = kDuration) {
  return Eigen::VectorXd::LinSpaced(samples, 0.0, duration);
}

double reproductionRmsePercent(const Eigen::MatrixXd& demo) {
  const Eigen::VectorXd t = demoTimes();
  const PositionDmp dmp = PositionDmp::learn(t, demo);
  PositionRolloutOptions o;
  o.dt = t[1] - t[0];
  const auto traj = dmp.rollout(o);
  EXPECT_EQ(traj.positions.rows(), demo.rows());
  return 100.0 * lfd_test::rmse(traj.positions, demo) / lfd_test::extent(demo);
}

TEST(GaussianBasis, ActivationsArePartitionOfUnityTimesPhase) {
  const lfd::CanonicalSystem cs;
  const lfd::GaussianBasis basis(30, cs);
  std::vector<double> row(30);
  for (double x : {1.0, 0.5, 0.1, 0.01, 1e-3, 1e-5, 0.0}) {
    basis.gatedActivationsDense(x, row.data());
    double sum = 0.0;
    for (double v : row) {
      EXPECT_GE(v, 0.0);
      sum += v;
    }
    EXPECT_NEAR(sum, x, 1e-12 * std::max(1.0, x)) << "x = " << x;
  }
  EXPECT_THROW(lfd::GaussianBasis(1, cs), std::invalid_argument);
}

TEST(SmoothDerivatives, ExactForPolynomialsOnNonUniformTimes) {
  Eigen::VectorXd t(40);
  for (int i = 0; i < 40; ++i) t[i] = 0.05 * i + 0.01 * std::sin(i);  // non-uniform, increasing
  Eigen::MatrixXd y(40, 1);
  for (int i = 0; i < 40; ++i) y(i, 0) = 2 * std::pow(t[i], 3) - t[i] * t[i] + 3;
  const auto d = lfd::smoothDerivatives(t, y);
  for (int i = 0; i < 40; ++i) {
    EXPECT_NEAR(d.velocity(i, 0), 6 * t[i] * t[i] - 2 * t[i], 1e-8);
    EXPECT_NEAR(d.acceleration(i, 0), 12 * t[i] - 2, 1e-7);
  }
}

// The demo smoother removes tremor-band noise, keeps the slow motion and lines (in the interior;
// at the ends it averages one-sided, as for a recording that starts and ends at rest).
TEST(GaussianSmooth, RemovesTremorKeepsMotionAndLines) {
  const int m = 2000;
  Eigen::VectorXd t(m);
  for (int i = 0; i < m; ++i) t[i] = 0.005 * i + 0.001 * std::sin(0.7 * i);  // non-uniform
  const double sigma = 0.05;
  Eigen::MatrixXd y(m, 3);
  for (int i = 0; i < m; ++i) {
    y(i, 0) = 0.3 - 0.2 * t[i];                  // a line
    y(i, 1) = std::sin(2 * M_PI * 0.5 * t[i]);   // 0.5 Hz motion
    y(i, 2) = std::sin(2 * M_PI * 10.0 * t[i]);  // 10 Hz tremor
  }
  const Eigen::MatrixXd s = lfd::gaussianSmooth(t, y, sigma);
  // Gains in the interior (2 s of margin) against exp(-2 (pi sigma f)^2).
  const Eigen::Index a = 400, n = m - 800;
  EXPECT_LT((s.col(0) - y.col(0)).segment(a, n).cwiseAbs().maxCoeff(), 2e-5);  // 0.2 s x 1e-4 s
  EXPECT_LT(std::abs(s(0, 2)), 0.3);  // the one-sided ends still damp the tremor (to 29 %)
  const double gain_slow = std::exp(-2 * std::pow(M_PI * sigma * 0.5, 2));
  EXPECT_LT((s.col(1) - gain_slow * y.col(1)).segment(a, n).cwiseAbs().maxCoeff(), 0.01);
  EXPECT_GT(gain_slow, 0.98);
  EXPECT_LT(s.col(2).segment(a, n).cwiseAbs().maxCoeff(), 0.01);  // 1 % of the tremor is left
  EXPECT_EQ(lfd::gaussianSmooth(t, y, 0.0), y);
  EXPECT_THROW(lfd::gaussianSmooth(t, y, -0.1), std::invalid_argument);
  EXPECT_THROW(lfd::gaussianSmooth(t.head(10), y, sigma), std::invalid_argument);
  Eigen::MatrixXd bad = y;
  bad(5, 1) = std::nan("");
  EXPECT_THROW(lfd::gaussianSmooth(t, bad, sigma), std::invalid_argument);
}

TEST(PositionDmp, Reproduces2dCurveWithin0p1PercentOfExtent) {
  const double pct = reproductionRmsePercent(lfd_test::curve2d(demoTimes(), kDuration));
  RecordProperty("rmse_percent_2d", std::to_string(pct));
  EXPECT_LT(pct, 0.1);
}

TEST(PositionDmp, Reproduces3dCurveWithin0p1PercentOfExtent) {
  const double pct = reproductionRmsePercent(lfd_test::curve3d(demoTimes(), kDuration));
  RecordProperty("rmse_percent_3d", std::to_string(pct));
  EXPECT_LT(pct, 0.1);
}

TEST(PositionDmp, FewBasisFunctionsAreWorseThanMany) {
  // Guards against a test that passes whatever the fit does.
  const Eigen::VectorXd t = demoTimes();
  const Eigen::MatrixXd demo = lfd_test::curve2d(t, kDuration);
  DmpParameters coarse;
  coarse.num_basis = 4;
  PositionRolloutOptions o;
  o.dt = t[1] - t[0];
  const auto bad = PositionDmp::learn(t, demo, coarse).rollout(o);
  EXPECT_GT(100.0 * lfd_test::rmse(bad.positions, demo) / lfd_test::extent(demo), 0.5);
}

TEST(PositionDmp, SettlesAtGoalWhenRolledOutPastDuration) {
  const Eigen::VectorXd t = demoTimes();
  const Eigen::MatrixXd demo = lfd_test::curve3d(t, kDuration);
  const PositionDmp dmp = PositionDmp::learn(t, demo);
  PositionRolloutOptions o;
  o.dt = 0.002;
  o.duration = 1.5 * kDuration;
  const auto traj = dmp.rollout(o);
  const Eigen::Vector3d goal = demo.row(demo.rows() - 1).transpose();
  const double ext = lfd_test::extent(demo);
  // Final position error and residual speed at 1.5 tau.
  // (The demo ends at zero velocity but non-zero acceleration, the hard case for settling.)
  const double final_error = (traj.positions.bottomRows(1).transpose() - goal).norm();
  RecordProperty("final_error_percent_at_1p5_tau", std::to_string(100.0 * final_error / ext));
  EXPECT_LT(final_error, 2e-4 * ext);
  EXPECT_LT(traj.velocities.bottomRows(1).norm(), 2e-3 * ext / kDuration);
  // No drift anywhere after tau.
  double worst = 0.0;
  for (Eigen::Index k = 0; k < traj.positions.rows(); ++k) {
    if (traj.times[k] >= kDuration) {
      worst = std::max(worst, (traj.positions.row(k).transpose() - goal).norm());
    }
  }
  EXPECT_LT(worst, 2e-3 * ext);
  // And with a new goal, it ends at the new goal.
  o.goal = goal + Eigen::Vector3d(0.1, -0.05, 0.02);
  const auto moved = dmp.rollout(o);
  EXPECT_LT((moved.positions.bottomRows(1).transpose() - *o.goal).norm(), 1e-3 * ext);
}

TEST(PositionDmp, StartEqualsGoalAxisStaysBounded) {
  // Axis 1 starts and ends at the same value but moves in between (a bump): a (g - y0)-scaled
  // DMP would divide by ~0 here. Axis 2 does not move at all.
  const Eigen::VectorXd t = demoTimes();
  Eigen::MatrixXd demo(t.size(), 3);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / kDuration;
    demo(i, 0) = 0.3 * s;
    demo(i, 1) = 0.1 * std::sin(M_PI * s) * std::sin(M_PI * s);
    demo(i, 2) = 0.5;
  }
  demo(t.size() - 1, 1) = demo(0, 1);  // exactly equal start and goal
  const PositionDmp dmp = PositionDmp::learn(t, demo);
  EXPECT_TRUE(dmp.weights().allFinite());
  PositionRolloutOptions o;
  o.dt = t[1] - t[0];
  const auto traj = dmp.rollout(o);
  EXPECT_LT(lfd_test::rmse(traj.positions, demo), 1e-3 * 0.3);
  EXPECT_LT(traj.positions.col(1).cwiseAbs().maxCoeff(), 0.11);
  EXPECT_LT((traj.positions.col(2).array() - 0.5).abs().maxCoeff(), 1e-9);
  // A slightly different goal on the flat axis must not blow the bump up.
  o.goal = Eigen::Vector3d(0.3, 1e-6, 0.5 + 1e-6);
  const auto moved = dmp.rollout(o);
  EXPECT_LT(moved.positions.col(1).cwiseAbs().maxCoeff(), 0.11);
  EXPECT_LT((moved.positions.col(2).array() - 0.5).abs().maxCoeff(), 1e-5);
}

TEST(PositionDmp, MovingGoalStaysSmooth) {
  const Eigen::VectorXd t = demoTimes();
  const Eigen::MatrixXd demo = lfd_test::curve3d(t, kDuration);
  lfd::SegmentDemo seg;
  seg.times = t;
  seg.positions = demo;
  const lfd::SegmentDmp dmp = lfd::SegmentDmp::learn(seg);
  const Eigen::Vector3d new_goal =
      demo.row(demo.rows() - 1).transpose() + Eigen::Vector3d(0.05, 0.08, -0.03);
  const double dt = 0.002;
  for (double filter : {0.0, 20.0}) {
    lfd::SegmentRolloutOptions o;
    o.dt = dt;
    o.goal_filter = filter;
    lfd::SegmentDmpRunner runner(dmp, o);
    std::vector<Eigen::Vector3d> pos, vel;
    for (int k = 0; runner.time() < 1.5 * kDuration; ++k) {
      if (k == 500) runner.setGoal({new_goal, std::nullopt, std::nullopt});  // mid-movement
      runner.step(dt);
      pos.push_back(runner.position());
      vel.push_back(runner.velocity());
    }
    double max_dv = 0.0, max_dp = 0.0;
    for (size_t k = 1; k < vel.size(); ++k) {
      max_dv = std::max(max_dv, (vel[k] - vel[k - 1]).norm());
      max_dp = std::max(max_dp, (pos[k] - pos[k - 1]).norm());
    }
    // Continuous: no step in position or velocity larger than the goal jump allows over one dt.
    EXPECT_LT(max_dp, 0.5 * dt) << "filter " << filter;  // speed < 0.5 m/s everywhere
    EXPECT_LT(max_dv, 0.02) << "filter " << filter;      // acceleration < 10 m/s^2
    EXPECT_LT((pos.back() - new_goal).norm(), 1e-3) << "filter " << filter;
  }
}

// A rollout with a goal switch is the plain rollout up to the switch, then the runner's moved-goal
// motion: the executor relies on this to replan a running segment without moving what is done.
TEST(SegmentDmp, RolloutGoalSwitchKeepsThePastAndReachesTheNewGoal) {
  const Eigen::VectorXd t = demoTimes();
  lfd::SegmentDemo seg;
  seg.times = t;
  seg.positions = lfd_test::curve3d(t, kDuration);
  const lfd::SegmentDmp dmp = lfd::SegmentDmp::learn(seg);
  lfd::SegmentRolloutOptions plain;
  plain.dt = 0.002;
  plain.goal_filter = 20.0;
  const lfd::SegmentTrajectory before = dmp.rollout(plain);
  const Eigen::Vector3d new_goal =
      seg.positions.bottomRows(1).transpose() + Eigen::Vector3d(0.05, -0.04, 0.02);
  lfd::SegmentRolloutOptions switched = plain;
  switched.duration = 1.5 * kDuration;
  switched.goal_switches.push_back({0.8, {Eigen::VectorXd(new_goal), std::nullopt, std::nullopt}});
  const lfd::SegmentTrajectory after = dmp.rollout(switched);
  const int at = static_cast<int>(std::lround(0.8 / plain.dt));
  EXPECT_EQ(after.positions.topRows(at + 1), before.positions.topRows(at + 1));
  EXPECT_GT((after.positions.row(at + 1) - before.positions.row(at + 1)).norm(), 0.0);
  EXPECT_LT((after.positions.bottomRows(1).transpose() - new_goal).norm(), 1e-3);
  double max_dv = 0.0;
  for (Eigen::Index k = 1; k < after.velocities.rows(); ++k)
    max_dv = std::max(max_dv, (after.velocities.row(k) - after.velocities.row(k - 1)).norm());
  EXPECT_LT(max_dv, 0.02);  // acceleration < 10 m/s^2: the filtered goal moves smoothly
  switched.goal_switches.front().time = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(dmp.rollout(switched), std::invalid_argument);
}

TEST(PositionDmp, ExactDiscretizationIsDtIndependent) {
  const Eigen::VectorXd t = demoTimes();
  const Eigen::MatrixXd demo = lfd_test::curve2d(t, kDuration);
  const PositionDmp dmp = PositionDmp::learn(t, demo);
  PositionRolloutOptions fine, coarse;
  fine.dt = 0.001;
  coarse.dt = 0.02;
  const auto a = dmp.rollout(fine);
  const auto b = dmp.rollout(coarse);
  double max_err = 0.0;
  for (Eigen::Index k = 0; k < b.positions.rows(); ++k) {
    max_err = std::max(max_err, (b.positions.row(k) - a.positions.row(20 * k)).norm());
  }
  EXPECT_LT(max_err, 2e-3 * lfd_test::extent(demo));
}

TEST(PositionDmp, TemporalScalingKeepsThePath) {
  const Eigen::VectorXd t = demoTimes();
  const Eigen::MatrixXd demo = lfd_test::curve3d(t, kDuration);
  const PositionDmp dmp = PositionDmp::learn(t, demo);
  PositionRolloutOptions o;
  o.dt = 2.0 * (t[1] - t[0]);
  o.tau = 2.0 * kDuration;
  o.start_velocity = dmp.startVelocity() / 2.0;
  const auto slow = dmp.rollout(o);
  EXPECT_EQ(slow.positions.rows(), demo.rows());
  EXPECT_LT(100.0 * lfd_test::rmse(slow.positions, demo) / lfd_test::extent(demo), 0.1);
}

TEST(PositionDmp, BadInputGivesClearErrors) {
  const Eigen::VectorXd t = demoTimes(5);
  EXPECT_THROW(PositionDmp::learn(t, Eigen::MatrixXd::Zero(5, 3)), std::invalid_argument);
  Eigen::VectorXd t20 = demoTimes(20);
  Eigen::MatrixXd y = Eigen::MatrixXd::Random(20, 3);
  y(7, 2) = std::numeric_limits<double>::quiet_NaN();
  try {
    PositionDmp::learn(t20, y);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 7"), std::string::npos) << e.what();
  }
  Eigen::VectorXd bad_t = t20;
  bad_t[10] = bad_t[9];
  EXPECT_THROW(PositionDmp::learn(bad_t, Eigen::MatrixXd::Zero(20, 3)), std::invalid_argument);
  EXPECT_THROW(PositionDmp::learn(t20, Eigen::MatrixXd::Zero(19, 3)), std::invalid_argument);
  const PositionDmp dmp = PositionDmp::learn(t20, Eigen::MatrixXd::Random(20, 3));
  PositionRolloutOptions o;
  o.goal = Eigen::Vector2d(1, 2);
  EXPECT_THROW(dmp.rollout(o), std::invalid_argument);
  o.goal.reset();
  o.dt = 0.0;
  EXPECT_THROW(dmp.rollout(o), std::invalid_argument);
  DmpParameters p;
  p.num_basis = 1;
  EXPECT_THROW(PositionDmp::learn(t20, Eigen::MatrixXd::Zero(20, 3), p), std::invalid_argument);
}

TEST(GripperDmp, SharesThePhaseAndReproducesAClosingGripper) {
  const Eigen::VectorXd t = demoTimes();
  lfd::SegmentDemo seg;
  seg.times = t;
  seg.positions = lfd_test::curve3d(t, kDuration);
  seg.gripper.resize(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    seg.gripper[i] = 0.08 / (1.0 + std::exp((t[i] - 1.4) * 12.0));  // opening 8 cm -> closed
  }
  const lfd::SegmentDmp dmp = lfd::SegmentDmp::learn(seg);
  ASSERT_TRUE(dmp.gripper.has_value());
  lfd::SegmentRolloutOptions o;
  o.dt = t[1] - t[0];
  const auto traj = dmp.rollout(o);
  EXPECT_LT(lfd_test::rmse(traj.gripper, seg.gripper), 1e-4);
  EXPECT_LT(100.0 * lfd_test::rmse(traj.positions, seg.positions) / lfd_test::extent(seg.positions),
            0.1);
  // Same phase: the gripper closes at the same fraction of a slowed-down movement.
  o.tau = 2 * kDuration;
  o.dt = 2 * (t[1] - t[0]);
  o.start_velocity = dmp.position->startVelocity() / 2.0;
  const auto slow = dmp.rollout(o);
  EXPECT_LT(lfd_test::rmse(slow.gripper, seg.gripper), 1e-3);
}

}  // namespace

// catkin_add_gtest links gtest without gtest_main (and the static gtest_main archive is then simply
// not pulled in by the standalone build).
int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
