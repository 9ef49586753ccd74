// Unit tests of the demonstrator's FSM plan: phase sequencing, speed scaling, geometry of the
// grasp and push motions, teleop-like hesitations, and the sampled Cartesian path.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "lfd_sim_bridge/demo_plan.hpp"

namespace demo = lfd_sim_bridge::demo;

namespace {

demo::Pose pose(double x, double y, double z, double yaw = 0.0) {
  demo::Pose p;
  p.position = {x, y, z};
  p.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return p;
}

demo::TaskInstance graspInstance() {
  return {"grasp", pose(0.40, -0.20, -0.035, 0.3), pose(0.35, -0.35, 0.10, 0.3)};
}

demo::TaskInstance pushInstance() {
  return {"push", pose(0.40, -0.10, -0.01), pose(0.50, -0.10, -0.01)};
}

const demo::Pose kStart = pose(0.20, -0.25, 0.05);

demo::DemoPlan plan(const demo::TaskInstance& inst, double speed = 1.0, bool teleop = false,
                    uint32_t seed = 1) {
  demo::Variation var;
  var.speed = speed;
  demo::TeleopStyle style;
  style.enabled = teleop;
  std::mt19937 rng(seed);
  return demo::planDemo(inst, kStart, demo::Geometry{}, demo::Timing{}, var, style, rng);
}

const demo::Segment& segment(const demo::DemoPlan& p, const std::string& label) {
  for (const auto& phase : p.phases)
    for (const auto& s : phase.segments)
      if (s.label == label) return s;
  throw std::runtime_error("no segment " + label);
}

demo::Pose phaseEnd(const demo::DemoPlan& p, size_t index) {
  demo::Pose from = p.start;
  for (size_t i = 0; i <= index; ++i) from = p.phases[i].segments.back().target;
  return from;
}

}  // namespace

TEST(DemoPlan, GraspPhasesInOrder) {
  const demo::DemoPlan p = plan(graspInstance());
  ASSERT_EQ(p.phases.size(), 3u);
  EXPECT_EQ(p.phases[0].name, "approach");
  EXPECT_EQ(p.phases[1].name, "grasp");
  EXPECT_EQ(p.phases[2].name, "move");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.phases[i].index, i);
  // Open during the approach, close on the stick (waiting for contact in sim mode) in "grasp".
  ASSERT_TRUE(p.phases[0].segments.front().gripper.has_value());
  EXPECT_GT(p.phases[0].segments.front().gripper->opening, 0.05);
  const demo::Segment& close = segment(p, "close");
  ASSERT_TRUE(close.gripper.has_value());
  EXPECT_TRUE(close.until_contact);
  EXPECT_LT(close.gripper->opening, 0.03);
}

TEST(DemoPlan, PushPhasesInOrder) {
  const demo::DemoPlan p = plan(pushInstance());
  ASSERT_EQ(p.phases.size(), 3u);
  EXPECT_EQ(p.phases[0].name, "approach");
  EXPECT_EQ(p.phases[1].name, "push");
  EXPECT_EQ(p.phases[2].name, "return");
  // The demo returns to where it started.
  EXPECT_LT((phaseEnd(p, 2).position - kStart.position).norm(), 1e-9);
}

TEST(DemoPlan, GraspGeometryLiftsAndCarriesTheStickToItsGoal) {
  const demo::TaskInstance inst = graspInstance();
  const demo::DemoPlan p = plan(inst);
  const demo::Pose grasp = phaseEnd(p, 0);
  // Grasp above the stick's centre (grasp_height 0 by default) with a yaw following the stick.
  EXPECT_LT((grasp.position - inst.object_start.position).norm(), 1e-9);
  EXPECT_NEAR(demo::yawOf(grasp.orientation), 0.3, 1e-9);
  EXPECT_GE(segment(p, "lift").target.position.z() - grasp.position.z(), 0.10);
  // Same yaw at start and goal: the TCP ends exactly above the goal by the grasp offset.
  const demo::Pose end = phaseEnd(p, 2);
  EXPECT_LT((end.position - inst.goal.position).norm(), 1e-9);
  // The pregrasp is above the grasp.
  const demo::Pose pre = segment(p, "pregrasp").target;
  EXPECT_NEAR(pre.position.z() - grasp.position.z(), 0.10, 1e-12);
  EXPECT_NEAR((pre.position - grasp.position).head<2>().norm(), 0.0, 1e-12);
}

