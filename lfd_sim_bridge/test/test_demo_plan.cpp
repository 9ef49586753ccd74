// Unit tests of the task interpreter (demo_plan.hpp): the primitives of a task file turned into
// the demonstrator's phases -- frames (objects, goal, start, tcp, heading, touch, an object's
// frame moved by its joint), carry and push, gripper actions, guarded steps, speed scaling, the
// teleop operator's hesitations and timed close -- and the sampled Cartesian path.
#include <cmath>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "lfd_sim_bridge/demo_plan.hpp"

namespace demo = lfd_sim_bridge::demo;
namespace task = lfd_sim_bridge::task;

namespace {

const std::string kConfig = std::string(LFD_CONFIG_DIR) + "/";

demo::Pose pose(double x, double y, double z, double yaw = 0.0) {
  demo::Pose p;
  p.position = {x, y, z};
  p.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return p;
}

const demo::Pose kStart = pose(0.20, -0.25, 0.05);  // TCP in base_link (= world - 0.85 in z)

Eigen::Isometry3d worldFromBase() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(0, 0, 0.85);
  return t;
}

task::Scene scene() {
  return task::loadScene(kConfig + "scene.yaml");
}

task::TaskDefinition fromText(const std::string& text) {
  const std::string path = testing::TempDir() + "plan_task.yaml";
  std::ofstream(path) << text;
  return task::loadTask(path, scene());
}

task::TaskDefinition shipped(const std::string& name) {
  return task::loadTask(kConfig + "tasks/" + name + ".yaml", scene());
}

demo::TaskInterpreter interpreter(const task::TaskDefinition& t, bool teleop = false) {
  demo::TeleopStyle style;
  style.enabled = teleop;
  lfd::GripperSetup gripper;  // open 0.08, close 0.0 at 20 N
  return demo::TaskInterpreter(t, scene(), gripper, demo::ToolGeometry{}, style);
}

task::Configuration configuration(const std::map<std::string, demo::Pose>& objects,
                                  const demo::Pose& goal) {
  task::Configuration c;
  c.objects = objects;
  c.goal = goal;
  return c;
}

demo::DemoPlan plan(const demo::TaskInterpreter& in, const task::Configuration& c,
                    double speed = 1.0, uint32_t seed = 1) {
  std::mt19937 rng(seed);
  return in.planAll(in.begin(c, worldFromBase(), kStart, speed, rng));
}

const demo::Segment& segment(const demo::DemoPlan& p, const std::string& label) {
  for (const auto& phase : p.phases)
    for (const auto& s : phase.segments)
      if (s.label == label) return s;
  throw std::runtime_error("no segment " + label);
}

demo::Pose phaseEnd(const demo::DemoPlan& p, size_t index) {
  return p.phases.at(index).segments.back().target;
}

// The grasp of config/tasks/grasp.yaml without its per-demo variation (exact geometry).
const char* const kGrasp = R"(
objects: [stick]
phases:
  - name: approach
    steps:
      - {gripper: open, duration: 0.5}
      - {move: {frame: stick, position: [0, 0, 0.105], symmetry: 2}, duration: 2.0, label: pregrasp}
      - {move: {frame: stick, position: [0, 0, 0.005], symmetry: 2}, duration: 1.2, label: descend}
  - name: grasp
    window: true
    steps:
      - {gripper: close, until_contact: both, duration: 1.0, settle: 0.3, label: close}
  - name: move
    steps:
      - {retreat: [0, 0, 0.15], duration: 1.2, label: lift}
      - {carry: stick, to: {frame: goal}, duration: 2.0, label: carry}
      - {hold: 0.6}
success: [{rule: object_at_goal, object: stick, distance: xyz, tolerance_m: 0.03}]
configurations:
  sim: [{id: 0, stick: [0.4, -0.2, 0.815, 0.3], goal: [0.35, -0.35, 0.95, 0.8]}]
  teleop: [{id: 0, stick: [0.4, -0.2, 0.815, 0.3], goal: [0.35, -0.35, 0.95, 0.8]}]
)";

task::Configuration graspScene() {
  return configuration({{"stick", pose(0.40, -0.20, 0.815, 0.3)}}, pose(0.35, -0.35, 0.95, 0.8));
}

task::Configuration pushScene(const demo::Pose& goal) {
  return configuration({{"box", pose(0.40, -0.10, 0.84)}}, goal);
}

}  // namespace

