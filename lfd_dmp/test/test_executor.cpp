// Executor logic without ROS: segment goal rules, gripper thresholding, segment sequencing of the
// planned path, and refusal of unreachable goals / mismatched libraries before anything moves.
#include "lfd_dmp/executor.hpp"
#include "lfd_dmp/object_following.hpp"
#include "lfd_dmp/plan_messages.hpp"
#include "lfd_dmp/skill_learner.hpp"
#include "planner_fixture.hpp"
#include "strokes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using namespace lfd_test;  // the shared fixture and its helpers

TEST(GripperEvents, ClosesOnceAtTheMiddleOfTheRange) {
  std::vector<double> v;
  for (int k = 0; k <= 100; ++k) v.push_back(0.04 - 0.025 * k / 100.0);  // 0.04 -> 0.015
  const auto e = lfd_dmp::gripperEvents(v, 0.5, 0.05, 0.005);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].sample, 0u);
  EXPECT_FALSE(e[0].close);  // starts open
  EXPECT_TRUE(e[1].close);
  EXPECT_NEAR(static_cast<double>(e[1].sample), 55.0, 1.0);  // 0.5 + 0.05 hysteresis past middle
}

TEST(GripperEvents, NoChatterInsideTheHysteresisAndNothingForAConstantGripper) {
  std::vector<double> v = {0.04, 0.03, 0.0, 0.023, 0.017, 0.023, 0.0};  // band 0.016..0.024
  const auto e = lfd_dmp::gripperEvents(v, 0.5, 0.1, 0.005);
  ASSERT_EQ(e.size(), 2u);  // initial open, one close; wiggles around 0.02 stay closed
  EXPECT_TRUE(e[1].close);
  EXPECT_EQ(e[1].sample, 2u);
  EXPECT_TRUE(lfd_dmp::gripperEvents(std::vector<double>(50, 0.03), 0.5, 0.05, 0.005).empty());
  const auto reopen = lfd_dmp::gripperEvents({0.0, 0.0, 0.08}, 0.5, 0.05, 0.005);
  ASSERT_EQ(reopen.size(), 2u);
  EXPECT_TRUE(reopen[0].close);
  EXPECT_FALSE(reopen[1].close);
}

TEST_F(PlannerTest, SegmentsRunInSequenceFromTheCurrentPoseToEachNewGoal) {
  const Eigen::Vector3d grasp = this->grasp(), goal = this->goal();
  lfd_dmp::ExecutorOptions opt = coarse();
  const lfd_dmp::ExecutionPlan plan = planner_.plan(lib_, targets(grasp, goal), q0_, 0.04, opt);
  ASSERT_EQ(plan.segments.size(), 2u);
  EXPECT_EQ(plan.segments[0].begin, 0u);
  EXPECT_EQ(plan.segments[0].end, plan.segments[1].begin);  // contiguous
  EXPECT_EQ(plan.segments[1].end, plan.times.size());
  EXPECT_EQ(plan.joints.size(), plan.times.size());
  // Starts at the robot's pose, reaches each segment goal at the segment end.
  EXPECT_LT((plan.poses.front().position - home_.position).norm(), 1e-9);
  EXPECT_LT((plan.poses[plan.segments[0].end - 1].position - grasp).norm(), 0.004);
  EXPECT_LT((plan.poses.back().position - goal).norm(), 0.004);
  // Durations come from the demos (2.0 s + 2.5 s), time strictly increasing.
  EXPECT_NEAR(plan.duration(), 4.5, 0.05);
  for (size_t k = 1; k < plan.times.size(); ++k) ASSERT_GT(plan.times[k], plan.times[k - 1]);
  // The joint path realizes the Cartesian path (IK checked on every sample).
  for (size_t k = 0; k < plan.poses.size(); k += 97)
    EXPECT_LT((planner_.forward(plan.joints[k]).position - plan.poses[k].position).norm(), 0.002);
  EXPECT_LT(plan.max_speed_ratio, 1.0);
  // The gripper starts open and closes once, during the first segment.
  ASSERT_EQ(plan.gripper_events.size(), 2u);
  EXPECT_FALSE(plan.gripper_events[0].close);
  EXPECT_TRUE(plan.gripper_events[1].close);
  EXPECT_LT(plan.gripper_events[1].sample, plan.segments[0].end);
  // Duration scale stretches the plan.
  opt.duration_scale = 1.5;
  EXPECT_NEAR(planner_.plan(lib_, targets(grasp, goal), q0_, 0.04, opt).duration(), 6.75, 0.05);
}

