// Orientation DMP (Ude et al. 2014 form) tests: log/exp maps, reproduction, goal reaching,
// sign flips, non-unit input, bad input.
#include "lfd_core/dmp/orientation_dmp.hpp"
#include "lfd_core/dmp/quaternion_log.hpp"
#include "lfd_core/dmp/segment_dmp.hpp"

#include "dmp_test_curves.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using lfd::OrientationDmp;
using lfd::OrientationRolloutOptions;

constexpr double kDuration = 2.0;
constexpr int kSamples = 1000;

double angleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return 2.0 * std::acos(std::min(1.0, std::abs(a.coeffs().dot(b.coeffs()))));
}

Eigen::Quaterniond rowQuat(const Eigen::MatrixXd& m, Eigen::Index r) {
  return Eigen::Quaterniond(m(r, 0), m(r, 1), m(r, 2), m(r, 3));
}

// A smooth demo: rotation about a slowly changing axis, ~100 degrees overall, starting at rest.
Eigen::MatrixXd orientationDemo(const Eigen::VectorXd& t) {
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 0, 1)));
  Eigen::MatrixXd rows(t.size(), 4);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / kDuration;
    const double mj = 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
    const Eigen::Vector3d rotvec(1.2 * mj, 0.6 * std::sin(M_PI * mj), -0.8 * mj);
    const Eigen::Quaterniond q = lfd::quaternionExp(0.5 * rotvec) * q0;
    rows.row(i) << q.w(), q.x(), q.y(), q.z();
  }
  return rows;
}

TEST(QuaternionLog, ExpInvertsLogAndErrorIsTheRotationVector) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  for (double angle : {0.0, 1e-9, 0.3, 1.5, 3.0}) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis));
    const Eigen::Vector3d r = lfd::quaternionLog(q);
    EXPECT_NEAR((2.0 * r - angle * axis).norm(), 0.0, 1e-12) << angle;
    EXPECT_NEAR(angleBetween(lfd::quaternionExp(r), q), 0.0, 1e-7) << angle;
    // -q is the same rotation: log picks the shortest arc.
    Eigen::Quaterniond neg(q);
    neg.coeffs() = -neg.coeffs();
    EXPECT_NEAR((lfd::quaternionLog(neg) - r).norm(), 0.0, 1e-12);
    // e(q) = 2 log(g * conj(q)) rotates q onto g.
    const Eigen::Quaterniond g(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()));
    const Eigen::Quaterniond start = Eigen::Quaterniond(Eigen::AngleAxisd(-angle, axis)) * g;
    EXPECT_NEAR((lfd::orientationError(g, start) - angle * axis).norm(), 0.0, 1e-9);
  }
}

TEST(OrientationDmp, ReproducesDemoAndReachesGoal) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(kSamples, 0.0, kDuration);
  const Eigen::MatrixXd demo = orientationDemo(t);
  const OrientationDmp dmp = OrientationDmp::learn(t, demo);
  EXPECT_FALSE(dmp.normalizedInput());
  OrientationRolloutOptions o;
  o.dt = t[1] - t[0];
  o.duration = 1.5 * kDuration;
  const auto traj = dmp.rollout(o);
  double max_err = 0.0;
  for (Eigen::Index i = 0; i < demo.rows(); ++i) {
    max_err = std::max(max_err, angleBetween(rowQuat(traj.quaternions, i), rowQuat(demo, i)));
  }
  RecordProperty("orientation_max_error_rad", std::to_string(max_err));
  EXPECT_LT(max_err, 1e-3);  // of a ~1.5 rad rotation
  const Eigen::Quaterniond goal = rowQuat(demo, demo.rows() - 1);
  EXPECT_LT(angleBetween(rowQuat(traj.quaternions, traj.quaternions.rows() - 1), goal), 1e-4);
  // Unit norm all along.
  for (Eigen::Index i = 0; i < traj.quaternions.rows(); ++i) {
    EXPECT_NEAR(traj.quaternions.row(i).norm(), 1.0, 1e-12);
  }
  // A new goal orientation is reached.
  o.goal = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())) * goal;
  const auto moved = dmp.rollout(o);
  EXPECT_LT(angleBetween(rowQuat(moved.quaternions, moved.quaternions.rows() - 1), *o.goal), 1e-3);
  // Goal given in the other hemisphere (-q) is the same orientation: same result.
  Eigen::Quaterniond neg_goal(*o.goal);
  neg_goal.coeffs() = -neg_goal.coeffs();
  o.goal = neg_goal;
  const auto moved_neg = dmp.rollout(o);
  EXPECT_LT(angleBetween(rowQuat(moved_neg.quaternions, moved_neg.quaternions.rows() - 1),
                         rowQuat(moved.quaternions, moved.quaternions.rows() - 1)),
            1e-9);
}

