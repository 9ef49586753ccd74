// Learner: cutting demos at changepoints into per-segment DMPs, and reading demo bags.
#include "lfd_dmp/demo_bag.hpp"
#include "lfd_dmp/demo_scene.hpp"
#include "lfd_dmp/skill_learner.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <lfd_msgs/DemoMetadata.h>
#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <gtest/gtest.h>

#include "declared_type_bytes.hpp"
#include "link_swap_race.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace {

// Approach (0..2 s), grasp-and-carry (2..4 s), return (4..5 s); gripper closes around 2 s. The
// scene: the stick at the object, the goal where it is carried (its x mirrors the object's).
lfd_dmp::DemoRecording recording(const std::string& id, double object_x, double hz = 100.0) {
  lfd_dmp::DemoRecording rec;
  rec.id = id;
  rec.frame = "base_link";
  lfd::Scene scene;
  scene.objects["stick"].position = Eigen::Vector3d(object_x, 0.0, 0.8);
  scene.goal.position = Eigen::Vector3d(1.1 - object_x, 0.1, 1.0);
  rec.scene = scene;
  const int m = static_cast<int>(5.0 * hz) + 1;
  rec.times = Eigen::VectorXd::LinSpaced(m, 10.0, 15.0);  // bag time does not start at 0
  rec.positions.resize(m, 3);
  rec.quaternions.resize(m, 4);
  rec.gripper.resize(m);
  auto mj = [](double s) {
    s = std::clamp(s, 0.0, 1.0);
    return 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
  };
  for (int i = 0; i < m; ++i) {
    const double t = rec.times[i] - 10.0;
    const Eigen::Vector3d home(0.3, -0.2, 0.9), object(object_x, 0.0, 0.8),
        lifted(1.1 - object_x, 0.1, 1.0);
    Eigen::Vector3d p = home + (object - home) * mj(t / 2.0);
    if (t > 2.0) p = object + (lifted - object) * mj((t - 2.0) / 2.0);
    if (t > 4.0) p = lifted + (home - lifted) * mj(t - 4.0);
    rec.positions.row(i) = p.transpose();
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.4 * mj(t / 5.0), Eigen::Vector3d::UnitZ()));
    rec.quaternions.row(i) << q.w(), q.x(), q.y(), q.z();
    rec.gripper[i] = 0.08 - 0.06 * mj((t - 1.8) / 0.4);
  }
  return rec;
}