// An object moved while the robot approaches it: the replanned path is the old one up to the
// update (the robot already followed it), then bends smoothly into the moved goals: the running
// segment's DMP goal moves, the later segment is generalized toward its new goal.
TEST_F(PlannerTest, AGoalMovedWhileItsSegmentRunsIsFollowedSmoothly) {
  const Eigen::Vector3d grasp = this->grasp(), goal = this->goal();
  lfd_dmp::ExecutorOptions opt = coarse();
  const lfd_dmp::ExecutionPlan before = planner_.plan(lib_, targets(grasp, goal), q0_, 0.04, opt);
  const Eigen::Vector3d shift(0.03, -0.02, 0.0);
  const double at = 0.8;  // s: within the approach (2.0 s)
  const std::vector<lfd_dmp::TargetUpdate> updates{{at, targets(grasp + shift, goal + shift)}};
  const lfd_dmp::ExecutionPlan after =
      planner_.replan(lib_, targets(grasp, goal), updates, before, q0_, 0.04, opt);
  ASSERT_EQ(after.segments.size(), 2u);
  ASSERT_EQ(after.joints.size(), after.times.size());
  const size_t k_at = static_cast<size_t>(std::lround(at / opt.dt));
  for (size_t k = 0; k <= k_at; ++k) {
    ASSERT_LT((after.poses[k].position - before.poses[k].position).norm(), 1e-12) << k;
    ASSERT_EQ(after.joints[k], before.joints[k]) << k;  // kept, not solved again
  }
  EXPECT_LT((after.poses[after.segments[0].end - 1].position - (grasp + shift)).norm(), 0.004);
  EXPECT_LT((after.poses.back().position - (goal + shift)).norm(), 0.004);
  EXPECT_LT((after.segments[0].goal.position - (grasp + shift)).norm(), 1e-12);
  // Smooth: the TCP's acceleration changes by less than 0.05 m/s^2 from one sample to the next
  // around the update (a goal that jumped there, unfiltered, steps it by 0.65 m/s^2).
  double max_da = 0.0;
  const auto acceleration = [&](size_t k) {
    return Eigen::Vector3d(
        (after.poses[k + 1].position - 2 * after.poses[k].position + after.poses[k - 1].position) /
        (opt.dt * opt.dt));
  };
  for (size_t k = k_at - 10; k < k_at + 10; ++k)
    max_da = std::max(max_da, (acceleration(k + 1) - acceleration(k)).norm());
  EXPECT_LT(max_da, 0.05);
  for (size_t k = 0; k < after.poses.size(); k += 97)
    EXPECT_LT((planner_.forward(after.joints[k]).position - after.poses[k].position).norm(), 0.002);
  // What is sent: the rest from the update, stamped when it starts, its first knot the old plan's
  // (the driver's targets go on without a jump).
  const trajectory_msgs::JointTrajectory tail =
      lfd_dmp::toJointTrajectory(after, ros::Time(100.0), 0.01, k_at);
  EXPECT_NEAR(tail.header.stamp.toSec(), 100.0 + after.times[k_at], 1e-9);
  ASSERT_FALSE(tail.points.empty());
  EXPECT_EQ(tail.points.front().time_from_start.toSec(), 0.0);
  for (size_t j = 0; j < tail.joint_names.size(); ++j)
    EXPECT_EQ(tail.points.front().positions[j], before.joints[k_at][static_cast<Eigen::Index>(j)]);
  EXPECT_NEAR(tail.points.back().time_from_start.toSec(), after.duration() - after.times[k_at],
              1e-9);
  EXPECT_THROW(lfd_dmp::toJointTrajectory(after, ros::Time(0), 0.01, after.times.size()),
               std::invalid_argument);
  // Updates out of order, or of the wrong size, are refused.
  EXPECT_THROW(planner_.replan(lib_, targets(grasp, goal), {{0.0, targets(grasp, goal)}}, before,
                               q0_, 0.04, opt),
               std::invalid_argument);
  EXPECT_THROW(planner_.replan(lib_, targets(grasp, goal), {{at, {target("approach", grasp)}}},
                               before, q0_, 0.04, opt),
               std::invalid_argument);
}