TEST(DemoPlan, PushGeometryEndsBehindTheTarget) {
  const demo::TaskInstance inst = pushInstance();
  const demo::Geometry g;
  const demo::DemoPlan p = plan(inst);
  const double face = g.box_half_length + g.tcp_to_face;
  const demo::Pose contact = phaseEnd(p, 0);
  // The approach ends with the fist on the box face (the push phase is the time in contact),
  // after lowering behind it with a clearance.
  EXPECT_NEAR(contact.position.x(), 0.40 - face + g.push_contact_depth, 1e-12);
  EXPECT_NEAR(segment(p, "lower").target.position.x(), 0.40 - face - g.push_clearance, 1e-12);
  EXPECT_NEAR(contact.position.y(), -0.10, 1e-12);
  const demo::Pose pushed = phaseEnd(p, 1);
  EXPECT_NEAR(pushed.position.x(), 0.50 - face, 1e-12);
  EXPECT_NEAR(pushed.position.z(), contact.position.z(), 1e-12);  // along the table
  EXPECT_THROW(plan({"push", pose(0.4, 0, 0), pose(0.4, 0, 0)}), std::invalid_argument);
}

TEST(DemoPlan, DiagonalPushTouchesTheBoxCorner) {
  // Pushed along its diagonal, the cube meets the fist with a corner, half * sqrt(2) from its
  // centre: the approach must end there, not at the face distance (which is inside the box).
  const demo::Geometry g;
  const demo::TaskInstance inst{"push", pose(0.40, -0.10, -0.01), pose(0.50, 0.0, -0.01)};
  const demo::DemoPlan p = plan(inst);
  const demo::Pose contact = phaseEnd(p, 0);
  const Eigen::Vector3d offset = inst.object_start.position - contact.position;
  EXPECT_NEAR(offset.head<2>().norm(), g.box_half_length * std::sqrt(2.0) + g.tcp_to_face, 1e-9);
  EXPECT_NEAR(offset.x(), offset.y(), 1e-12);  // straight behind, along the push
}

TEST(DemoPlan, SlightlyOffAxisPushMeetsTheFaceNotTheCorner) {
  // 16 degrees off the box's axis, the corner lies beside the push line, out of the fist's
  // reach: the fist's trailing edge (lateral offset -tcp_to_face) touches the face first.
  const demo::Geometry g;
  const double angle = 16.0 * M_PI / 180.0;
  const demo::TaskInstance inst{
      "push", pose(0.40, -0.10, -0.01),
      pose(0.40 + 0.1 * std::cos(angle), -0.10 + 0.1 * std::sin(angle), -0.01)};
  const Eigen::Vector3d offset = inst.object_start.position - phaseEnd(plan(inst), 0).position;
  const double face_depth = (g.box_half_length + g.tcp_to_face * std::sin(angle)) / std::cos(angle);
  ASSERT_LT(face_depth, g.box_half_length * (std::cos(angle) + std::sin(angle)));  // not the corner
  EXPECT_NEAR(offset.head<2>().norm(), face_depth + g.tcp_to_face, 1e-9);
}

TEST(DemoPlan, SpeedScalesEveryDuration) {
  for (const auto& inst : {graspInstance(), pushInstance()}) {
    const double nominal = plan(inst, 1.0).duration();
    EXPECT_NEAR(plan(inst, 2.0).duration(), nominal / 2.0, 1e-9);
    EXPECT_NEAR(plan(inst, 0.7).duration(), nominal / 0.7, 1e-9);
    EXPECT_GT(nominal, 5.0);
    EXPECT_LT(nominal, 15.0);
  }
  EXPECT_THROW(plan(graspInstance(), 0.0), std::invalid_argument);
  EXPECT_THROW(plan({"pour", pose(0, 0, 0), pose(1, 0, 0)}), std::invalid_argument);
}

