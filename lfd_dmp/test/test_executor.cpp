// Executor logic without ROS: segment goal rules, gripper thresholding, segment sequencing of the
// planned path, and refusal of unreachable goals / mismatched libraries before anything moves.
#include "lfd_dmp/executor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

// From CMake, not __FILE__: ccache (CCACHE_BASEDIR) makes __FILE__ relative to the build tree.
const std::string kUrdf = std::string(LFD_REPO_DIR) + "/lfd_sim_bridge/models/jvrc1_like.urdf";

lfd::KinematicChain chain() {
  return lfd::KinematicChain::fromUrdfFile(kUrdf, "base_link", "r_gripper_tcp");
}

// tasks.yaml preferred posture (TCP fingers-down above the workspace centre).
Eigen::VectorXd homePosture(const lfd::KinematicChain& c) {
  const std::map<std::string, double> p = {
      {"WAIST_Y", 0.08},       {"WAIST_P", 0.24},       {"R_SHOULDER_P", -0.72},
      {"R_SHOULDER_R", -0.23}, {"R_SHOULDER_Y", -0.06}, {"R_ELBOW_P", -1.02},
      {"R_ELBOW_Y", -0.19},    {"R_WRIST_R", 0.09},     {"R_WRIST_Y", 1.51}};
  Eigen::VectorXd q = Eigen::VectorXd::Zero(c.dof());
  for (int i = 0; i < c.dof(); ++i)
    if (p.count(c.jointNames()[i])) q[i] = p.at(c.jointNames()[i]);
  return q;
}

double minJerk(double u) {
  return u * u * u * (10 - 15 * u + 6 * u * u);
}

// A min-jerk segment between two points with a gripper ramp from g0 to g1.
lfd::SegmentDmp learnSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Quaterniond& q, double g0, double g1, double T) {
  const int m = 200;
  lfd::SegmentDemo d;
  d.times.resize(m);
  d.positions.resize(m, 3);
  d.quaternions.resize(m, 4);
  d.gripper.resize(m);
  for (int k = 0; k < m; ++k) {
    const double u = static_cast<double>(k) / (m - 1);
    d.times[k] = u * T;
    d.positions.row(k) = (a + minJerk(u) * (b - a)).transpose();
    d.quaternions.row(k) << q.w(), q.x(), q.y(), q.z();
    d.gripper[k] = g0 + minJerk(u) * (g1 - g0);
  }
  lfd::DmpParameters params;
  params.num_basis = 20;
  return lfd::SegmentDmp::learn(d, params);
}

// A two-segment library: demo j moves home -> via[j] in t0 s (gripper g0 -> g1), then
// via[j] -> end[j] in t1 s (gripper held at g1).
struct TwoSegmentTask {
  std::string task, first, second;
  double g0 = 0.0, g1 = 0.0, t0 = 2.0, t1 = 2.5;
};
lfd_dmp::SkillLibrary twoSegmentLibrary(const TwoSegmentTask& spec, const lfd_dmp::TcpPose& home,
                                        const std::vector<Eigen::Vector3d>& via,
                                        const std::vector<Eigen::Vector3d>& end) {
  lfd_dmp::SkillLibrary lib;
  lib.task = spec.task;
  lib.segments.resize(2);
  lib.segments[0].name = spec.first;
  lib.segments[1].name = spec.second;
  for (size_t j = 0; j < via.size(); ++j) {
    for (int s = 0; s < 2; ++s) {
      lfd_dmp::DemoSkill d;
      d.demo_id = spec.task + "_" + std::to_string(j);
      d.dmp = s == 0
                  ? learnSegment(home.position, via[j], home.orientation, spec.g0, spec.g1, spec.t0)
                  : learnSegment(via[j], end[j], home.orientation, spec.g1, spec.g1, spec.t1);
      d.parameters = lfd::goalParameters(d.dmp);
      lib.dmp_parameters = d.dmp.params;
      lib.segments[s].demos.push_back(d);
    }
  }
  return lib;
}