TEST(SkillLearner, CutsDemosAtChangepointsIntoSegmentDmps) {
  std::vector<lfd_dmp::DemoRecording> demos = {recording("a.bag", 0.6), recording("b.bag", 0.7),
                                               recording("c.bag", 0.65)};
  std::vector<std::vector<double>> cps = {{12.0, 14.0}, {12.0, 14.0}, {13.0}};  // c: inconsistent
  lfd_dmp::LearnOptions opt;
  opt.task = "grasp";
  opt.segment_names = {"approach", "grasp", "move"};
  opt.features = {"gripper", "speed"};
  const auto out = lfd_dmp::learnSkillLibrary(demos, cps, opt);
  EXPECT_EQ(out.demos_used, 2u);
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_NE(out.warnings[0].find("c.bag skipped"), std::string::npos);
  const auto& lib = out.library;
  ASSERT_EQ(lib.segments.size(), 3u);
  EXPECT_EQ(lib.segments[0].name, "approach");
  EXPECT_EQ(lib.segments[2].name, "move");
  EXPECT_EQ(lib.features, opt.features);
  for (const auto& seg : lib.segments) ASSERT_EQ(seg.demos.size(), 2u);
  // Segment 0 of demo b ends at its object; its goal parameters are that position.
  const auto& s0 = lib.segments[0].demos[1];
  EXPECT_NEAR(s0.start_time, 10.0, 1e-9);
  EXPECT_NEAR(s0.end_time, 12.0, 1e-9);
  EXPECT_LT((s0.parameters - Eigen::Vector3d(0.7, 0.0, 0.8)).norm(), 1e-9);
  // Each segment DMP reproduces its piece of the demo, including the gripper closing.
  const auto& s1 = lib.segments[1].demos[0];
  lfd::SegmentRolloutOptions o;
  o.dt = 0.01;
  const auto traj = s1.dmp.rollout(o);
  const Eigen::MatrixXd truth = demos[0].positions.middleRows(200, 201);
  EXPECT_LT((traj.positions - truth).rowwise().norm().maxCoeff(), 1e-3);
  EXPECT_NEAR(traj.gripper[traj.gripper.size() - 1], 0.02, 1e-3);
  // Consecutive segments join at the same sample.
  EXPECT_EQ(lib.segments[0].demos[0].end_time, lib.segments[1].demos[0].start_time);
  // Where each segment ends was learned from the scenes: at the stick, at the goal, back home.
  ASSERT_TRUE(lib.segments[0].goal && lib.segments[1].goal && lib.segments[2].goal);
  EXPECT_EQ(lib.segments[0].goal->position_frame.name(), "object:stick");
  EXPECT_LT(lib.segments[0].goal->position_offset.norm(), 1e-9);
  EXPECT_EQ(lib.segments[1].goal->position_frame.name(), "goal");
  EXPECT_TRUE(lib.segments[2].goal->position_frame.name() == "base" ||
              lib.segments[2].goal->position_frame.name() == "start");
  EXPECT_LT(lib.segments[2].goal->position_spread, 1e-9);
  EXPECT_EQ(lib.cartesian_frame, "base_link");
  ASSERT_EQ(lib.demo_scenes.size(), 2u);  // the used demos' scenes, for heading frames
  EXPECT_LT((lib.demo_scenes.at("b.bag").start.position - Eigen::Vector3d(0.3, -0.2, 0.9)).norm(),
            1e-9);
}

TEST(SkillLearner, ScenesForSomeDemosOnlyOrMixedFramesAreRefused) {
  std::vector<lfd_dmp::DemoRecording> demos = {recording("a.bag", 0.6), recording("b.bag", 0.7)};
  const std::vector<std::vector<double>> cps = {{12.0, 14.0}, {12.0, 14.0}};
  lfd_dmp::LearnOptions opt;
  demos[1].scene.reset();
  try {
    lfd_dmp::learnSkillLibrary(demos, cps, opt);
    FAIL() << "a library was learned with a scene for one demo of two";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("b.bag"), std::string::npos) << e.what();
  }
  demos[0].scene.reset();  // no scene at all: the DMPs, no goals, and a warning saying so
  const auto out = lfd_dmp::learnSkillLibrary(demos, cps, opt);
  EXPECT_FALSE(out.library.segments[0].goal.has_value());
  ASSERT_EQ(out.warnings.size(), 1u);
  EXPECT_NE(out.warnings[0].find("cannot reproduce"), std::string::npos) << out.warnings[0];
  demos[1].frame = "world";
  EXPECT_THROW(lfd_dmp::learnSkillLibrary(demos, cps, opt), std::invalid_argument);
}

// A teleoperated demo: the same motion plus 10 Hz, 3 mm tremor. Without smoothing the DMPs replay
// the tremor (centimetres once the start velocity is the robot's); with it, the intended motion.
TEST(SkillLearner, NamesSegmentsOnlyWhenTheVoteGivesTheTasksCount) {
  // The vote (2 of 3 demos: two changepoints -> three segments) does not give the two segments the
  // task names: no segment is called "approach", and the warning says why.
  std::vector<lfd_dmp::DemoRecording> demos = {recording("a.bag", 0.6), recording("b.bag", 0.7),
                                               recording("c.bag", 0.65)};
  std::vector<std::vector<double>> cps = {{12.0, 14.0}, {12.0, 14.0}, {13.0}};
  lfd_dmp::LearnOptions opt;
  opt.task = "grasp";
  opt.segment_names = {"approach", "move"};
  const auto out = lfd_dmp::learnSkillLibrary(demos, cps, opt);
  ASSERT_EQ(out.library.segments.size(), 3u);
  for (size_t s = 0; s < 3; ++s)
    EXPECT_EQ(out.library.segments[s].name, "segment_" + std::to_string(s));
  ASSERT_EQ(out.warnings.size(), 2u);
  EXPECT_NE(out.warnings[0].find("left unnamed"), std::string::npos) << out.warnings[0];
}