TEST(TaskInterpreter, GraspPhasesAndGripperFromTheFile) {
  const demo::DemoPlan p = plan(interpreter(fromText(kGrasp)), graspScene());
  ASSERT_EQ(p.phases.size(), 3u);
  EXPECT_EQ(p.phases[0].name, "approach");
  EXPECT_EQ(p.phases[1].name, "grasp");
  EXPECT_TRUE(p.phases[1].window);
  EXPECT_EQ(p.phases[2].name, "move");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.phases[i].index, i);
  ASSERT_TRUE(p.phases[0].segments.front().gripper.has_value());
  EXPECT_DOUBLE_EQ(p.phases[0].segments.front().gripper->opening, 0.08);  // robot.yaml's open
  const demo::Segment& close = segment(p, "close");
  ASSERT_TRUE(close.gripper.has_value());
  EXPECT_EQ(close.until_contact, demo::Contact::kBoth);
  EXPECT_DOUBLE_EQ(close.gripper->opening, 0.0);
  EXPECT_DOUBLE_EQ(close.gripper->max_effort, 20.0);
  EXPECT_DOUBLE_EQ(close.settle, 0.3);
}

TEST(TaskInterpreter, GraspGeometryLiftsAndCarriesTheStickToItsGoal) {
  const demo::DemoPlan p = plan(interpreter(fromText(kGrasp)), graspScene());
  const demo::Pose grasp = phaseEnd(p, 0);  // in base_link: the world minus 0.85 in z
  EXPECT_LT((grasp.position - Eigen::Vector3d(0.40, -0.20, 0.815 + 0.005 - 0.85)).norm(), 1e-9);
  EXPECT_NEAR(demo::yawOf(grasp.orientation), 0.3, 1e-9);
  const demo::Pose pre = segment(p, "pregrasp").target;
  EXPECT_LT((pre.position - grasp.position - Eigen::Vector3d(0, 0, 0.10)).norm(), 1e-9);
  EXPECT_LT(
      (segment(p, "lift").target.position - grasp.position - Eigen::Vector3d(0, 0, 0.15)).norm(),
      1e-9);
  // The stick keeps its place in the hand: it ends at its goal, turned by the goal's yaw.
  const demo::Pose end = phaseEnd(p, 2);
  EXPECT_LT((end.position - Eigen::Vector3d(0.35, -0.35, 0.95 + 0.005 - 0.85)).norm(), 1e-9);
  EXPECT_NEAR(demo::yawOf(end.orientation), 0.8, 1e-9);
}

TEST(TaskInterpreter, SymmetricToolTakesTheNearestTurn) {
  // A stick at yaw 2.8 rad is grasped at 2.8 - pi (the gripper is symmetric by a half turn).
  const demo::DemoPlan p =
      plan(interpreter(fromText(kGrasp)),
           configuration({{"stick", pose(0.4, -0.2, 0.815, 2.8)}}, pose(0.35, -0.35, 0.95, 2.8)));
  EXPECT_NEAR(demo::yawOf(phaseEnd(p, 0).orientation), 2.8 - M_PI, 1e-9);
}

TEST(TaskInterpreter, PushTouchesTheBoxFaceAndEndsBehindTheTarget) {
  const demo::DemoPlan p = plan(interpreter(shipped("push")), pushScene(pose(0.50, -0.10, 0.84)));
  const double face = 0.04 + 0.012;  // box half size + fist half width
  const demo::Pose contact = phaseEnd(p, 0);
  EXPECT_NEAR(contact.position.x(), 0.40 - face, 1e-12);
  EXPECT_NEAR(contact.position.y(), -0.10, 1e-12);
  EXPECT_NEAR(contact.position.z(), 0.84 - 0.85, 1e-12);  // at the box's centre height
  EXPECT_NEAR(segment(p, "lower").target.position.x(), 0.40 - face - 0.02, 1e-12);
  const demo::Pose pushed = phaseEnd(p, 1);
  EXPECT_NEAR(pushed.position.x(), 0.50 - face, 1e-12);
  EXPECT_NEAR(pushed.position.z(), contact.position.z(), 1e-12);  // along the table
  EXPECT_NEAR(segment(p, "retreat").target.position.x(), 0.50 - face - 0.06, 1e-12);
  // The demo returns to where it started.
  EXPECT_LT((phaseEnd(p, 2).position - kStart.position).norm(), 1e-12);
}

TEST(TaskInterpreter, DiagonalPushTouchesTheBoxCorner) {
  // Pushed along its diagonal, the cube meets the fist with a corner, half * sqrt(2) from its
  // centre: the approach must end there, not at the face distance (which is inside the box).
  const demo::DemoPlan p = plan(interpreter(shipped("push")), pushScene(pose(0.50, 0.0, 0.84)));
  const Eigen::Vector3d offset =
      Eigen::Vector3d(0.40, -0.10, 0.84 - 0.85) - phaseEnd(p, 0).position;
  EXPECT_NEAR(offset.head<2>().norm(), 0.04 * std::sqrt(2.0) + 0.012, 1e-9);
  EXPECT_NEAR(offset.x(), offset.y(), 1e-12);  // straight behind, along the push
}