// Which objects a plan follows and until when: each through 60% of the first segment whose goal
// frames name it (then the robot is at it; later the robot moves it). A move under both
// thresholds, an object not seen and a window that is over change nothing.
TEST_F(PlannerTest, ObjectsAreFollowedUntilTheRobotReachesThem) {
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
  const Eigen::Vector3d grasp = home_.position + Eigen::Vector3d(0.02, 0.0, -0.045);
  const lfd_dmp::ExecutionPlan plan =
      planner_.plan(lib_, targets(grasp, grasp + Eigen::Vector3d(0, 0.05, 0.1)), q0_, 0.04, opt);
  lfd_dmp::SkillLibrary lib = lib_;
  lib.segments[0].goal.emplace();
  lib.segments[0].goal->position_frame = lfd::SceneFrame::parse("object:block");
  lib.segments[1].goal.emplace();
  lib.segments[1].goal->position_frame = lfd::SceneFrame::parse("goal");
  lib.segments[1].goal->motion_frame = lfd::SceneFrame::parse("heading:block");
  lib.segments[1].goal->orientation_frame = lfd::SceneFrame::parse("object:tray");
  const lfd_dmp::FollowOptions follow;
  const auto windows = lfd_dmp::followWindows(lib, plan, follow);
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_NEAR(windows.at("block"), 0.6 * plan.segments[0].duration, 1e-9);
  EXPECT_NEAR(windows.at("tray"), plan.segments[0].duration + 0.6 * plan.segments[1].duration,
              1e-9);

  lfd::Scene planned;
  planned.objects["block"] = {Eigen::Vector3d(0.4, 0.0, 0.8), Eigen::Quaterniond::Identity()};
  planned.objects["tray"] = {Eigen::Vector3d(0.4, 0.3, 0.8), Eigen::Quaterniond::Identity()};
  std::map<std::string, lfd::Pose> now = planned.objects;
  EXPECT_TRUE(lfd_dmp::movedObjects(planned, now, windows, 0.5, follow).empty());
  now["block"].position.x() += 0.004;  // under 5 mm
  EXPECT_TRUE(lfd_dmp::movedObjects(planned, now, windows, 0.5, follow).empty());
  now["block"].position.x() += 0.04;
  const auto moved = lfd_dmp::movedObjects(planned, now, windows, 0.5, follow);
  ASSERT_EQ(moved.size(), 1u);
  EXPECT_EQ(moved[0].object, "block");
  EXPECT_NEAR(moved[0].shift, 0.044, 1e-9);
  EXPECT_EQ(lfd_dmp::describeMoves(moved), "object 'block' moved 4.40 cm and turned 0.00 deg");
  // Reached: the block rides with the robot now.
  EXPECT_TRUE(lfd_dmp::movedObjects(planned, now, windows, windows.at("block"), follow).empty());
  now["tray"].orientation = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(lfd_dmp::movedObjects(planned, now, windows, 3.0, follow).size(), 1u);
  now.erase("tray");  // not seen: not moved
  EXPECT_TRUE(lfd_dmp::movedObjects(planned, now, windows, 3.0, follow).empty());
  lfd_dmp::FollowOptions bad;
  bad.lead = 0.0;
  EXPECT_THROW(lfd_dmp::checkFollowOptions(bad), std::invalid_argument);
}

// Regression: the driver refuses a trajectory whose velocity is beyond a joint's limit; the
// executor checks the trajectory it would send first, so the goal fails naming the joint. A
// normal plan is within the limits.
TEST_F(PlannerTest, ATrajectoryFasterThanAJointsLimitIsRefusedBeforeItIsSent) {
  const Eigen::Vector3d grasp = this->grasp(), goal = this->goal();
  lfd_dmp::ExecutorOptions opt = coarse();
  const lfd_dmp::ExecutionPlan plan = planner_.plan(lib_, targets(grasp, goal), q0_, 0.04, opt);
  trajectory_msgs::JointTrajectory msg = lfd_dmp::toJointTrajectory(plan, ros::Time(0), 0.01);
  const Eigen::VectorXd& limits = chain_.velocityLimits();
  EXPECT_NO_THROW(lfd_dmp::checkTrajectoryVelocities(msg, chain_.jointNames(), limits));
  ASSERT_GT(limits[1], 0.0);
  msg.points[5].velocities[1] = -1.5 * limits[1];
  try {
    lfd_dmp::checkTrajectoryVelocities(msg, chain_.jointNames(), limits);
    ADD_FAILURE() << "a velocity over the limit passed";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("joint " + chain_.jointNames()[1]), std::string::npos) << what;
    EXPECT_NE(what.find("over its velocity limit"), std::string::npos) << what;
  }
}

TEST_F(PlannerTest, RefusesUnreachableGoalsAndMismatchedLibraries) {
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.01;
  const Eigen::Vector3d grasp = home_.position + Eigen::Vector3d(0.02, 0.0, -0.045);
  try {
    planner_.plan(lib_, targets(grasp, Eigen::Vector3d(2.0, -1.5, 0.5)), q0_, 0.04, opt);
    FAIL() << "an unreachable goal was accepted";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unreachable"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'move'"), std::string::npos) << msg;  // names the failing segment
  }
  auto one = targets(grasp, grasp);
  one.pop_back();
  EXPECT_THROW(planner_.plan(lib_, one, q0_, 0.04, opt), std::invalid_argument);
  EXPECT_THROW(planner_.plan(lib_, targets(grasp, grasp), Eigen::VectorXd::Zero(3), 0.04, opt),
               std::invalid_argument);
  lfd_dmp::SkillLibrary empty;
  EXPECT_THROW(planner_.plan(empty, {}, q0_, 0.04, opt), std::invalid_argument);
}