TEST(SkillLearner, SmoothingKeepsTheMotionAndDropsTheTremor) {
  const lfd_dmp::DemoRecording clean = recording("clean.bag", 0.6);
  lfd_dmp::DemoRecording shaky = clean;
  shaky.id = "shaky.bag";
  for (Eigen::Index i = 0; i < shaky.times.size(); ++i) {
    const double t = shaky.times[i];
    shaky.positions.row(i) +=
        0.003 * Eigen::RowVector3d(std::sin(2 * M_PI * 10 * t), std::cos(2 * M_PI * 10.3 * t),
                                   std::sin(2 * M_PI * 9.7 * t + 1));
  }
  lfd_dmp::LearnOptions opt;
  // The three segments' rollouts of a demo learned with `sigma`, between the clean demo's segment
  // boundaries (as the executor gives every segment its start and goal).
  const auto reference = lfd_dmp::learnSkillLibrary({clean}, {{12.0, 14.0}}, opt).library;
  auto rollouts = [&](const lfd_dmp::DemoRecording& demo, double sigma) {
    opt.smoothing_sigma = sigma;
    const auto out = lfd_dmp::learnSkillLibrary({demo}, {{12.0, 14.0}}, opt);
    EXPECT_EQ(out.library.smoothing_sigma, sigma);  // recorded with the skills
    std::vector<Eigen::MatrixXd> parts;
    for (size_t s = 0; s < out.library.segments.size(); ++s) {
      const lfd::PositionDmp& ref = *reference.segments[s].demos[0].dmp.position;
      lfd::SegmentRolloutOptions o;
      o.dt = 0.01;
      o.start_position = ref.start();
      o.goal_position = ref.goal();
      o.start_velocity = ref.startVelocity();
      parts.push_back(out.library.segments[s].demos[0].dmp.rollout(o).positions);
    }
    return parts;
  };
  auto worst = [](const std::vector<Eigen::MatrixXd>& a, const std::vector<Eigen::MatrixXd>& b) {
    double err = 0.0;
    for (size_t s = 0; s < a.size(); ++s)
      err = std::max(err, (a[s] - b[s]).rowwise().norm().maxCoeff());
    return err;
  };
  const auto truth = rollouts(clean, 0.0);
  EXPECT_GT(worst(rollouts(shaky, 0.0), truth), 0.01);  // the tremor is learned, and amplified
  // Smoothed, the shaky demo gives the skills of the smoothed clean one: the tremor is gone...
  const auto clean_smoothed = rollouts(clean, 0.05);
  EXPECT_LT(worst(rollouts(shaky, 0.05), clean_smoothed), 0.001);
  // ... and the motion is kept up to the smoother's curvature bias (sigma^2 / 2 x 2.5 m/s^2 at
  // the fastest turn of this 1 s, 44 cm return).
  EXPECT_LT(worst(clean_smoothed, truth), 0.004);
  opt.smoothing_sigma = -1.0;
  EXPECT_THROW(lfd_dmp::learnSkillLibrary({clean}, {{12.0}}, opt), std::invalid_argument);
}