TEST(TaskInterpreter, SlightlyOffAxisPushMeetsTheFaceNotTheCorner) {
  // 16 degrees off the box's axis, the corner lies beside the push line, out of the fist's
  // reach: the fist's trailing edge touches the face first.
  const double angle = 16.0 * M_PI / 180.0, half = 0.04, fist = 0.012;
  const demo::DemoPlan p =
      plan(interpreter(shipped("push")),
           pushScene(pose(0.40 + 0.1 * std::cos(angle), -0.10 + 0.1 * std::sin(angle), 0.84)));
  const Eigen::Vector3d offset = Eigen::Vector3d(0.40, -0.10, -0.01) - phaseEnd(p, 0).position;
  const double face_depth = (half + fist * std::sin(angle)) / std::cos(angle);
  ASSERT_LT(face_depth, half * (std::cos(angle) + std::sin(angle)));  // not the corner
  EXPECT_NEAR(offset.head<2>().norm(), face_depth + fist, 1e-9);
}

TEST(TaskInterpreter, AHeadingTowardItsOwnOriginIsAClearError) {
  const demo::TaskInterpreter in = interpreter(shipped("push"));
  std::mt19937 rng(1);
  try {
    in.begin(pushScene(pose(0.40, -0.10, 0.84)), worldFromBase(), kStart, 1.0, rng);
    FAIL() << "a push to where the box already is was planned";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("push.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("frames.heading"), std::string::npos) << e.what();
  }
}

TEST(TaskInterpreter, ObjectFramesFollowTheirJoint) {
  // The drawer's handle (scene.yaml: 0.145 m out of its front, 7 cm up) with the drawer 3 cm open.
  const task::TaskDefinition t = shipped("drawer");
  task::Configuration c = configuration({{"drawer", pose(0.70, -0.30, 0.80, M_PI)}},
                                        pose(0.70 - 0.145 - 0.10, -0.30, 0.87, M_PI));
  c.joints["drawer_slide"] = 0.03;
  std::mt19937 rng(1);
  const demo::TaskInterpreter in = interpreter(t);
  const demo::DemoState s = in.begin(c, worldFromBase(), kStart, 1.0, rng);
  const demo::Frame& handle = s.true_starts.at("drawer.handle");
  EXPECT_NEAR(handle.position.x(), 0.70 - 0.145 - 0.03, 1e-9);
  EXPECT_NEAR(handle.position.z(), 0.87 - 0.85, 1e-9);
  // Pulled to the goal: the hand ends where it holds the handle, moved by the goal's offset.
  const demo::DemoPlan p = in.planAll(s);
  EXPECT_NEAR(phaseEnd(p, 2).position.x() - phaseEnd(p, 0).position.x(), -0.07, 1e-9);
}

TEST(TaskInterpreter, GuardedStepsAndReplanningFromAContact) {
  const demo::TaskInterpreter in = interpreter(shipped("wipe"));
  std::mt19937 rng(1);
  demo::DemoState s =
      in.begin(configuration({}, pose(0.5, -0.3, 0.80)), worldFromBase(), kStart, 1.0, rng);
  const demo::Phase approach = in.planPhase(s, 0, kStart);
  EXPECT_EQ(approach.segments.back().until_contact, demo::Contact::kAny);
  EXPECT_EQ(approach.segments.front().until_contact, demo::Contact::kNone);
  // Stopped 12 mm above its target: the next phase starts there; its targets are the goal's.
  demo::Pose stopped = approach.segments.back().target;
  stopped.position.z() += 0.012;
  const demo::Phase press = in.planPhase(s, 1, stopped);
  EXPECT_EQ(press.name, "press");
  EXPECT_TRUE(press.window);
  EXPECT_NEAR(press.segments.front().target.position.z(), 0.80 + 0.006 - 0.85, 1e-12);
  // Relative to the TCP, the lift-off follows where the wipe ended.
  demo::Pose wiped = in.planPhase(s, 2, press.segments.back().target).segments.back().target;
  wiped.position.y() += 0.01;
  const demo::Phase lift = in.planPhase(s, 3, wiped);
  EXPECT_LT(
      (lift.segments.front().target.position - wiped.position - Eigen::Vector3d(0, 0, 0.02)).norm(),
      1e-12);
}

TEST(TaskInterpreter, SpeedScalesEveryDuration) {
  const demo::TaskInterpreter in = interpreter(fromText(kGrasp));
  const double nominal = plan(in, graspScene(), 1.0).duration();
  EXPECT_NEAR(nominal, 0.5 + 2.0 + 1.2 + 1.0 + 1.2 + 2.0 + 0.6, 1e-9);
  EXPECT_NEAR(plan(in, graspScene(), 2.0).duration(), nominal / 2.0, 1e-9);
  EXPECT_NEAR(plan(in, graspScene(), 0.7).duration(), nominal / 0.7, 1e-9);
  EXPECT_THROW(plan(in, graspScene(), 0.0), std::invalid_argument);
}

TEST(TaskInterpreter, VariationMovesWhereTheHandTakesTheObject) {
  // grasp.yaml: +-1.5 cm along the stick, +-0.08 rad.
  const demo::TaskInterpreter in = interpreter(shipped("grasp"));
  double spread = 0.0;
  for (uint32_t seed = 1; seed < 20; ++seed) {
    const demo::Pose g = phaseEnd(plan(in, graspScene(), 1.0, seed), 0);
    const Eigen::Vector3d d = g.position - Eigen::Vector3d(0.40, -0.20, -0.03);
    EXPECT_LE(std::abs(d.dot(Eigen::Vector3d(-std::sin(0.3), std::cos(0.3), 0))),
              1e-9);  // along it
    EXPECT_LE(d.head<2>().norm(), 0.015 + 1e-9);
    EXPECT_LE(std::abs(demo::yawOf(g.orientation) - 0.3), 0.08 + 1e-9);
    spread = std::max(spread, d.head<2>().norm());
  }
  EXPECT_GT(spread, 0.005);
}

TEST(TaskInterpreter, TeleopHesitatesAndClosesByTime) {
  const demo::TaskInterpreter sim = interpreter(fromText(kGrasp));
  const demo::TaskInterpreter teleop = interpreter(fromText(kGrasp), true);
  int hesitations = 0, durations_differ = 0;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const demo::DemoPlan p = plan(teleop, graspScene(), 1.0, seed);
    for (const auto& phase : p.phases)
      for (const auto& s : phase.segments)
        hesitations += s.label.find("_hesitate") != std::string::npos;
    durations_differ +=
        std::abs(p.duration() - plan(sim, graspScene(), 1.0, seed).duration()) > 1e-6;
    // No force feedback: a reaction delay, then a timed close without waiting for contact.
    const demo::Phase& grasp = p.phases[1];
    ASSERT_EQ(grasp.segments.size(), 2u);
    EXPECT_EQ(grasp.segments[0].label, "react");
    EXPECT_EQ(grasp.segments[1].until_contact, demo::Contact::kNone);
    EXPECT_NEAR(grasp.segments[1].duration, 0.9, 1e-12);
    // A hesitation splits a move but it still ends at the same pose.
    EXPECT_LT((phaseEnd(p, 2).position - phaseEnd(plan(sim, graspScene()), 2).position).norm(),
              1e-9);
  }
  EXPECT_GT(hesitations, 5);
  EXPECT_GT(durations_differ, 15);
}