// Regression: a library (built in memory, past the loader's bounds) whose finite weights are so
// huge that the rollout overflows crashed the executor node (IK returned an empty joint vector).
// Planning must fail with a clear error instead.
TEST_F(PlannerTest, OverflowingSkillWeightsAreAClearError) {
  lfd_dmp::SkillLibrary lib = lib_;
  for (lfd_dmp::DemoSkill& demo : lib.segments[0].demos) {
    const lfd::PositionDmp p = *demo.dmp.position;  // a copy: emplace destroys the original
    demo.dmp.position.emplace(
        p.parameters(), p.tau(),
        Eigen::MatrixXd::Constant(p.weights().rows(), p.weights().cols(), 1e300), p.start(),
        p.goal(), p.startVelocity());
  }
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.01;
  const Eigen::Vector3d grasp = home_.position + Eigen::Vector3d(0.02, 0.0, -0.045);
  try {
    planner_.plan(lib, targets(grasp, grasp), q0_, 0.04, opt);
    FAIL() << "a plan from overflowing weights was accepted";
  } catch (const std::exception& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("finite"), std::string::npos) << msg;
  }
}

// Three push demos, each: approach (home -> behind the box), push (0.1 m straight along its
// direction). Directions +x, -y and +x+y: the pushes differ only by their heading.
lfd_dmp::SkillLibrary pushLibrary(const lfd_dmp::TcpPose& home) {
  const Eigen::Vector3d contacts[3] = {
      {0.02, 0.04, -0.05}, {0.08, 0.06, -0.05}, {0.0, -0.06, -0.05}};
  const Eigen::Vector3d directions[3] = {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY(),
                                         Eigen::Vector3d(1, 1, 0).normalized()};
  std::vector<Eigen::Vector3d> contact, end;
  for (int j = 0; j < 3; ++j) {
    contact.push_back(home.position + contacts[j]);
    end.push_back(contact.back() + 0.1 * directions[j]);
  }
  return twoSegmentLibrary({"push", "approach", "push", 0.0, 0.0, 2.0, 3.0}, home, contact, end);
}

// Largest distance of the planned push segment from the straight stroke it should follow.
double strokeDeviation(const lfd_dmp::ExecutionPlan& plan, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = (b - a).normalized();
  double worst = 0.0;
  for (size_t k = plan.segments[1].begin; k < plan.segments[1].end; ++k) {
    const Eigen::Vector3d r = plan.poses[k].position - a;
    worst = std::max(worst, (r - r.dot(u) * u).norm());
  }
  return worst;
}

TEST_F(PlannerTest, HeadingFrameKeepsAPushStraightInANewDirection) {
  const lfd_dmp::SkillLibrary lib = pushLibrary(home_);
  // A direction no demo pushed in: 29 degrees clockwise from +x.
  const Eigen::Vector3d contact = home_.position + Eigen::Vector3d(0.03, 0.0, -0.05);
  const Eigen::Vector3d end = contact + 0.1 * Eigen::Vector3d(std::cos(-0.5), std::sin(-0.5), 0);
  std::vector<lfd_dmp::SegmentTarget> t = {target("approach", contact), target("push", end)};
  lfd_dmp::HeadingFrame heading;  // the demos' own headings: +x, -y, +x+y
  heading.frame = "heading:box";
  heading.yaw = -0.5;
  heading.demo_yaw = {{"push_0", 0.0}, {"push_1", -M_PI / 2}, {"push_2", M_PI / 4}};
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
  opt.allow_extrapolation = true;  // the hand-made targets carry no range
  for (bool local_linear : {true, false}) {
    opt.generalization.local_linear = local_linear;
    t[1].heading = heading;
    const lfd_dmp::ExecutionPlan framed = planner_.plan(lib, t, q0_, std::nullopt, opt);
    EXPECT_LT(strokeDeviation(framed, contact, end), 0.001) << "local_linear " << local_linear;
    EXPECT_LT((framed.poses.back().position - end).norm(), 0.004);
    t[1].heading.reset();
    const lfd_dmp::ExecutionPlan world = planner_.plan(lib, t, q0_, std::nullopt, opt);
    if (!local_linear) {  // the convex mix of the demos' headings bends the stroke
      EXPECT_GT(strokeDeviation(world, contact, end), 0.005);
    }
  }
  // A one-way stroke is averaged over the demos (their shapes agree along the frame).
  t[1].heading = heading;
  EXPECT_EQ(planner_.plan(lib, t, q0_, std::nullopt, opt).segments[1].demos.size(), 3u);
  // No demo with a heading: a clear refusal.
  heading.demo_yaw = {{"another_demo", 0.0}};
  t[1].heading = heading;
  EXPECT_THROW(planner_.plan(lib, t, q0_, std::nullopt, opt), std::invalid_argument);
}