// Alignment re-times each segment's demos, never where a segment starts or ends: the segment times,
// ends and goals are the recorded ones; demos timed alike keep their DMPs; the alignment and each
// segment's reference demo are recorded with the skills.
TEST(SkillLearner, TimeAlignmentKeepsEachSegmentsTimesAndEnds) {
  const std::vector<lfd_dmp::DemoRecording> demos = {recording("a.bag", 0.6),
                                                     recording("b.bag", 0.7)};
  const std::vector<std::vector<double>> cps = {{12.0, 14.0}, {12.0, 14.0}};
  lfd_dmp::LearnOptions opt;
  const lfd_dmp::SkillLibrary as_recorded = lfd_dmp::learnSkillLibrary(demos, cps, opt).library;
  opt.time_alignment = lfd::TimeAlignmentOptions{};
  const lfd_dmp::SkillLibrary aligned = lfd_dmp::learnSkillLibrary(demos, cps, opt).library;
  ASSERT_TRUE(aligned.time_alignment.has_value());
  EXPECT_FALSE(as_recorded.time_alignment.has_value());
  for (size_t s = 0; s < 3; ++s) {
    EXPECT_FALSE(aligned.segments[s].time_reference.empty());
    EXPECT_TRUE(as_recorded.segments[s].time_reference.empty());
    EXPECT_EQ(aligned.segments[s].goal->position_frame.name(),
              as_recorded.segments[s].goal->position_frame.name());
    for (size_t d = 0; d < 2; ++d) {
      const lfd_dmp::DemoSkill& a = aligned.segments[s].demos[d];
      const lfd_dmp::DemoSkill& r = as_recorded.segments[s].demos[d];
      EXPECT_EQ(a.start_time, r.start_time);
      EXPECT_EQ(a.end_time, r.end_time);
      EXPECT_EQ(a.dmp.tau, r.dmp.tau);
      EXPECT_LT((a.parameters - r.parameters).norm(), 1e-12);
      EXPECT_LT((a.dmp.position->start() - r.dmp.position->start()).norm(), 1e-12);
      // The two demos are timed alike (their paths differ in length, not in timing).
      EXPECT_LT((a.dmp.rollout().positions - r.dmp.rollout().positions).cwiseAbs().maxCoeff(),
                0.002);
    }
  }
}

TEST(SkillLearner, RejectsUnusableInput) {
  std::vector<lfd_dmp::DemoRecording> demos = {recording("a.bag", 0.6)};
  lfd_dmp::LearnOptions opt;
  EXPECT_THROW(lfd_dmp::learnSkillLibrary({}, {}, opt), std::invalid_argument);
  EXPECT_THROW(lfd_dmp::learnSkillLibrary(demos, {}, opt), std::invalid_argument);
  try {
    lfd_dmp::learnSkillLibrary(demos, {{16.0}}, opt);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("outside the recording"), std::string::npos) << e.what();
  }
  // A changepoint 2 samples after the start leaves a segment too short for a DMP.
  try {
    lfd_dmp::learnSkillLibrary(demos, {{10.02}}, opt);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("segment 0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at least"), std::string::npos) << e.what();
  }
}

// A demo bag as the recorder writes it: poses, gripper, and optionally the metadata (scene) and
// the static transform world -> base_link (base_link 0.85 m up).
// `late_index` >= 0: that pose is stamped `late_seconds` after its time, yet recorded in its place
// (a publisher's clock that jumped): the bag holds it out of stamp order.
void writeBag(const std::string& path, const lfd_dmp::DemoRecording& rec,
              const std::string& extra_json, bool tf_static, Eigen::Index late_index = -1,
              double late_seconds = 0.0) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  const ros::Time t0(rec.times[0]);
  if (!extra_json.empty()) {
    lfd_msgs::DemoMetadata meta;
    meta.header.stamp = t0;
    meta.extra_json = extra_json;
    bag.write("/lfd/metadata", t0, meta);
  }
  if (tf_static) {
    tf2_msgs::TFMessage tf;
    geometry_msgs::TransformStamped t;
    t.header.frame_id = "world";
    t.child_frame_id = "base_link";
    t.transform.translation.z = 0.85;
    t.transform.rotation.w = 1.0;
    tf.transforms.push_back(t);
    bag.write("/tf_static", t0, tf);
  }
  for (Eigen::Index i = 0; i < rec.times.size(); ++i) {
    geometry_msgs::PoseStamped p;
    p.header.stamp = ros::Time(rec.times[i]);
    p.header.frame_id = "base_link";
    p.pose.position.x = rec.positions(i, 0);
    p.pose.position.y = rec.positions(i, 1);
    p.pose.position.z = rec.positions(i, 2);
    p.pose.orientation.w = rec.quaternions(i, 0);
    p.pose.orientation.x = rec.quaternions(i, 1);
    p.pose.orientation.y = rec.quaternions(i, 2);
    p.pose.orientation.z = rec.quaternions(i, 3);
    const ros::Time received = p.header.stamp;
    if (i == late_index) p.header.stamp = ros::Time(rec.times[i] + late_seconds);
    bag.write("/ee_pose", received, p);
    p.header.stamp = received;
    if (i % 2 == 0) {  // gripper at half the rate: interpolated onto the pose stamps
      sensor_msgs::JointState js;
      js.header.stamp = p.header.stamp;
      js.name = {"R_GRIPPER"};
      js.position = {rec.gripper[i]};
      bag.write("/gripper/state", js.header.stamp, js);
    }
  }
  bag.close();
}