TEST(SamplePhase, ContinuousFromStartToEnd) {
  const demo::DemoPlan p = plan(interpreter(fromText(kGrasp)), graspScene());
  demo::Pose from = p.start;
  for (const demo::Phase& phase : p.phases) {
    const double dt = 0.02;
    const auto samples = demo::samplePhase(from, phase, dt, 0.0);
    ASSERT_GE(samples.size(), 2u);
    EXPECT_LT((samples.front().pose.position - from.position).norm(), 1e-12);
    EXPECT_LT((samples.back().pose.position - phase.segments.back().target.position).norm(), 1e-12);
    EXPECT_NEAR(samples.back().t, phase.duration(), 1e-12);
    for (size_t k = 1; k < samples.size(); ++k)  // minimum-jerk: < 2 m/s anywhere here
      EXPECT_LT((samples[k].pose.position - samples[k - 1].pose.position).norm(), 2.0 * dt);
    from = phase.segments.back().target;
  }
}

TEST(SamplePhase, TremorIsAddedOnTopOfThePath) {
  const demo::DemoPlan p = plan(interpreter(fromText(kGrasp)), graspScene());
  const demo::Tremor tremor(0.002, 8.0, 12.0, 3);
  const auto clean = demo::samplePhase(p.start, p.phases[0], 0.01, 5.0);
  const auto shaky = demo::samplePhase(p.start, p.phases[0], 0.01, 5.0, &tremor);
  ASSERT_EQ(clean.size(), shaky.size());
  double sum2 = 0.0;
  for (size_t k = 0; k < clean.size(); ++k) {
    const Eigen::Vector3d d = shaky[k].pose.position - clean[k].pose.position;
    EXPECT_LT((d - tremor.at(5.0 + clean[k].t)).norm(), 1e-12);
    sum2 += d.squaredNorm() / 3.0;
  }
  EXPECT_NEAR(std::sqrt(sum2 / clean.size()), 0.002, 0.001);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