// A goal far from every demonstrated goal is refused before anything is planned, with the
// distance; allowed, it is planned with a warning. Either way the distance is reported.
TEST_F(PlannerTest, GoalsOutsideTheDemonstratedRangeAreRefusedUnlessAllowed) {
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.01;
  const Eigen::Vector3d grasp = home_.position + Eigen::Vector3d(0.02, 0.0, -0.045);
  auto t = targets(grasp, grasp + Eigen::Vector3d(0.0, 0.05, 0.12));
  t[1].range = {"goal", 0.2, 0.05, 0.03, 0.1};
  try {
    planner_.plan(lib_, t, q0_, 0.04, opt);
    FAIL() << "a goal outside the demonstrated range was planned";
  } catch (const lfd_dmp::OutsideDemoRange& e) {
    EXPECT_DOUBLE_EQ(e.distance, 0.2);
    EXPECT_DOUBLE_EQ(e.angle, 0.05);
    const std::string msg = e.what();
    EXPECT_NE(msg.find("segment 'move'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("allow_extrapolation"), std::string::npos) << msg;
  }
  opt.allow_extrapolation = true;
  const lfd_dmp::ExecutionPlan plan = planner_.plan(lib_, t, q0_, 0.04, opt);
  EXPECT_TRUE(plan.outside_demo_range);
  EXPECT_DOUBLE_EQ(plan.extrapolation_distance, 0.2);
  ASSERT_FALSE(plan.warnings.empty());
  EXPECT_NE(plan.warnings.back().find("allow_extrapolation"), std::string::npos);
  t[1].range.distance = 0.01;  // inside the margins: no flag, the distance still reported
  const lfd_dmp::ExecutionPlan inside = planner_.plan(lib_, t, q0_, 0.04, opt);
  EXPECT_FALSE(inside.outside_demo_range);
  EXPECT_DOUBLE_EQ(inside.extrapolation_distance, 0.01);
  // A goal beyond the demos' goals: the motion's shape comes from the kernel average there.
  t[1].shape_distance = 0.1;
  t[1].shape_margin = 0.02;
  const lfd_dmp::ExecutionPlan convex = planner_.plan(lib_, t, q0_, 0.04, opt);
  ASSERT_FALSE(convex.warnings.empty());
  EXPECT_NE(convex.warnings.back().find("kernel average"), std::string::npos);
}

// Regression: duration_scale 1000 took 1.36 GB. The plan is refused before anything is allocated,
// naming the limit; planning can be cancelled between pieces of work.
TEST_F(PlannerTest, LongPlansAreRefusedAndPlanningCanBeCancelled) {
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.002;
  opt.max_samples = 10000;  // 20 s at 500 Hz
  opt.duration_scale = 1000.0;
  const Eigen::Vector3d grasp = home_.position + Eigen::Vector3d(0.02, 0.0, -0.045);
  const auto t = targets(grasp, grasp + Eigen::Vector3d(0.0, 0.05, 0.12));
  try {
    planner_.plan(lib_, t, q0_, 0.04, opt);
    FAIL() << "a 4500 s plan was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_plan_seconds"), std::string::npos) << e.what();
  }
  opt.duration_scale = 1.0;
  int polls = 0;
  EXPECT_THROW(planner_.plan(lib_, t, q0_, 0.04, opt, [&] { return ++polls > 3; }),
               lfd_dmp::PlanningCancelled);
  EXPECT_EQ(polls, 4);
  EXPECT_NO_THROW(planner_.plan(lib_, t, q0_, 0.04, opt, [] { return false; }));
}

