// Recovery after a failed grasp or a drop, without ROS: which alarms are a lost grasp, which
// segment a retry starts from, the retreat back to it and the plan of the rest of the task.
#include "lfd_dmp/recovery.hpp"
#include "planner_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using namespace lfd_test;  // the shared fixture and its helpers

class RecoveryTest : public PlannerTest {};

lfd::Deviation deviation(double time, double expected, double measured) {
  lfd::Deviation d;
  d.time = time;
  d.expected = expected;
  d.measured = measured;
  d.score = 2.0;
  return d;
}

// The library's reach for a block, then its carry to the goal.
lfd_dmp::SkillLibrary reachForTheBlock(lfd_dmp::SkillLibrary lib) {
  lib.segments[0].goal.emplace();
  lib.segments[0].goal->position_frame = lfd::SceneFrame::parse("object:block");
  lib.segments[0].goal->orientation_frame = lfd::SceneFrame::parse("object:block");
  lib.segments[1].goal.emplace();
  lib.segments[1].goal->position_frame = lfd::SceneFrame::parse("goal");
  lib.segments[1].goal->orientation_frame = lfd::SceneFrame::parse("goal");
  return lib;
}

// A retry plans the task from a segment on: the earlier segments stay in the plan, empty, so that
// indices match the library's and its signature's; the rest starts at the robot's pose.
TEST_F(RecoveryTest, ARetryPlansTheTaskFromASegmentOn) {
  lfd_dmp::ExecutorOptions opt = coarse();
  const auto whole = planner_.plan(lib_, targets(grasp(), goal()), q0_, 0.04, opt);
  const Eigen::VectorXd q_mid = whole.joints[whole.segments[0].end / 2];
  opt.first_segment = 1;
  const auto rest = planner_.plan(lib_, targets(grasp(), goal()), q_mid, 0.015, opt);
  ASSERT_EQ(rest.segments.size(), 2u);
  EXPECT_EQ(rest.segments[0].begin, 0u);
  EXPECT_EQ(rest.segments[0].end, 0u);
  EXPECT_EQ(rest.segments[0].duration, 0.0);
  EXPECT_EQ(rest.segments[0].name, "approach");
  EXPECT_EQ(rest.segments[1].begin, 0u);
  EXPECT_EQ(rest.segments[1].end, rest.times.size());
  EXPECT_NEAR(rest.duration(), 2.5, 0.05);
  EXPECT_LT((rest.poses.front().position - planner_.forward(q_mid).position).norm(), 1e-9);
  EXPECT_LT((rest.poses.back().position - goal()).norm(), 0.004);
  EXPECT_EQ(rest.joints.size(), rest.times.size());
  opt.first_segment = 2;
  EXPECT_THROW(planner_.plan(lib_, targets(grasp(), goal()), q0_, 0.04, opt),
               std::invalid_argument);
}

// A lost grasp: the hand should hold (the plan has had the gripper closed for min_hold_time) and a
// sensor reads less than the demonstrations did. More than expected, or an alarm before the
// gripper closed or while it closes, is not.
TEST_F(RecoveryTest, AnAlarmIsALostGraspOnlyWhileHoldingAndWhenTheSensorReadsLess) {
  const auto plan = planner_.plan(lib_, targets(grasp(), goal()), q0_, 0.04, coarse());
  ASSERT_EQ(plan.gripper_events.size(), 2u);
  const double closed_at = plan.times[plan.gripper_events[1].sample];
  const double carrying = plan.times[plan.segments[1].begin] + 0.5;
  EXPECT_FALSE(lfd_dmp::gripperClosedAt(plan, 0));
  EXPECT_TRUE(lfd_dmp::gripperClosedAt(plan, plan.segments[1].begin));
  EXPECT_TRUE(lfd_dmp::lostGrasp(deviation(carrying, 9.6, 0.2), plan, {}));    // the pads unloaded
  EXPECT_TRUE(lfd_dmp::lostGrasp(deviation(carrying, -4.0, -0.5), plan, {}));  // the weight gone
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(carrying, 9.6, 15.0), plan, {}));  // squeezed harder
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(carrying, -4.0, 8.0), plan, {}));  // a yank
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(carrying, 5.5, -5.4), plan, {}));  // pressed instead
  EXPECT_TRUE(lfd_dmp::lostGrasp(deviation(carrying, -4.0, 0.3), plan, {}));   // noise around 0
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(closed_at - 0.1, 9.6, 0.2), plan, {}));  // still open
  // Closing: the fingers load the pads within min_hold_time of the command.
  lfd_dmp::RecoveryOptions options;
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(closed_at + 0.5, 9.6, 0.2), plan, options));
  options.min_hold_time = 0.4;
  EXPECT_TRUE(lfd_dmp::lostGrasp(deviation(closed_at + 0.5, 9.6, 0.2), plan, options));
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(NAN, 9.6, 0.2), plan, {}));
}