TEST(DemoBag, ReadsPosesAndInterpolatesTheGripper) {
  const std::string path =
      ::testing::TempDir() + "/lfd_dmp_demo_" + std::to_string(::getpid()) + ".bag";
  const lfd_dmp::DemoRecording rec = recording(path, 0.6, 50.0);
  writeBag(path, rec, "", false);
  const lfd_dmp::DemoRecording back = lfd_dmp::readDemoBag(path);
  ASSERT_EQ(back.times.size(), rec.times.size());
  EXPECT_LT((back.times - rec.times).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((back.positions - rec.positions).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((back.quaternions - rec.quaternions).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_EQ(back.gripper.size(), rec.gripper.size());
  EXPECT_LT((back.gripper - rec.gripper).cwiseAbs().maxCoeff(), 2e-3);
  EXPECT_EQ(back.frame, "base_link");
  EXPECT_FALSE(back.scene.has_value());  // no metadata: no scene (and no error)
  std::remove(path.c_str());
  EXPECT_THROW(lfd_dmp::readDemoBag(path), std::runtime_error);
}

// Regression: a topic declared geometry_msgs/PoseStamped whose message holds other bytes (here a
// PoseStamped cut short) made roscpp throw "Buffer Overrun", which was all the learner said. The
// error names the file, the topic, the declared type, the message's index and time.
TEST(DemoBag, MessageBytesThatDoNotMatchTheDeclaredTypeAreNamed) {
  const std::string path =
      ::testing::TempDir() + "/lfd_dmp_mismatch_" + std::to_string(::getpid()) + ".bag";
  const lfd_dmp::DemoRecording rec = recording(path, 0.6, 50.0);
  writeBag(path, rec, "", false);
  {
    rosbag::Bag bag(path, rosbag::bagmode::Append);
    geometry_msgs::PoseStamped p;
    p.header.stamp = ros::Time(rec.times[3] + 0.001);
    p.header.frame_id = "base_link";
    std::vector<std::uint8_t> bytes = lfd_test::serializedBytes(p);
    bytes.resize(bytes.size() - 20);  // the orientation cut off
    lfd_test::writeAsDeclaredType<geometry_msgs::PoseStamped>(bag, "/ee_pose", p.header.stamp,
                                                              bytes);
  }
  try {
    lfd_dmp::readDemoBag(path);
    ADD_FAILURE() << "a message cut short was read";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("message 4 on '/ee_pose' (declared 'geometry_msgs/PoseStamped') at t = "),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("its bytes do not match the declared message definition"),
              std::string::npos)
        << what;
  }
  std::remove(path.c_str());
}

// Regression: a link swapped between a demo bag and a FIFO while the learner reads it never
// hangs it in open() (it checked the path, then opened it again by name).
TEST(DemoBag, LinkSwappedToFifoNeverHangsTheReader) {
  const std::string dir = ::testing::TempDir() + "/lfd_dmp_race_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string bag = dir + "/real.bag";
  writeBag(bag, recording(bag, 0.6, 50.0), "", false);
  const lfd_test::LinkSwapRaceResult r =
      lfd_test::raceLinkSwap(dir + "/link.bag", bag, dir + "/pipe.bag",
                             [](const std::string& link) { lfd_dmp::readDemoBag(link); });
  EXPECT_EQ(r.hung_calls, 0) << "of " << r.calls << " calls";
  EXPECT_GT(r.read_calls, 0);
  std::filesystem::remove_all(dir);
}

// Regression: one pose stamped 5 s late. The reader used to skip every pose stamped before it
// (half the demo) and the learner succeeded with its first segment ending 3 s off; the shared
// timestamp policy keeps every pose in stamp order and warns, naming the topic and the count.
TEST(DemoBag, APoseStampedLateIsPutInOrderAndWarned) {
  const std::string path =
      ::testing::TempDir() + "/lfd_dmp_late_" + std::to_string(::getpid()) + ".bag";
  lfd_dmp::DemoRecording rec = recording(path, 0.6, 50.0);
  rec.times = Eigen::VectorXd::LinSpaced(rec.times.size(), 10.0, 20.0);  // a 10 s demo
  const Eigen::Index late = 50;                                          // at t = 12 s
  writeBag(path, rec, "", false, late, 5.02);  // between two samples' stamps
  lfd_dmp::DemoRecording back = lfd_dmp::readDemoBag(path);
  back.scene = rec.scene;                          // the bag holds no metadata
  ASSERT_EQ(back.times.size(), rec.times.size());  // nothing dropped
  for (Eigen::Index i = 1; i < back.times.size(); ++i) ASSERT_LT(back.times[i - 1], back.times[i]);
  ASSERT_EQ(back.warnings.size(), 1u);
  EXPECT_NE(back.warnings[0].find("/ee_pose: of 251 messages, 1 stamped out of order"),
            std::string::npos)
      << back.warnings[0];
  // The learner's segment times stay where the changepoints are.
  lfd_dmp::DemoRecording other = recording("b.bag", 0.7, 50.0);
  other.times = rec.times;
  const auto out = lfd_dmp::learnSkillLibrary({back, other}, {{14.0, 18.0}, {14.0, 18.0}}, {});
  ASSERT_EQ(out.library.segments.size(), 3u);
  const auto& first = out.library.segments[0].demos[0];
  EXPECT_NEAR(first.start_time, 10.0, 1e-6);
  EXPECT_NEAR(first.end_time, 14.0, 0.05);
  EXPECT_NEAR(out.library.segments[1].demos[0].end_time, 18.0, 0.05);
  std::remove(path.c_str());
}

// The scene of the metadata (the "scene" block, or the older object/object_start/goal fields) is
// brought from the world into the poses' frame with the bag's /tf_static.
TEST(DemoBag, ReadsTheSceneIntoThePosesFrame) {
  const std::string path =
      ::testing::TempDir() + "/lfd_dmp_scene_" + std::to_string(::getpid()) + ".bag";
  const lfd_dmp::DemoRecording rec = recording(path, 0.6, 50.0);
  const std::string scene =
      R"({"scene": {"frame": "world", "objects": {"box": {"position": [0.5, -0.3, 0.84],)"
      R"( "orientation": [1, 0, 0, 0]}}, "goal": {"position": [0.6, -0.3, 0.84]}, "joints": {}},)"
      R"( "object": "stick", "object_start": {"position": [0, 0, 0]}, "goal": {"position": [0, 0, 0]}})";
  writeBag(path, rec, scene, true);
  lfd_dmp::DemoRecording back = lfd_dmp::readDemoBag(path);
  ASSERT_TRUE(back.scene.has_value());
  ASSERT_EQ(back.scene->objects.count("box"), 1u);  // the scene block first
  EXPECT_LT((back.scene->objects.at("box").position - Eigen::Vector3d(0.5, -0.3, -0.01)).norm(),
            1e-12);
  EXPECT_NEAR(back.scene->goal.position.z(), -0.01, 1e-12);
  const std::string legacy =
      R"({"object": "stick", "frame": "world", "object_start": {"position": [0.4, -0.2, 0.815],)"
      R"( "orientation": [0.995, 0, 0, 0.0998]}, "goal": {"position": [0.5, -0.3, 0.95],)"
      R"( "orientation": [1, 0, 0, 0]}, "table_top": 0.8})";
  writeBag(path, rec, legacy, true);
  back = lfd_dmp::readDemoBag(path);
  ASSERT_TRUE(back.scene.has_value());
  EXPECT_NEAR(back.scene->objects.at("stick").position.z(), -0.035, 1e-12);
  EXPECT_NEAR(back.scene->objects.at("stick").orientation.norm(), 1.0, 1e-12);  // normalized
  // A scene in the world without the transform to the poses' frame: an error that says so.
  writeBag(path, rec, legacy, false);
  try {
    lfd_dmp::readDemoBag(path);
    FAIL() << "a world scene was read without world -> base_link";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/tf_static"), std::string::npos) << e.what();
  }
  // A malformed scene names the field.
  writeBag(path, rec, R"({"scene": {"objects": {"box": {"position": [1, 2]}}, "goal": {}}})", true);
  try {
    lfd_dmp::readDemoBag(path);
    FAIL() << "a malformed scene was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.objects.box.position"), std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());
}

TEST(DemoScene, StaticTransformsChainAndRefuseWhatDoesNotConnect) {
  lfd_dmp::StaticTransforms tf;
  Eigen::Isometry3d up = Eigen::Isometry3d::Identity();
  up.translation().z() = 0.85;
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  turned.translation().x() = 0.1;
  tf.add("world", "base_link", up);
  tf.add("base_link", "chest", turned);
  const Eigen::Isometry3d world_in_chest = tf.lookup("chest", "world");
  EXPECT_NEAR((world_in_chest * Eigen::Vector3d(0.1, 1.0, 0.85) - Eigen::Vector3d(1, 0, 0)).norm(),
              0.0, 1e-12);
  EXPECT_TRUE(tf.lookup("world", "world").isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_THROW(tf.lookup("world", "camera"), std::runtime_error);
  EXPECT_THROW(tf.add("a", "a", up), std::runtime_error);
  EXPECT_FALSE(lfd_dmp::sceneFromMetadata(R"({"seed": 3})").has_value());
  EXPECT_THROW(lfd_dmp::sceneFromMetadata("{not json"), std::runtime_error);
  EXPECT_THROW(lfd_dmp::sceneFromMetadata(
                   R"({"object": "s", "object_start": {"position": [0, 0, 0],)"
                   R"( "orientation": [0, 0, 0, 0]}, "goal": {"position": [0, 0, 0]}})"),
               std::runtime_error);
}

// A transform of random rotation and translation (seeded: the same every run).
Eigen::Isometry3d randomTransform(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return t;
}

// Lookups chain through the tree as the products of the transforms along it: up from the source
// to the frame both descend from, down to the target (here across two branches of depth 3).
TEST(DemoScene, StaticTransformsChainedLookupsEqualTheProducts) {
  std::mt19937 rng(7);
  const Eigen::Isometry3d base_in_world = randomTransform(rng),
                          chest_in_base = randomTransform(rng),
                          camera_in_chest = randomTransform(rng),
                          table_in_world = randomTransform(rng),
                          box_in_table = randomTransform(rng);
  lfd_dmp::StaticTransforms tf;
  EXPECT_TRUE(tf.empty());
  tf.add("world", "base_link", base_in_world);
  tf.add("base_link", "chest", chest_in_base);
  tf.add("chest", "head_camera", camera_in_chest);
  tf.add("world", "table", table_in_world);
  tf.add("/table", "box", box_in_table);  // tf2 drops the leading '/': the same "table"
  EXPECT_FALSE(tf.empty());

  const Eigen::Isometry3d camera_in_world = base_in_world * chest_in_base * camera_in_chest;
  const Eigen::Isometry3d box_in_world = table_in_world * box_in_table;
  auto expectNear = [](const Eigen::Isometry3d& got, const Eigen::Isometry3d& want) {
    EXPECT_LT((got.matrix() - want.matrix()).cwiseAbs().maxCoeff(), 1e-12) << got.matrix();
  };
  expectNear(tf.lookup("world", "head_camera"), camera_in_world);
  expectNear(tf.lookup("head_camera", "world"), camera_in_world.inverse());
  expectNear(tf.lookup("box", "head_camera"), box_in_world.inverse() * camera_in_world);
  expectNear(tf.lookup("chest", "box"), (base_in_world * chest_in_base).inverse() * box_in_world);
  expectNear(tf.lookup("/world", "box"), box_in_world);
  // A point through the chain and back is where it started.
  const Eigen::Vector3d p(0.3, -0.2, 0.9);
  EXPECT_LT((tf.lookup("box", "head_camera") * (tf.lookup("head_camera", "box") * p) - p).norm(),
            1e-12);
  // A frame given a new parent moves with it (a later /tf_static message replaces the former).
  tf.add("chest", "box", box_in_table);
  expectNear(tf.lookup("world", "box"), base_in_world * chest_in_base * box_in_table);
  EXPECT_THROW(tf.lookup("world", "nowhere"), std::runtime_error);
  EXPECT_THROW(tf.add("", "a", box_in_table), std::runtime_error);
  EXPECT_THROW(tf.add("/a", "a", box_in_table), std::runtime_error);
  Eigen::Isometry3d bad = box_in_table;
  bad.translation().x() = std::nan("");
  EXPECT_THROW(tf.add("world", "c", bad), std::runtime_error);
}

// The touch pads of recording(): loaded while the stick is held (2..4 s), on the demo's clock.
lfd::FeatureMatrix touchOf(const lfd_dmp::DemoRecording& rec, double level, const char* name) {
  lfd::FeatureMatrix m;
  m.names = {name};
  m.data.resize(rec.times.size(), 1);
  for (Eigen::Index i = 0; i < rec.times.size(); ++i) {
    const double t = rec.times[i] - rec.times[0];
    m.time.push_back(rec.times[i]);
    m.data(i, 0) = (t > 2.05 && t < 3.95 ? level : 0.0) + 0.01 * std::sin(37.0 * t);
  }
  return m;
}

TEST(SkillLearner, LearnsTheSensorySignatureOfEachSegment) {
  std::vector<lfd_dmp::DemoRecording> demos;
  for (double x : {0.6, 0.65, 0.7}) {
    demos.push_back(recording("d" + std::to_string(x) + ".bag", x));
    demos.back().sensors = touchOf(demos.back(), 4.0 + 10 * (x - 0.6), "/touch/values/0");
    demos.back().sensor_sources = {"/touch"};
  }
  demos.push_back(recording("other.bag", 0.62));
  demos.back().sensors = touchOf(demos.back(), 4.0, "/pads/left");
  const std::vector<std::vector<double>> cps(demos.size(), {12.0, 14.0});
  lfd_dmp::LearnOptions opt;
  opt.task = "grasp";
  opt.signature = lfd::SignatureOptions();
  const auto out = lfd_dmp::learnSkillLibrary(demos, cps, opt);
  ASSERT_TRUE(out.library.sensory_signature.has_value());
  const lfd::SensorySignature& sig = *out.library.sensory_signature;
  EXPECT_EQ(sig.demonstrations, 3u);  // other.bag's sensor differs: left out, and said so
  bool said = false;
  for (const auto& w : out.warnings)
    said = said || w.find("other.bag left out") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_EQ(sig.channels, std::vector<std::string>{"/touch/values/0"});
  EXPECT_EQ(sig.sources, std::vector<std::string>{"/touch"});
  ASSERT_EQ(sig.segments.size(), 3u);
  EXPECT_NEAR(sig.segments[1].duration_mean, 2.0, 0.02);
  EXPECT_NEAR(sig.segments[1].channels[0].mean[25], 4.5, 0.1);   // held: the pads loaded
  EXPECT_NEAR(sig.segments[0].channels[0].mean[25], 0.0, 0.05);  // approach: nothing touched

  for (auto& d : demos) d.sensors = lfd::FeatureMatrix();
  const auto none = lfd_dmp::learnSkillLibrary(demos, cps, opt);
  EXPECT_FALSE(none.library.sensory_signature.has_value());
  said = false;
  for (const auto& w : none.warnings)
    said = said || w.find("no sensory signature") != std::string::npos;
  EXPECT_TRUE(said);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