// Push demos recorded around the home pose, learned with their scenes: home -> behind the box
// (2 s), push it 12-15 cm (2 s), home (2 s); each pushes in another direction.
lfd_dmp::LearnOutcome learnedPushLibrary(const lfd_dmp::TcpPose& home) {
  const double directions[4] = {0.0, -M_PI / 2, M_PI / 4, -M_PI / 4};
  std::vector<lfd_dmp::DemoRecording> demos;
  std::vector<std::vector<double>> cps;
  for (int j = 0; j < 4; ++j) {
    const Eigen::Vector3d u(std::cos(directions[j]), std::sin(directions[j]), 0.0);
    const Eigen::Vector3d box = home.position + Eigen::Vector3d(0.06 + 0.01 * j, -0.02 * j, -0.06);
    lfd_dmp::DemoRecording rec;
    rec.id = "push_" + std::to_string(j);
    rec.frame = "base_link";
    lfd::Scene scene;
    scene.objects["box"].position = box;
    scene.goal.position = box + (0.12 + 0.01 * j) * u;
    rec.scene = scene;
    const Eigen::Vector3d via[4] = {home.position, box - 0.072 * u, scene.goal.position - 0.052 * u,
                                    home.position};
    const int m = 601;
    rec.times = Eigen::VectorXd::LinSpaced(m, 0.0, 6.0);
    rec.positions.resize(m, 3);
    rec.quaternions.resize(m, 4);
    for (int k = 0; k < m; ++k) {
      const double t = rec.times[k];
      const int s = std::min(2, static_cast<int>(t / 2.0));
      const double u_s = minJerk(std::clamp((t - 2.0 * s) / 2.0, 0.0, 1.0));
      rec.positions.row(k) = (via[s] + u_s * (via[s + 1] - via[s])).transpose();
      rec.quaternions.row(k) << home.orientation.w(), home.orientation.x(), home.orientation.y(),
          home.orientation.z();
    }
    demos.push_back(rec);
    cps.push_back({2.0, 4.0});
  }
  lfd_dmp::LearnOptions opt;
  opt.task = "push";
  opt.segment_names = {"approach", "push", "return"};
  opt.params.num_basis = 20;
  return lfd_dmp::learnSkillLibrary(demos, cps, opt);
}

TEST_F(PlannerTest, SegmentGoalsFollowTheFramesLearnedFromTheDemos) {
  const lfd_dmp::LearnOutcome learned = learnedPushLibrary(home_);
  const lfd_dmp::SkillLibrary& lib = learned.library;
  EXPECT_EQ(lib.segments[0].goal->position_frame.name(), "heading:box");
  EXPECT_EQ(lib.segments[1].goal->position_frame.name(), "goal_heading:box");
  ASSERT_TRUE(lib.segments[1].goal->motion_frame.has_value());  // the stroke follows the box's way
  EXPECT_EQ(lib.segments[1].goal->motion_frame->name(), "heading:box");
  EXPECT_FALSE(lib.segments[0].goal->motion_frame.has_value());
  // A new scene, pushing in a direction no demo pushed in.
  lfd::Scene scene;
  const Eigen::Vector3d box = home_.position + Eigen::Vector3d(0.07, -0.03, -0.06);
  const Eigen::Vector3d u(std::cos(-0.3), std::sin(-0.3), 0.0);
  scene.objects["box"].position = box;
  scene.goal.position = box + 0.11 * u;
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
  std::vector<std::string> warnings;
  const auto t = lfd_dmp::segmentTargets(lib, scene, home_, opt, &warnings);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_LT((t[0].goal.position - (box - 0.072 * u)).norm(), 1e-6);
  EXPECT_LT((t[1].goal.position - (scene.goal.position - 0.052 * u)).norm(), 1e-6);
  EXPECT_LT((t[2].goal.position - home_.position).norm(), 1e-6);
  EXPECT_EQ(t[1].frames.rfind("goal_heading:box / ", 0), 0u) << t[1].frames;
  EXPECT_NE(t[1].frames.find("(along heading:box)"), std::string::npos) << t[1].frames;
  ASSERT_TRUE(t[1].heading.has_value());
  EXPECT_NEAR(t[1].heading->yaw, -0.3, 1e-9);
  EXPECT_EQ(t[1].heading->demo_yaw.size(), 4u);
  EXPECT_FALSE(t[0].range.outside());  // a heading and a box position like the demos'
  EXPECT_FALSE(t[1].range.outside());
  const lfd_dmp::ExecutionPlan plan = planner_.plan(lib, t, q0_, std::nullopt, opt);
  EXPECT_LT((plan.poses[plan.segments[1].end - 1].position - t[1].goal.position).norm(), 0.004);
  EXPECT_LT(strokeDeviation(plan, t[0].goal.position, t[1].goal.position), 0.002);
  // A scene without the box, or with the box on its goal, is refused naming the segment.
  lfd::Scene no_box = scene;
  no_box.objects.clear();
  try {
    lfd_dmp::segmentTargets(lib, no_box, home_, opt, &warnings);
    FAIL() << "goals were computed without the box";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("segment 'approach'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no object 'box'"), std::string::npos) << e.what();
  }
  lfd::Scene there = scene;
  there.goal.position = box;
  EXPECT_THROW(lfd_dmp::segmentTargets(lib, there, home_, opt, &warnings), std::invalid_argument);
  // Far away: outside the range (reported), refused by plan() unless allowed.
  lfd::Scene far = scene;
  far.objects["box"].position += Eigen::Vector3d(0.5, 0.0, 0.0);
  far.goal.position += Eigen::Vector3d(0.5, 0.0, 0.0);
  const auto tf = lfd_dmp::segmentTargets(lib, far, home_, opt, &warnings);
  EXPECT_GT(tf[0].range.distance, 0.4);
  EXPECT_TRUE(tf[0].range.outside());
  EXPECT_GT(tf[0].shape_distance, tf[0].shape_margin);
  EXPECT_THROW(planner_.plan(lib, tf, q0_, std::nullopt, opt), lfd_dmp::OutsideDemoRange);
  // A library learned without scenes cannot be executed: relearn.
  lfd_dmp::SkillLibrary no_goals = lib;
  no_goals.segments[1].goal.reset();
  try {
    lfd_dmp::segmentTargets(no_goals, scene, home_, opt, &warnings);
    FAIL() << "a library without learned goals was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("relearn"), std::string::npos) << e.what();
  }
}