TEST(OrientationDmp, SignFlipsAndNonUnitInputGiveTheSameDmp) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(300, 0.0, kDuration);
  const Eigen::MatrixXd clean = orientationDemo(t);
  Eigen::MatrixXd messy = clean;
  for (Eigen::Index i = 0; i < messy.rows(); ++i) {
    if (i % 7 == 3) messy.row(i) *= -1.0;           // sign flips (same rotations)
    messy.row(i) *= 1.0 + 0.3 * std::sin(0.1 * i);  // non-unit norms
  }
  const OrientationDmp a = OrientationDmp::learn(t, clean);
  const OrientationDmp b = OrientationDmp::learn(t, messy);
  EXPECT_TRUE(b.normalizedInput());
  EXPECT_GT(b.signFlips(), 0);
  EXPECT_EQ(a.signFlips(), 0);
  EXPECT_LT((a.weights() - b.weights()).cwiseAbs().maxCoeff(), 1e-8 * (1 + a.weights().norm()));
  // The bundle reports the normalization as a warning.
  lfd::SegmentDemo seg;
  seg.times = t;
  seg.quaternions = messy;
  const lfd::SegmentDmp sd = lfd::SegmentDmp::learn(seg);
  ASSERT_EQ(sd.warnings.size(), 1u);
  EXPECT_NE(sd.warnings[0].find("normalized"), std::string::npos);
}

// A task frame is only usable if rotating a learned skill is the same as learning the rotated
// demonstration, and rolling the rotated skill out gives the rotated motion.
TEST(SegmentDmp, RotatedSkillIsTheSkillOfTheRotatedDemo) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, kDuration);
  lfd::SegmentDemo demo;
  demo.times = t;
  demo.positions = lfd_test::curve3d(t, kDuration);
  demo.quaternions = orientationDemo(t);
  demo.gripper = Eigen::VectorXd::LinSpaced(t.size(), 0.08, 0.0);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.2, -0.4, 1.0).normalized()).toRotationMatrix();
  const Eigen::Quaterniond qr(r);

  lfd::SegmentDemo turned = demo;
  turned.positions = demo.positions * r.transpose();
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const Eigen::Quaterniond q = qr * rowQuat(demo.quaternions, i);
    turned.quaternions.row(i) << q.w(), q.x(), q.y(), q.z();
  }
  const lfd::SegmentDmp skill = lfd::SegmentDmp::learn(demo);
  const lfd::SegmentDmp rotated = skill.rotated(r);
  const lfd::SegmentDmp learned_turned = lfd::SegmentDmp::learn(turned);
  const double wscale =
      1.0 + skill.position->weights().norm() + skill.orientation->weights().norm();
  EXPECT_LT((rotated.position->weights() - learned_turned.position->weights()).norm(),
            1e-9 * wscale);
  EXPECT_LT((rotated.orientation->weights() - learned_turned.orientation->weights()).norm(),
            1e-9 * wscale);
  EXPECT_EQ(rotated.gripper->weights(), skill.gripper->weights());

  // New start and goal, given in the world: the rotated skill from rotated boundary conditions.
  lfd::SegmentRolloutOptions o;
  o.dt = 0.004;
  o.start_position = Eigen::VectorXd(Eigen::Vector3d(0.1, 0.2, 0.3));
  o.goal_position = Eigen::VectorXd(Eigen::Vector3d(0.5, -0.1, 0.4));
  o.start_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()));
  o.goal_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()));
  lfd::SegmentRolloutOptions ro = o;
  ro.start_position = Eigen::VectorXd(r * Eigen::Vector3d(*o.start_position));
  ro.goal_position = Eigen::VectorXd(r * Eigen::Vector3d(*o.goal_position));
  ro.start_orientation = qr * *o.start_orientation;
  ro.goal_orientation = qr * *o.goal_orientation;
  const lfd::SegmentTrajectory a = skill.rollout(o);
  const lfd::SegmentTrajectory b = rotated.rollout(ro);
  ASSERT_EQ(a.times.size(), b.times.size());
  EXPECT_LT((a.positions * r.transpose() - b.positions).cwiseAbs().maxCoeff(), 1e-9);
  double worst_angle = 0.0;
  for (Eigen::Index i = 0; i < a.times.size(); ++i) {
    worst_angle = std::max(worst_angle,
                           angleBetween(qr * rowQuat(a.quaternions, i), rowQuat(b.quaternions, i)));
  }
  EXPECT_LT(worst_angle, 1e-7);
  EXPECT_LT((a.gripper - b.gripper).cwiseAbs().maxCoeff(), 1e-12);

  EXPECT_THROW(skill.rotated(2.0 * r), std::invalid_argument);  // not orthonormal
  EXPECT_THROW(skill.rotated(-Eigen::Matrix3d::Identity()), std::invalid_argument);  // reflection
}

