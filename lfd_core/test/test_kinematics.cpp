// KinematicChain (URDF -> FK/Jacobian) and InverseKinematics (DLS) on the lfd humanoid model and on
// small hand-written URDFs with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "lfd_core/kinematics/inverse_kinematics.hpp"
#include "lfd_core/kinematics/kinematic_chain.hpp"

namespace {

const std::string kRobotUrdf = std::string(LFD_ROBOT_DIR) + "/models/jvrc1_like.urdf";

// base -> (fixed, rotated) -> revolute z -> prismatic x -> fixed tip.
const char* const kSmallUrdf = R"(<?xml version="1.0"?>
<robot name="small">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="tip"/>
  <joint name="mount" type="fixed"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="turn" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
  <joint name="slide" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" effort="50" velocity="0.2"/></joint>
  <joint name="tool" type="fixed"><parent link="c"/><child link="tip"/>
    <origin xyz="0.1 0 0" rpy="0 0 0"/></joint>
</robot>)";

lfd::KinematicChain taskChain() {
  return lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "base_link", "r_gripper_tcp");
}

Eigen::VectorXd randomConfig(const lfd::KinematicChain& chain, std::mt19937& rng,
                             double margin_fraction) {
  Eigen::VectorXd q(chain.dof());
  std::uniform_real_distribution<double> u(margin_fraction, 1.0 - margin_fraction);
  for (int i = 0; i < chain.dof(); ++i)
    q[i] = chain.lowerLimits()[i] + u(rng) * (chain.upperLimits()[i] - chain.lowerLimits()[i]);
  return q;
}

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

TEST(KinematicChain, ExtractsTheRightArmChainWithLimits) {
  const auto chain = taskChain();
  const std::vector<std::string> expected = {
      "WAIST_Y",      "WAIST_P",   "WAIST_R",   "R_SHOULDER_P", "R_SHOULDER_R",
      "R_SHOULDER_Y", "R_ELBOW_P", "R_ELBOW_Y", "R_WRIST_R",    "R_WRIST_Y"};
  EXPECT_EQ(chain.jointNames(), expected);
  const int elbow = chain.jointIndex("R_ELBOW_P");
  ASSERT_GE(elbow, 0);
  EXPECT_DOUBLE_EQ(chain.lowerLimits()[elbow], -2.5);
  EXPECT_DOUBLE_EQ(chain.upperLimits()[elbow], 0.0);
  EXPECT_GT(chain.velocityLimits()[elbow], 0.0);
  EXPECT_GT(chain.effortLimits()[elbow], 0.0);
  EXPECT_EQ(chain.jointIndex("L_ELBOW_P"), -1);

  const auto arm = lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "chest_link", "r_gripper_tcp");
  EXPECT_EQ(arm.dof(), 7);
  EXPECT_EQ(arm.jointNames().front(), "R_SHOULDER_P");
}