// A wipe recorded by a teleoperator: three 16 cm strokes along the yaw `heading`, centred at `c`,
// 1.6 s each, with a hesitation of 1.6 s before stroke `pause_before` (0, 1, 2).
lfd_dmp::DemoRecording wipeRecording(const std::string& id, const Eigen::Vector3d& c,
                                     double heading, int pause_before,
                                     const Eigen::Quaterniond& q) {
  const double stroke = 1.6, pause = 1.6, total = 3 * stroke + pause;
  const Eigen::Vector3d axis(std::cos(heading), std::sin(heading), 0.0);
  lfd_dmp::DemoRecording rec;
  rec.id = id;
  const int m = static_cast<int>(total * 100) + 1;
  rec.times = Eigen::VectorXd::LinSpaced(m, 0.0, total);
  rec.positions.resize(m, 3);
  rec.quaternions.resize(m, 4);
  for (int k = 0; k < m; ++k) {
    double t = rec.times[k], x = -0.08;
    for (int s = 0; s < 3; ++s) {
      const double hold = s == pause_before ? pause : 0.0, from = s % 2 == 0 ? -0.08 : 0.08;
      x = from - 2.0 * from * minJerk(std::clamp((t - hold) / stroke, 0.0, 1.0));
      if (t < hold + stroke) break;
      t -= hold + stroke;
    }
    rec.positions.row(k) = (c + x * axis).transpose();
    rec.quaternions.row(k) << q.w(), q.x(), q.y(), q.z();
  }
  return rec;
}

// The strokes of a planned segment along x: the shortest way between two turning points (a
// turn needs 1 cm of way back), and how many turns.
std::pair<double, int> shortestStroke(const lfd_dmp::ExecutionPlan& plan) {
  std::vector<double> x;
  for (const auto& p : plan.poses) x.push_back(p.position.x());
  const lfd_testing::Strokes s = lfd_testing::countStrokes(x);
  return {s.shortest, s.reversals};
}

// Three wipe demos, each hesitating before another stroke, in other places and headings. Learned
// as recorded, the executor's mix puts one demo's strokes on another's returns and they shrink;
// learned with their timing aligned, the mix keeps three full strokes.
TEST_F(PlannerTest, TheMixOfStrokesTimedDifferentlyKeepsThemWhenTheLearnerAlignsTheirTiming) {
  std::vector<lfd_dmp::DemoRecording> demos;
  const double headings[3] = {0.0, 0.4, -0.3};
  lfd_dmp::HeadingFrame frame;
  frame.frame = "goal";
  for (int j = 0; j < 3; ++j) {
    const std::string id = "wipe_" + std::to_string(j);
    const Eigen::Vector3d c = home_.position + Eigen::Vector3d(0.02 * j, -0.01 * j, -0.05);
    demos.push_back(wipeRecording(id, c, headings[j], j, home_.orientation));
    frame.demo_yaw[id] = headings[j];
  }
  const Eigen::Vector3d goal = home_.position + Eigen::Vector3d(0.09, 0.0, -0.05);
  std::vector<lfd_dmp::SegmentTarget> t = {target("wipe", goal)};
  t[0].heading = frame;
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
  opt.allow_extrapolation = true;  // the hand-made target carries no range
  lfd::CartesianToJoints ik = converter(chain_, q0_);
  lfd::TimedPose start{0.0, home_};  // start where the strokes start
  start.pose.position = goal - Eigen::Vector3d(0.16, 0, 0);
  const Eigen::VectorXd q_start = ik.convert({start}, q0_).positions[0];
  lfd_dmp::LearnOptions learn;
  learn.params.num_basis = 60;
  for (bool local_linear : {false, true}) {
    opt.generalization.local_linear = local_linear;
    for (bool aligned : {false, true}) {
      learn.time_alignment.reset();
      if (aligned) learn.time_alignment = lfd::TimeAlignmentOptions{};
      const lfd_dmp::LearnOutcome out =
          lfd_dmp::learnSkillLibrary(demos, {{}, {}, {}}, learn);  // one segment, no scenes
      const lfd_dmp::ExecutionPlan plan = planner_.plan(out.library, t, q_start, std::nullopt, opt);
      EXPECT_EQ(plan.segments[0].demos.size(), 3u);  // every demo in the mix
      const auto [shortest, turns] = shortestStroke(plan);
      if (aligned) {
        EXPECT_TRUE(out.library.time_alignment.has_value());  // recorded with the skills
        EXPECT_FALSE(out.library.segments[0].time_reference.empty());
        EXPECT_EQ(turns, 2) << "local_linear " << local_linear;
        EXPECT_GT(shortest, 0.15) << "local_linear " << local_linear;  // the demos' 16 cm
      } else if (!local_linear) {  // a convex mix: what alignment fixes
        EXPECT_LT(shortest, 0.12);
      }
    }
  }
}