// A fist holds nothing: a plan whose fingers close fully (a push, a wipe) has no grasp to lose,
// however light its pads; the same closing that stops on an object 1 cm wide does.
TEST_F(RecoveryTest, AFistThatClosesOnNothingHasNoGraspToLose) {
  const auto plan = planner_.plan(lib_, targets(grasp(), goal()), q0_, 0.04, coarse());
  const std::size_t closed = plan.gripper_events.at(1).sample;
  const double carrying = plan.times[plan.segments[1].begin] + 0.5;
  auto fist = plan;
  for (std::size_t i = closed; i < fist.gripper.size(); ++i) fist.gripper[i] = 0.0;
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(carrying, 9.6, 0.2), fist, {}));
  auto held = fist;
  for (std::size_t i = closed; i < held.gripper.size(); ++i) held.gripper[i] = 0.01;
  EXPECT_TRUE(lfd_dmp::lostGrasp(deviation(carrying, 9.6, 0.2), held, {}));
  // Measured from the robot's closing command: a gripper commanded to 8 mm holds nothing at 1 cm.
  EXPECT_FALSE(lfd_dmp::lostGrasp(deviation(carrying, 9.6, 0.2), held, {}, 0.008));
}

// The last boundary that held: the start of the segment that reached for the object the gripper
// closed on, wherever in the task the grasp was lost; never before the plan's first segment.
TEST_F(RecoveryTest, ARetryStartsWhereTheHandReachedForTheObject) {
  const lfd_dmp::SkillLibrary lib = reachForTheBlock(lib_);
  lfd_dmp::ExecutorOptions opt = coarse();
  const auto plan = planner_.plan(lib, targets(grasp(), goal()), q0_, 0.04, opt);
  EXPECT_EQ(lfd_dmp::retrySegment(lib, plan, plan.times.size() - 1), 0u);
  EXPECT_EQ(lfd_dmp::retrySegment(lib, plan, plan.segments[1].begin + 10), 0u);
  // A plan that starts at the carry (the earlier segments done) retries from there.
  opt.first_segment = 1;
  const auto rest =
      planner_.plan(lib, targets(grasp(), goal()), plan.joints[plan.segments[1].begin], 0.015, opt);
  EXPECT_EQ(lfd_dmp::retrySegment(lib, rest, rest.times.size() - 1), 1u);
  // The gripper never closed: from the first segment.
  lfd_dmp::ExecutionPlan open = plan;
  open.gripper_events.resize(1);
  EXPECT_EQ(lfd_dmp::retrySegment(lib, open, open.times.size() - 1), 0u);
}

// The way back: a joint-space min-jerk move from where the arm is to where the retry starts, at
// most the configured fraction of each joint's velocity limit, at rest at both ends.
TEST_F(RecoveryTest, TheRetreatIsASlowJointMoveBackToTheBoundary) {
  const auto plan = planner_.plan(lib_, targets(grasp(), goal()), q0_, 0.04, coarse());
  const Eigen::VectorXd from = plan.joints.back();
  lfd_dmp::RecoveryOptions options;
  const auto back = lfd_dmp::retreatPlan(planner_, from, q0_, 0.01, options);
  ASSERT_EQ(back.segments.size(), 1u);
  EXPECT_EQ(back.segments[0].end, back.times.size());
  EXPECT_EQ(back.joints.front(), from);
  EXPECT_LT((back.joints.back() - q0_).norm(), 1e-12);
  EXPECT_GE(back.duration(), options.min_retreat_duration);
  const Eigen::VectorXd& limits = planner_.chain().velocityLimits();
  double worst = 0.0;
  for (size_t k = 1; k < back.joints.size(); ++k)
    for (Eigen::Index j = 0; j < limits.size(); ++j)
      worst = std::max(worst, std::abs(back.joints[k][j] - back.joints[k - 1][j]) /
                                  (back.times[k] - back.times[k - 1]) / limits[j]);
  EXPECT_LE(worst, options.retreat_speed_fraction * 1.01);
  EXPECT_LT((back.joints[1] - back.joints[0]).norm(), 1e-4);  // starts and ends at rest
  EXPECT_LT((back.joints.back() - back.joints[back.joints.size() - 2]).norm(), 1e-4);
  EXPECT_LT((back.poses.back().position - home_.position).norm(), 1e-9);
  options.retreat_speed_fraction = 0.0;
  EXPECT_THROW(lfd_dmp::retreatPlan(planner_, from, q0_, 0.01, options), std::invalid_argument);
  EXPECT_THROW(lfd_dmp::retreatPlan(planner_, from, Eigen::VectorXd::Zero(2), 0.01, {}),
               std::invalid_argument);
}

}  // namespace