TEST(KinematicChain, ForwardKinematicsOfKnownConfigurations) {
  const auto chain = taskChain();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(chain.dof());
  // Zero pose: arm hanging, TCP straight below the shoulder (0.10 + 0.36 - 0.30 - 0.26 - 0.128).
  Eigen::Isometry3d t = chain.forward(q);
  EXPECT_NEAR((t.translation() - Eigen::Vector3d(0, -0.21, -0.228)).norm(), 0.0, 1e-12);
  EXPECT_TRUE(t.linear().isIdentity(1e-12));
  // Arm raised straight forward: TCP 0.688 m in front of the shoulder, pointing along +x.
  q[chain.jointIndex("R_SHOULDER_P")] = -M_PI / 2;
  t = chain.forward(q);
  EXPECT_NEAR((t.translation() - Eigen::Vector3d(0.688, -0.21, 0.46)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((t.linear() * Eigen::Vector3d(0, 0, -1) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
  // Waist turned 90 deg left with the arm hanging: the shoulder swings to the front.
  q.setZero();
  q[chain.jointIndex("WAIST_Y")] = M_PI / 2;
  t = chain.forward(q);
  EXPECT_NEAR((t.translation() - Eigen::Vector3d(0.21, 0.0, -0.228)).norm(), 0.0, 1e-12);

  const auto small = lfd::KinematicChain::fromUrdfString(kSmallUrdf, "base", "tip");
  ASSERT_EQ(small.dof(), 2);
  // Mount yaw 90 deg, turn 0.5 rad, slide 0.2: tip at radius 0.8 along angle pi/2 + 0.5.
  const Eigen::Isometry3d ts = small.forward(Eigen::Vector2d(0.5, 0.2));
  const double angle = M_PI / 2 + 0.5;
  EXPECT_NEAR(
      (ts.translation() - Eigen::Vector3d(0.8 * std::cos(angle), 0.8 * std::sin(angle), 1)).norm(),
      0.0, 1e-12);
  EXPECT_DOUBLE_EQ(small.upperLimits()[1], 0.3);
  EXPECT_DOUBLE_EQ(small.velocityLimits()[1], 0.2);
}

void expectJacobianMatchesFiniteDifferences(const lfd::KinematicChain& chain,
                                            const Eigen::VectorXd& q) {
  const lfd::Matrix6Xd jac = chain.jacobian(q);
  const Eigen::Isometry3d t0 = chain.forward(q);
  const double h = 1e-6;
  for (int i = 0; i < chain.dof(); ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    const Eigen::Isometry3d tp = chain.forward(qp), tm = chain.forward(qm);
    const Eigen::Vector3d dp = (tp.translation() - tm.translation()) / (2 * h);
    const Eigen::Vector3d dw = rotationVector(tp.linear() * tm.linear().transpose()) / (2 * h);
    EXPECT_NEAR((jac.col(i).head<3>() - dp).norm(), 0.0, 1e-6) << "joint " << i;
    EXPECT_NEAR((jac.col(i).tail<3>() - dw).norm(), 0.0, 1e-6) << "joint " << i;
  }
  // The combined call agrees with the separate ones.
  Eigen::Isometry3d pose;
  lfd::Matrix6Xd jac2;
  chain.forwardAndJacobian(q, pose, jac2);
  EXPECT_TRUE(pose.isApprox(t0, 1e-14));
  EXPECT_TRUE(jac2.isApprox(jac, 1e-14));
}

TEST(KinematicChain, JacobianMatchesFiniteDifferences) {
  std::mt19937 rng(7);
  const auto chain = taskChain();
  for (int trial = 0; trial < 20; ++trial)
    expectJacobianMatchesFiniteDifferences(chain, randomConfig(chain, rng, 0.0));
  const auto small = lfd::KinematicChain::fromUrdfString(kSmallUrdf, "base", "tip");
  expectJacobianMatchesFiniteDifferences(small, Eigen::Vector2d(-0.3, 0.1));
}

TEST(KinematicChain, RejectsBadInput) {
  EXPECT_THROW(lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "base_link", "no_such_link"),
               std::invalid_argument);
  EXPECT_THROW(lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "no_such_base", "r_gripper_tcp"),
               std::invalid_argument);
  // Tip above the base, and a tip on another branch.
  EXPECT_THROW(lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "r_gripper_tcp", "base_link"),
               std::invalid_argument);
  EXPECT_THROW(lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "l_wrist_y_link", "r_gripper_tcp"),
               std::invalid_argument);
  // The mimic finger cannot be part of a serial chain.
  EXPECT_THROW(lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "base_link", "r_gripper_finger_r"),
               std::invalid_argument);
  EXPECT_THROW(lfd::KinematicChain::fromUrdfString("<robot name=\"x\"><link name=", "a", "b"),
               std::invalid_argument);
  EXPECT_THROW(lfd::KinematicChain::fromUrdfString("not xml at all", "a", "b"),
               std::invalid_argument);
  EXPECT_THROW(lfd::KinematicChain::fromUrdfFile("/nonexistent/robot.urdf", "a", "b"),
               std::runtime_error);
  const auto chain = taskChain();
  EXPECT_THROW(chain.forward(Eigen::VectorXd::Zero(3)), std::invalid_argument);
  EXPECT_THROW(
      lfd::InverseKinematics(chain).solve(Eigen::Isometry3d::Identity(), Eigen::VectorXd::Zero(4)),
      std::invalid_argument);
  lfd::IkOptions bad;
  bad.weights.setZero();
  EXPECT_THROW(lfd::InverseKinematics(chain, bad), std::invalid_argument);
}

TEST(InverseKinematics, ConvergesOnRandomReachableTargetsWithinLimits) {
  std::mt19937 rng(42);
  for (const char* base : {"base_link", "chest_link"}) {
    const auto chain = lfd::KinematicChain::fromUrdfFile(kRobotUrdf, base, "r_gripper_tcp");
    lfd::InverseKinematics ik(chain);
    int converged = 0;
    const int trials = 100;
    for (int trial = 0; trial < trials; ++trial) {
      // Configurations at least 10% of each range inside the limits (the task margin).
      const Eigen::VectorXd q_true = randomConfig(chain, rng, 0.10);
      const Eigen::Isometry3d target = chain.forward(q_true);
      const lfd::IkResult r = ik.reach(target, chain.midRange());
      ASSERT_EQ(r.q.size(), chain.dof());
      EXPECT_TRUE(chain.withinLimits(r.q)) << base << " trial " << trial;
      if (!r.converged) continue;
      ++converged;
      const Eigen::Isometry3d reached = chain.forward(r.q);
      EXPECT_LT((reached.translation() - target.translation()).norm(), 1e-4);
      EXPECT_LT(rotationVector(reached.linear() * target.linear().transpose()).norm(), 1e-3);
    }
    EXPECT_EQ(converged, trials) << "chain from " << base;
  }
}