// Nothing is task-specific: a task no code knows (four segments, objects named "cup" and "tray")
// learns where each segment ends from its scenes, and a new scene gives the goals.
TEST_F(PlannerTest, AnyTaskLearnsItsSegmentGoalsFromItsScenes) {
  std::vector<lfd_dmp::DemoRecording> demos;
  std::vector<std::vector<double>> cps;
  const Eigen::Vector3d up(0.0, 0.0, 0.06);
  for (int j = 0; j < 5; ++j) {
    lfd::Scene scene;
    scene.objects["cup"].position =
        home_.position + Eigen::Vector3d(0.05 - 0.02 * j, 0.03 * j - 0.06, -0.06);
    scene.objects["tray"].position = home_.position + Eigen::Vector3d(0.02 * j, -0.05, -0.07);
    scene.goal.position = home_.position + Eigen::Vector3d(-0.03 * j, 0.04 + 0.01 * j, -0.04);
    const Eigen::Vector3d via[5] = {home_.position, scene.objects["cup"].position,
                                    scene.goal.position, scene.goal.position + up, home_.position};
    lfd_dmp::DemoRecording rec;
    rec.id = "demo_" + std::to_string(j);
    rec.frame = "base_link";
    rec.scene = scene;
    const int m = 801;
    rec.times = Eigen::VectorXd::LinSpaced(m, 0.0, 8.0);
    rec.positions.resize(m, 3);
    rec.quaternions.resize(m, 4);
    for (int k = 0; k < m; ++k) {
      const int s = std::min(3, static_cast<int>(rec.times[k] / 2.0));
      const double u = minJerk(std::clamp((rec.times[k] - 2.0 * s) / 2.0, 0.0, 1.0));
      rec.positions.row(k) = (via[s] + u * (via[s + 1] - via[s])).transpose();
      rec.quaternions.row(k) << home_.orientation.w(), home_.orientation.x(), home_.orientation.y(),
          home_.orientation.z();
    }
    demos.push_back(rec);
    cps.push_back({2.0, 4.0, 6.0});
  }
  lfd_dmp::LearnOptions learn;
  learn.task = "stack";
  learn.segment_names = {"reach", "carry", "lift", "home"};
  learn.params.num_basis = 20;
  const lfd_dmp::SkillLibrary lib = lfd_dmp::learnSkillLibrary(demos, cps, learn).library;
  const char* expected[4] = {"object:cup", "goal", "goal", "start"};
  for (int s = 0; s < 4; ++s) EXPECT_EQ(lib.segments[s].goal->position_frame.name(), expected[s]);
  lfd::Scene scene;
  scene.objects["cup"].position = home_.position + Eigen::Vector3d(0.0, 0.0, -0.06);
  scene.objects["tray"].position = home_.position + Eigen::Vector3d(0.04, -0.05, -0.07);
  scene.goal.position = home_.position + Eigen::Vector3d(-0.05, 0.06, -0.04);
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
  std::vector<std::string> warnings;
  const auto t = lfd_dmp::segmentTargets(lib, scene, home_, opt, &warnings);
  EXPECT_LT((t[0].goal.position - scene.objects["cup"].position).norm(), 1e-6);
  EXPECT_LT((t[1].goal.position - scene.goal.position).norm(), 1e-6);
  EXPECT_LT((t[2].goal.position - (scene.goal.position + up)).norm(), 1e-6);
  EXPECT_LT((t[3].goal.position - home_.position).norm(), 1e-6);
  const lfd_dmp::ExecutionPlan plan = planner_.plan(lib, t, q0_, std::nullopt, opt);
  ASSERT_EQ(plan.segments.size(), 4u);
  for (int s = 0; s < 4; ++s)
    EXPECT_LT((plan.poses[plan.segments[s].end - 1].position - t[s].goal.position).norm(), 0.004);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