TEST(OrientationDmp, StartEqualsGoalStaysBounded) {
  // Rotate out by 0.5 rad and back: start == goal exactly.
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(500, 0.0, kDuration);
  Eigen::MatrixXd rows(t.size(), 4);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double s = t[i] / kDuration;
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(0.5 * std::pow(std::sin(M_PI * s), 2), Eigen::Vector3d::UnitZ()));
    rows.row(i) << q.w(), q.x(), q.y(), q.z();
  }
  rows.row(t.size() - 1) = rows.row(0);
  const OrientationDmp dmp = OrientationDmp::learn(t, rows);
  EXPECT_TRUE(dmp.weights().allFinite());
  OrientationRolloutOptions o;
  o.dt = 0.004;
  o.duration = 1.5 * kDuration;
  const auto traj = dmp.rollout(o);
  double max_angle = 0.0;
  for (Eigen::Index i = 0; i < traj.quaternions.rows(); ++i) {
    max_angle = std::max(max_angle, angleBetween(rowQuat(traj.quaternions, i), dmp.start()));
  }
  EXPECT_LT(max_angle, 0.51);
  EXPECT_GT(max_angle, 0.49);
  EXPECT_LT(angleBetween(rowQuat(traj.quaternions, traj.quaternions.rows() - 1), dmp.goal()), 1e-4);
}

TEST(OrientationDmp, BadInputGivesClearErrors) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(50, 0.0, 1.0);
  Eigen::MatrixXd rows = orientationDemo(t);
  Eigen::MatrixXd nan_rows = rows;
  nan_rows(20, 2) = std::numeric_limits<double>::quiet_NaN();
  try {
    OrientationDmp::learn(t, nan_rows);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 20"), std::string::npos) << e.what();
  }
  Eigen::MatrixXd zero_rows = rows;
  zero_rows.row(5).setZero();
  EXPECT_THROW(OrientationDmp::learn(t, zero_rows), std::invalid_argument);
  EXPECT_THROW(OrientationDmp::learn(t, rows.leftCols(3)), std::invalid_argument);
  EXPECT_THROW(OrientationDmp::learn(t.head(4), rows.topRows(4)), std::invalid_argument);
  const OrientationDmp dmp = OrientationDmp::learn(t, rows);
  OrientationRolloutOptions o;
  o.goal = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_THROW(dmp.rollout(o), std::invalid_argument);
}

}  // namespace

// catkin_add_gtest links gtest without gtest_main (and the static gtest_main archive is then simply
// not pulled in by the standalone build).
int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