// Three demos of a two-segment "reach then carry" task around the home TCP pose; the gripper
// closes during the first segment.
lfd_dmp::SkillLibrary library(const lfd_dmp::TcpPose& home) {
  const Eigen::Vector3d offsets[3] = {
      {0.05, -0.05, -0.04}, {-0.05, -0.03, -0.05}, {0.0, 0.06, -0.045}};
  std::vector<Eigen::Vector3d> grasp, goal;
  for (int j = 0; j < 3; ++j) {
    grasp.push_back(home.position + offsets[j]);
    goal.push_back(grasp.back() + Eigen::Vector3d(-0.04 * j, 0.05, 0.12));
  }
  return twoSegmentLibrary({"grasp", "approach", "move", 0.04, 0.015, 2.0, 2.5}, home, grasp, goal);
}

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

TEST(SegmentTargets, GraspAndPushRulesFollowTheSituation) {
  lfd_dmp::TaskGoalModel grasp;
  grasp.segments = {{"approach",
                     lfd_dmp::GoalReference::kObject,
                     {0, 0, 0.005},
                     0.0,
                     lfd_dmp::OrientationRule::kObjectYaw},
                    {"move",
                     lfd_dmp::GoalReference::kGoal,
                     {0, 0, 0.005},
                     0.0,
                     lfd_dmp::OrientationRule::kGoalYaw}};
  lfd_dmp::TaskSituation s;
  s.object_position = {0.5, -0.3, -0.035};
  s.object_yaw = 0.2 + M_PI;  // a stick is symmetric: the wrist takes the small yaw
  s.goal_position = {0.4, -0.2, 0.1};
  s.goal_yaw = -0.3;
  lfd_dmp::TcpPose start;
  const auto t = lfd_dmp::segmentTargets(grasp, s, start, Eigen::Quaterniond::Identity());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_NEAR((t[0].position - Eigen::Vector3d(0.5, -0.3, -0.03)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((t[1].position - Eigen::Vector3d(0.4, -0.2, 0.105)).norm(), 0.0, 1e-12);
  ASSERT_TRUE(t[0].orientation && t[1].orientation);
  EXPECT_NEAR(t[0].orientation->angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()))),
              0.0, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(*t[1].orientation).angle(), 0.3, 1e-9);

  lfd_dmp::TaskGoalModel push;
  push.segments = {
      {"approach",
       lfd_dmp::GoalReference::kObject,
       {0, 0, 0},
       -0.072,
       lfd_dmp::OrientationRule::kPushYaw},
      {"push",
       lfd_dmp::GoalReference::kGoal,
       {0, 0, 0},
       -0.052,
       lfd_dmp::OrientationRule::kPushYaw,
       "push"},
      {"return", lfd_dmp::GoalReference::kStart, {0, 0, 0}, 0.0, lfd_dmp::OrientationRule::kStart}};
  s.object_position = {0.5, -0.16, -0.01};
  s.goal_position = {0.5, -0.30, -0.01};  // push along -y
  start.position = {0.3, -0.3, 0.1};
  const auto p = lfd_dmp::segmentTargets(push, s, start, Eigen::Quaterniond::Identity());
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NEAR((p[0].position - Eigen::Vector3d(0.5, -0.16 + 0.072, -0.01)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p[1].position - Eigen::Vector3d(0.5, -0.30 + 0.052, -0.01)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p[2].position - start.position).norm(), 0.0, 1e-12);
  EXPECT_EQ(p[0].frame, "");
  EXPECT_EQ(p[1].frame, "push");
  EXPECT_NEAR((*p[0].orientation * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, -1, 0)).norm(),
              0.0, 1e-9);
  s.goal_position = s.object_position;
  EXPECT_THROW(lfd_dmp::segmentTargets(push, s, start, Eigen::Quaterniond::Identity()),
               std::invalid_argument);
  EXPECT_THROW(lfd_dmp::parseGoalReference("table"), std::invalid_argument);
  EXPECT_THROW(lfd_dmp::parseOrientationRule("sideways"), std::invalid_argument);
}

// The planner's IK: the chain with default options, pulled toward the home posture.
lfd::CartesianToJoints converter(const lfd::KinematicChain& chain, const Eigen::VectorXd& home) {
  lfd::CartesianToJoints ik(chain);
  ik.setPreferredPosture(home);
  return ik;
}