TEST(DemoPlan, SimModeIgnoresTheRandomGenerator) {
  const demo::DemoPlan a = plan(graspInstance(), 1.0, false, 1);
  const demo::DemoPlan b = plan(graspInstance(), 1.0, false, 99);
  EXPECT_DOUBLE_EQ(a.duration(), b.duration());
}

TEST(DemoPlan, TeleopHesitatesAndClosesByTime) {
  int hesitations = 0;
  double min_duration = 1e9, max_duration = 0.0;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const demo::DemoPlan p = plan(graspInstance(), 1.0, true, seed);
    for (const auto& phase : p.phases)
      for (const auto& s : phase.segments)
        if (s.label.find("_hesitate") != std::string::npos) {
          ++hesitations;
          EXPECT_FALSE(s.is_move);
          EXPECT_GE(s.duration, 0.2);
        }
    const demo::Segment& close = segment(p, "close");
    EXPECT_FALSE(close.until_contact);  // no force feedback: a timed close
    EXPECT_NEAR(close.gripper->opening, 0.0, 1e-12);
    min_duration = std::min(min_duration, p.duration());
    max_duration = std::max(max_duration, p.duration());
    // The operator still ends at the goal.
    EXPECT_LT((phaseEnd(p, 2).position - graspInstance().goal.position).norm(), 0.03);
  }
  EXPECT_GT(hesitations, 5);
  EXPECT_GT(max_duration - min_duration, 1.0);  // human timing varies from demo to demo
}

TEST(SamplePhase, ContinuousFromStartToEnd) {
  const demo::DemoPlan p = plan(graspInstance());
  const double dt = 0.01;
  demo::Pose from = p.start;
  for (const auto& phase : p.phases) {
    const auto samples = demo::samplePhase(from, phase, dt, 0.0);
    ASSERT_GE(samples.size(), 2u);
    EXPECT_DOUBLE_EQ(samples.front().t, 0.0);
    EXPECT_NEAR(samples.back().t, phase.duration(), 1e-12);
    EXPECT_LT((samples.front().pose.position - from.position).norm(), 1e-12);
    EXPECT_LT((samples.back().pose.position - phase.segments.back().target.position).norm(), 1e-12);
    for (size_t k = 1; k < samples.size(); ++k) {
      EXPECT_GT(samples[k].t, samples[k - 1].t);
      // 1 m/s would be far above any demo speed: the path has no jumps.
      EXPECT_LT((samples[k].pose.position - samples[k - 1].pose.position).norm(), 1.0 * dt);
    }
    from = phase.segments.back().target;
  }
}

TEST(SamplePhase, TremorIsAddedOnTopOfThePath) {
  const demo::DemoPlan p = plan(pushInstance());
  const demo::Tremor tremor(0.002, 8.0, 12.0, 3);
  const auto clean = demo::samplePhase(p.start, p.phases[0], 0.01, 5.0);
  const auto shaky = demo::samplePhase(p.start, p.phases[0], 0.01, 5.0, &tremor);
  ASSERT_EQ(clean.size(), shaky.size());
  double max_dev = 0.0;
  for (size_t k = 0; k < clean.size(); ++k) {
    const Eigen::Vector3d dev = shaky[k].pose.position - clean[k].pose.position;
    EXPECT_TRUE(dev.isApprox(tremor.at(5.0 + clean[k].t), 1e-9) || dev.norm() < 1e-12);
    max_dev = std::max(max_dev, dev.norm());
  }
  EXPECT_GT(max_dev, 0.001);
  EXPECT_LT(max_dev, 0.015);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