TEST(InverseKinematics, WarmStartConvergesInFewIterations) {
  std::mt19937 rng(3);
  const auto chain = lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "chest_link", "r_gripper_tcp");
  lfd::InverseKinematics ik(chain);
  lfd::IkResult r;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::VectorXd q0 = randomConfig(chain, rng, 0.15);
    Eigen::Isometry3d target = chain.forward(q0);
    target.translation() += Eigen::Vector3d(0.003, -0.002, 0.002);  // one DMP step away
    ASSERT_TRUE(ik.solve(target, q0, r));
    EXPECT_LE(r.iterations, 8);
  }
}

TEST(InverseKinematics, PositionOnlyWeightsIgnoreOrientation) {
  const auto chain = taskChain();
  lfd::IkOptions options;
  options.weights << 1, 1, 1, 0, 0, 0;
  lfd::InverseKinematics ik(chain, options);
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() << 0.35, -0.25, 0.0;
  target.linear() =
      Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const lfd::IkResult r = ik.reach(target, chain.midRange());
  ASSERT_TRUE(r.converged);
  EXPECT_LT((chain.forward(r.q).translation() - target.translation()).norm(), 1e-4);
  EXPECT_DOUBLE_EQ(r.orientation_error, 0.0);
}

TEST(InverseKinematics, ReportsUnreachableTargets) {
  const auto chain = taskChain();
  lfd::InverseKinematics ik(chain);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() << 1.5, -0.2, 0.3;  // about twice the arm's reach
  const lfd::IkResult r = ik.reach(far, chain.midRange());
  EXPECT_FALSE(r.converged);
  EXPECT_GT(r.position_error, 0.3);
  EXPECT_TRUE(chain.withinLimits(r.q));
  // Reachable position but an orientation the wrist cannot take there (pointing back into the
  // body).
  Eigen::Isometry3d twisted = Eigen::Isometry3d::Identity();
  twisted.translation() << 0.6, -0.2, 0.0;
  twisted.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_FALSE(ik.reach(twisted, chain.midRange()).converged);
}

TEST(InverseKinematics, PreferredPostureShapesTheRedundancy) {
  const auto chain = lfd::KinematicChain::fromUrdfFile(kRobotUrdf, "chest_link", "r_gripper_tcp");
  lfd::InverseKinematics ik(chain);
  Eigen::VectorXd q0 = chain.midRange();
  const Eigen::Isometry3d target = chain.forward(q0);
  // Two preferred postures that differ in the elbow-swivel direction give different solutions,
  // each closer to its own preference.
  Eigen::VectorXd pa = q0, pb = q0;
  pa[chain.jointIndex("R_SHOULDER_Y")] += 0.6;
  pb[chain.jointIndex("R_SHOULDER_Y")] -= 0.6;
  lfd::IkOptions options;
  options.posture_gain = 0.2;
  options.max_iterations = 400;
  options.position_tolerance = 1e-7;
  options.orientation_tolerance = 1e-6;
  ik.setOptions(options);
  ik.setPreferredPosture(pa);
  const lfd::IkResult ra = ik.solve(target, pa);
  ik.setPreferredPosture(pb);
  const lfd::IkResult rb = ik.solve(target, pb);
  ASSERT_TRUE(ra.converged);
  ASSERT_TRUE(rb.converged);
  EXPECT_GT((ra.q - rb.q).norm(), 0.05);
  EXPECT_LT((ra.q - pa).norm(), (rb.q - pa).norm());
}

}  // namespace

// Regression: a finite target so far away that every attempt's pose error overflows returned an
// empty q with error 0 (read as success; the executor then indexed the empty vector).
TEST(InverseKinematics, OverflowingTargetIsAClearFailureNeverAnEmptyResult) {
  const auto chain = taskChain();
  lfd::InverseKinematics ik(chain);
  Eigen::Isometry3d huge = Eigen::Isometry3d::Identity();
  huge.translation() << 1e300, -1e300, 1e300;
  const lfd::IkResult r = ik.reach(huge, chain.midRange());
  EXPECT_FALSE(r.converged);
  ASSERT_EQ(r.q.size(), chain.dof());
  EXPECT_TRUE(chain.withinLimits(r.q));
  EXPECT_FALSE(std::isfinite(r.position_error));
  EXPECT_NE(r.failure.find("not finite"), std::string::npos) << r.failure;
  // A reachable target afterwards: no failure left over from the previous query.
  Eigen::Isometry3d near = chain.forward(chain.midRange());
  const lfd::IkResult ok = ik.reach(near, chain.midRange());
  EXPECT_TRUE(ok.converged);
  EXPECT_TRUE(ok.failure.empty());
}

TEST(InverseKinematics, NonFiniteTargetIsRefused) {
  const auto chain = taskChain();
  lfd::InverseKinematics ik(chain);
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    Eigen::Isometry3d target = chain.forward(chain.midRange());
    target.translation().x() = bad;
    EXPECT_THROW(ik.reach(target, chain.midRange()), std::invalid_argument);
    EXPECT_THROW(ik.solve(target, chain.midRange()), std::invalid_argument);
  }
}