class PlannerTest : public ::testing::Test {
 protected:
  PlannerTest()
      : chain_(chain()), q0_(homePosture(chain_)), planner_(converter(chain_, q0_)) {
    home_ = planner_.forward(q0_);
    lib_ = library(home_);
  }
  std::vector<lfd_dmp::SegmentTarget> targets(const Eigen::Vector3d& grasp,
                                              const Eigen::Vector3d& goal) const {
    return {{"approach", grasp, home_.orientation}, {"move", goal, home_.orientation}};
  }
  lfd::KinematicChain chain_;
  Eigen::VectorXd q0_;
  lfd_dmp::TaskPlanner planner_;
  lfd_dmp::TcpPose home_;
  lfd_dmp::SkillLibrary lib_;
};

TEST_F(PlannerTest, SegmentsRunInSequenceFromTheCurrentPoseToEachNewGoal) {
  const Eigen::Vector3d grasp = home_.position + Eigen::Vector3d(0.02, 0.0, -0.045);
  const Eigen::Vector3d goal = grasp + Eigen::Vector3d(-0.03, 0.05, 0.12);
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
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

// Issue 12: a library (built in memory, past the loader's bounds) whose finite weights are so
// huge that the rollout overflows crashed the executor node (IK returned an empty joint vector).
// Planning must fail with a clear error instead.
TEST_F(PlannerTest, OverflowingSkillWeightsAreAClearError) {
  lfd_dmp::SkillLibrary lib = lib_;
  for (lfd_dmp::DemoSkill& demo : lib.segments[0].demos) {
    const lfd::PositionDmp p = *demo.dmp.position;  // a copy: emplace destroys the original
    demo.dmp.position.emplace(p.parameters(), p.tau(),
                              Eigen::MatrixXd::Constant(p.weights().rows(), p.weights().cols(), 1e300),
                              p.start(), p.goal(), p.startVelocity());
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

TEST_F(PlannerTest, TaskFrameKeepsAPushStraightInANewDirection) {
  const lfd_dmp::SkillLibrary lib = pushLibrary(home_);
  // A direction no demo pushed in: 29 degrees clockwise from +x.
  const Eigen::Vector3d contact = home_.position + Eigen::Vector3d(0.03, 0.0, -0.05);
  const Eigen::Vector3d end = contact + 0.1 * Eigen::Vector3d(std::cos(-0.5), std::sin(-0.5), 0);
  std::vector<lfd_dmp::SegmentTarget> t = {{"approach", contact, home_.orientation, ""},
                                           {"push", end, home_.orientation, "push"}};
  lfd_dmp::ExecutorOptions opt;
  opt.dt = 0.004;
  for (bool local_linear : {true, false}) {
    opt.generalization.local_linear = local_linear;
    t[1].frame = "push";
    const lfd_dmp::ExecutionPlan framed = planner_.plan(lib, t, q0_, std::nullopt, opt);
    EXPECT_LT(strokeDeviation(framed, contact, end), 0.001) << "local_linear " << local_linear;
    EXPECT_LT((framed.poses.back().position - end).norm(), 0.004);
    t[1].frame.clear();
    const lfd_dmp::ExecutionPlan world = planner_.plan(lib, t, q0_, std::nullopt, opt);
    if (!local_linear) {  // the convex mix of the demos' headings bends the stroke
      EXPECT_GT(strokeDeviation(world, contact, end), 0.005);
    }
  }
  // A heading that is not defined, or a frame segment that does not exist: clear refusals.
  const std::vector<lfd_dmp::SegmentTarget> no_stroke = {
      {"approach", contact, home_.orientation, ""},
      {"push", contact + Eigen::Vector3d(0.005, 0, 0.02), home_.orientation, "push"}};
  try {
    planner_.plan(lib, no_stroke, q0_, std::nullopt, opt);
    FAIL() << "a push without a heading was planned";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("heading"), std::string::npos) << e.what();
  }
  t[1].frame = "lift";
  EXPECT_THROW(planner_.plan(lib, t, q0_, std::nullopt, opt), std::invalid_argument);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
