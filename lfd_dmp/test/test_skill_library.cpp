// Skill library JSON: round trip and validation errors.
#include "lfd_dmp/skill_library.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>

namespace {

using lfd_dmp::SkillLibrary;

lfd::SegmentDmp learnDemo(double goal_x) {
  lfd::SegmentDemo demo;
  demo.times = Eigen::VectorXd::LinSpaced(200, 0.0, 1.5);
  demo.positions.resize(200, 3);
  demo.quaternions.resize(200, 4);
  demo.gripper.resize(200);
  for (int i = 0; i < 200; ++i) {
    const double s = demo.times[i] / 1.5;
    const double mj = 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
    demo.positions.row(i) << 0.3 + (goal_x - 0.3) * mj, 0.1 * std::sin(M_PI * s), 0.8 + 0.05 * mj;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7 * mj, Eigen::Vector3d::UnitZ()));
    demo.quaternions.row(i) << q.w(), q.x(), q.y(), q.z();
    demo.gripper[i] = 0.08 - 0.07 * mj;
  }
  return lfd::SegmentDmp::learn(demo);
}

SkillLibrary makeLibrary() {
  SkillLibrary lib;
  lib.task = "grasp";
  lib.features = {"gripper_opening", "ee_speed", "ee_x"};
  lib.smoothing_sigma = 0.05;
  lib.time_alignment = lfd::TimeAlignmentOptions{0.04, 0.12, false};
  for (int s = 0; s < 2; ++s) {
    lfd_dmp::SegmentSkills seg;
    seg.index = s;
    seg.name = s == 0 ? "approach" : "move";
    seg.time_reference = "demo_1.bag";
    for (int d = 0; d < 2; ++d) {
      lfd_dmp::DemoSkill skill;
      skill.demo_id = "demo_" + std::to_string(d) + ".bag";
      skill.start_time = 1.5 * s;
      skill.end_time = 1.5 * (s + 1);
      skill.dmp = learnDemo(0.5 + 0.1 * d + 0.2 * s);
      skill.parameters = skill.dmp.position->goal();
      seg.demos.push_back(skill);
    }
    lfd::SegmentGoalModel goal;
    goal.position_frame = lfd::SceneFrame::parse(s == 0 ? "object:stick" : "goal");
    goal.position_offset = Eigen::Vector3d(0.01, 0.0, 0.005);
    goal.position_spread = 0.004;
    goal.orientation_frame = lfd::SceneFrame::parse("heading:stick");
    goal.orientation_offset = Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()));
    goal.orientation_spread = 0.05;
    if (s == 1) goal.motion_frame = lfd::SceneFrame::parse("heading:stick");
    goal.motion_spread = 0.1;
    goal.candidates = {
        {lfd::SceneFrame::parse("base"), 0.2, 0.3},
        {lfd::SceneFrame::parse("heading:stick"), std::numeric_limits<double>::infinity(), 0.05}};
    seg.goal = goal;
    lib.segments.push_back(seg);
  }
  for (int d = 0; d < 2; ++d) {
    lfd_dmp::DemoScene scene;
    scene.start.position = Eigen::Vector3d(0.3, -0.3, 0.1);
    scene.scene.objects["stick"].position = Eigen::Vector3d(0.5 + 0.1 * d, -0.2, -0.035);
    scene.scene.goal.position = Eigen::Vector3d(0.4, -0.3, 0.1);
    lib.demo_scenes["demo_" + std::to_string(d) + ".bag"] = scene;
  }
  return lib;
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "/lfd_dmp_test_" + std::to_string(::getpid()) + "_" + name;
}

std::string loadError(const nlohmann::json& j) {
  const std::string path = tempPath("bad.json");
  std::ofstream(path) << j.dump();
  try {
    lfd_dmp::loadSkillLibrary(path);
  } catch (const std::runtime_error& e) {
    std::remove(path.c_str());
    return e.what();
  }
  std::remove(path.c_str());
  return "";
}

TEST(SkillLibrary, RoundTripKeepsEverything) {
  const SkillLibrary lib = makeLibrary();
  const std::string path = tempPath("lib.json");
  lfd_dmp::saveSkillLibrary(lib, path, false);
  const SkillLibrary back = lfd_dmp::loadSkillLibrary(path);
  EXPECT_EQ(lfd_dmp::toJson(back), lfd_dmp::toJson(lib));
  EXPECT_EQ(back.task, "grasp");
  EXPECT_EQ(back.features, lib.features);
  EXPECT_EQ(back.smoothing_sigma, 0.05);
  ASSERT_TRUE(back.time_alignment.has_value());
  EXPECT_EQ(back.time_alignment->sample_seconds, 0.04);
  EXPECT_EQ(back.time_alignment->warp_sigma, 0.12);
  EXPECT_FALSE(back.time_alignment->yaw_invariant);
  EXPECT_EQ(back.segments[1].time_reference, "demo_1.bag");
  EXPECT_EQ(back.cartesian_frame, "base_link");
  ASSERT_EQ(back.demo_scenes.size(), 2u);
  EXPECT_EQ(back.demo_scenes.at("demo_1.bag").scene.objects.at("stick").position.x(), 0.6);
  ASSERT_TRUE(back.segments[1].goal.has_value());
  EXPECT_EQ(back.segments[1].goal->position_frame.name(), "goal");
  ASSERT_TRUE(back.segments[1].goal->motion_frame.has_value());
  EXPECT_EQ(back.segments[1].goal->motion_frame->name(), "heading:stick");
  EXPECT_FALSE(back.segments[0].goal->motion_frame.has_value());
  EXPECT_TRUE(std::isinf(back.segments[1].goal->candidates[1].position_m));  // undefined frame
  ASSERT_EQ(back.segments.size(), 2u);
  EXPECT_EQ(back.segments[1].name, "move");
  const auto& a = lib.segments[1].demos[1].dmp;
  const auto& b = back.segments[1].demos[1].dmp;
  EXPECT_EQ(a.position->weights(), b.position->weights());  // bit-exact doubles
  EXPECT_EQ(a.orientation->weights(), b.orientation->weights());
  EXPECT_EQ(a.gripper->weights(), b.gripper->weights());
  // Same rollouts.
  lfd::SegmentRolloutOptions o;
  o.goal_position = Eigen::Vector3d(0.7, 0.05, 0.85);
  const auto ta = a.rollout(o);
  const auto tb = b.rollout(o);
  EXPECT_LT((ta.positions - tb.positions).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ta.quaternions - tb.quaternions).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ta.gripper - tb.gripper).cwiseAbs().maxCoeff(), 1e-12);
  std::remove(path.c_str());
}

TEST(SkillLibrary, ValidationNamesTheProblem) {
  const nlohmann::json good = lfd_dmp::toJson(makeLibrary());
  EXPECT_EQ(loadError(good), "");

  nlohmann::json j = good;
  j["version"] = 3;
  EXPECT_NE(loadError(j).find("unsupported version 3"), std::string::npos) << loadError(j);
  j["version"] = 1;  // goals were hand-written rules then: relearn, never guess
  EXPECT_NE(loadError(j).find("relearn"), std::string::npos) << loadError(j);

  j = good;
  j["segments"][0]["goal"]["position"]["frame"] = "table";
  EXPECT_NE(loadError(j).find("segments[0].goal.position.frame: unknown frame 'table'"),
            std::string::npos)
      << loadError(j);
  j = good;
  j["segments"][1]["goal"]["orientation"]["offset"] = {0, 0, 0, 0};
  EXPECT_NE(loadError(j).find("segments[1].goal.orientation.offset: quaternion has zero norm"),
            std::string::npos)
      << loadError(j);
  j = good;
  j["demo_scenes"][1]["objects"]["stick"]["position"][2] = 1e9;
  EXPECT_NE(loadError(j).find("demo_scenes[1].objects.stick.position"), std::string::npos)
      << loadError(j);
  j = good;  // a library without learned goals still loads (dmp_tool's); the executor refuses it
  j["segments"][0].erase("goal");
  j.erase("demo_scenes");
  EXPECT_EQ(loadError(j), "");

  j = good;
  j["format"] = "something_else";
  EXPECT_NE(loadError(j).find("format"), std::string::npos);

  j = good;
  j["segments"][0]["demos"][1]["dmp"]["position"]["weights"][1].erase(3);
  EXPECT_NE(loadError(j).find(
                "segments[0].demos[1].dmp.position.weights[1]: expected 50 numbers, got 49"),
            std::string::npos)
      << loadError(j);

  j = good;
  j["segments"][1]["demos"][0]["dmp"]["gripper"]["weights"][7] =
      std::numeric_limits<double>::quiet_NaN();  // serialized as null
  EXPECT_NE(loadError(j).find("segments[1].demos[0].dmp.gripper.weights[7]: expected a number"),
            std::string::npos)
      << loadError(j);

  // Regression: finite but huge numbers overflowed the rollout and crashed the executor's IK.
  j = good;
  j["segments"][0]["demos"][1]["dmp"]["position"]["weights"][2][5] = 1e300;
  EXPECT_NE(loadError(j).find("segments[0].demos[1].dmp.position.weights: weight 1e+300"),
            std::string::npos)
      << loadError(j);
  j = good;
  j["segments"][1]["demos"][0]["dmp"]["gripper"]["weights"][3] = -1e12;
  EXPECT_NE(loadError(j).find("gripper.weights: weight -1e+12"), std::string::npos) << loadError(j);
  j = good;
  j["segments"][0]["demos"][0]["dmp"]["position"]["goal"][0] = 1e300;
  EXPECT_NE(loadError(j).find("position.goal: position 1e+300"), std::string::npos) << loadError(j);

  j = good;
  j["segments"][0]["demos"][0]["dmp"].erase("tau");
  EXPECT_NE(loadError(j).find("missing field \"tau\""), std::string::npos);

  j = good;
  j["segments"][0]["demos"][0]["dmp"]["orientation"]["goal"] = {0, 0, 0, 0};
  EXPECT_NE(loadError(j).find("zero norm"), std::string::npos);

  j = good;
  j["segments"][0]["demos"][1]["dmp"].erase("orientation");
  EXPECT_NE(loadError(j).find("different parts"), std::string::npos);

  j = good;
  j["smoothing_sigma"] = -0.1;
  EXPECT_NE(loadError(j).find("smoothing_sigma: must be >= 0"), std::string::npos) << loadError(j);

  j = good;  // libraries written before the smoothing was recorded
  j.erase("smoothing_sigma");
  EXPECT_EQ(loadError(j), "");

  j = good;
  j["time_alignment"]["sample_seconds"] = 0.0;
  EXPECT_NE(loadError(j).find("time_alignment.sample_seconds: must be > 0"), std::string::npos)
      << loadError(j);
  j = good;
  j["time_alignment"]["yaw_invariant"] = 1;
  EXPECT_NE(loadError(j).find("time_alignment.yaw_invariant"), std::string::npos);
  j = good;  // learned as recorded: no alignment, no reference
  j.erase("time_alignment");
  j["segments"][0].erase("time_reference");
  EXPECT_EQ(loadError(j), "");

  j = good;
  j["dmp_parameters"]["num_basis"] = 1;
  EXPECT_NE(loadError(j).find("num_basis"), std::string::npos);

  j = good;
  j["segments"][0]["demos"][1]["parameters"] = {1.0, 2.0};
  EXPECT_NE(loadError(j).find("parameters: expected 3 numbers"), std::string::npos) << loadError(j);

  const std::string path = tempPath("notjson.json");
  std::ofstream(path) << "{ not json";
  try {
    lfd_dmp::loadSkillLibrary(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not valid JSON"), std::string::npos);
  }
  std::remove(path.c_str());
  EXPECT_THROW(lfd_dmp::loadSkillLibrary(tempPath("missing.json")), std::runtime_error);
}

}  // namespace

// catkin_add_gtest links gtest without gtest_main (and the static gtest_main archive is then simply
// not pulled in by the standalone build).
// Regression: a library whose tau is 1e-6 s (or 0.05 s where its demos took 9.8 s)
// "succeeded" in 0.1 s without moving. Durations, sizes and strings are checked on load; each
// refusal names the segment, the field and the limit's key. The valid library still loads.
TEST(SkillLibrary, ImplausibleDurationsAndSizesAreRefusedOnLoad) {
  const nlohmann::json good = lfd_dmp::toJson(makeLibrary());
  EXPECT_EQ(loadError(good), "");

  nlohmann::json j = good;
  j["segments"][1]["demos"][0]["dmp"]["tau"] = 1e-6;
  std::string error = loadError(j);
  EXPECT_NE(error.find("segments[1] 'move', demos[0] 'demo_0.bag'.dmp.tau: 1e-06 s outside"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("library_limits/min_tau"), std::string::npos) << error;

  j = good;  // a 9.8 s demonstration played in 0.5 s
  j["segments"][0]["demos"][1]["end_time"] = 9.8;
  j["segments"][0]["demos"][1]["start_time"] = 0.0;
  j["segments"][0]["demos"][1]["dmp"]["tau"] = 0.5;
  error = loadError(j);
  EXPECT_NE(error.find("segments[0] 'approach', demos[1] 'demo_1.bag'.dmp.tau: 0.5 s for a "
                       "demonstrated segment of 9.8 s"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("library_limits/max_tau_ratio"), std::string::npos) << error;

  j = good;
  j["segments"][0]["demos"][0]["dmp"]["tau"] = 1e6;
  EXPECT_NE(loadError(j).find("library_limits/min_tau, max_tau"), std::string::npos);

  j = good;  // sizes: segments, basis functions, strings
  for (int k = 0; k < 70; ++k) j["segments"].push_back(good["segments"][0]);
  EXPECT_NE(loadError(j).find("segments: 72 is over the limit of 64 (library_limits/max_segments)"),
            std::string::npos)
      << loadError(j);
  j = good;
  j["dmp_parameters"]["num_basis"] = 5000;
  EXPECT_NE(loadError(j).find("dmp_parameters.num_basis: over the limit of 1000"),
            std::string::npos)
      << loadError(j);
  j = good;
  j["segments"][0]["demos"][0]["demo_id"] = std::string(100000, 'x');
  error = loadError(j);
  EXPECT_NE(error.find("skill library.segments[0].demos[0].demo_id: a string of 100000 is over "
                       "the limit of 4096 (library_limits/max_string_length)"),
            std::string::npos)
      << error;
  EXPECT_LT(error.size(), 400u);
  j = good;
  j["features"] = nlohmann::json::array();
  for (int k = 0; k < 2000; ++k) j["features"].push_back("f");
  EXPECT_NE(loadError(j).find("library_limits/max_list_length"), std::string::npos);

  lfd_dmp::LibraryLimits tight;  // the file's size, before it is parsed
  tight.max_file_bytes = 1000;
  const std::string path = tempPath("big.json");
  std::ofstream(path) << good.dump();
  try {
    lfd_dmp::loadSkillLibrary(path, tight);
    ADD_FAILURE() << "a library over max_file_bytes loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("library_limits/max_file_bytes"), std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

// A signature of two segments and two channels, as the learner would store it.
lfd::SensorySignature makeSignature() {
  lfd::SensorySignature sig;
  sig.channels = {"/touch/values/0", "/wrist_ft/wrench/force/z"};
  sig.sources = {"/touch", "/wrist_ft"};
  sig.demonstrations = 5;
  sig.options.phase_bins = 4;
  for (int s = 0; s < 2; ++s) {
    lfd::SegmentSignature seg;
    seg.duration_mean = 1.5 + s;
    seg.duration_spread = 0.1;
    for (int c = 0; c < 2; ++c) {
      lfd::ChannelSignature ch;
      ch.mean = Eigen::Vector4d(0.0, 1.0 + s, 2.5, 0.25 * c);
      ch.spread = Eigen::Vector4d(0.1, 0.2, 0.3, 0.4);
      ch.threshold = 3.0 + c;
      ch.nominal_score = 1.25;
      ch.held = Eigen::Vector4d(0.0, 0.5 + s, 2.0, 0.0);
      seg.channels.push_back(ch);
    }
    sig.segments.push_back(seg);
  }
  sig.rest_bands = {0.25, 0.5};
  sig.options.rest_band_fraction = 0.05;
  return sig;
}

TEST(SkillLibrary, TheSensorySignatureTravelsWithTheLibrary) {
  SkillLibrary lib = makeLibrary();
  lib.sensory_signature = makeSignature();
  const std::string path = tempPath("sig.json");
  lfd_dmp::saveSkillLibrary(lib, path, false);
  const SkillLibrary back = lfd_dmp::loadSkillLibrary(path);
  std::remove(path.c_str());
  ASSERT_TRUE(back.sensory_signature.has_value());
  EXPECT_EQ(lfd_dmp::toJson(back), lfd_dmp::toJson(lib));
  EXPECT_EQ(back.sensory_signature->sources, lib.sensory_signature->sources);
  EXPECT_EQ(back.sensory_signature->segments[1].channels[1].mean,
            lib.sensory_signature->segments[1].channels[1].mean);
  EXPECT_EQ(back.sensory_signature->options.phase_bins, 4u);
  EXPECT_EQ(back.sensory_signature->rest_bands, lib.sensory_signature->rest_bands);
  EXPECT_EQ(back.sensory_signature->segments[1].channels[0].held,
            lib.sensory_signature->segments[1].channels[0].held);
}

// A library learned before the missing-contact check (no held levels, rest bands or option)
// loads with the check off: the levels alone judge its reproductions, as they did.
TEST(SkillLibrary, ASignatureWithoutRestBandsLoadsWithTheMissingContactCheckOff) {
  SkillLibrary lib = makeLibrary();
  lib.sensory_signature = makeSignature();
  nlohmann::json j = lfd_dmp::toJson(lib);
  auto& sig = j["sensory_signature"];
  sig.erase("rest_bands");
  sig["options"].erase("rest_band_fraction");
  for (auto& segment : sig["segments"])
    for (auto& channel : segment["channels"]) channel.erase("held");
  const std::string path = tempPath("old_sig.json");
  std::ofstream(path) << j.dump();
  const SkillLibrary back = lfd_dmp::loadSkillLibrary(path);
  std::remove(path.c_str());
  ASSERT_TRUE(back.sensory_signature.has_value());
  EXPECT_TRUE(back.sensory_signature->rest_bands.empty());
  EXPECT_EQ(back.sensory_signature->options.rest_band_fraction, 0.0);
  EXPECT_EQ(back.sensory_signature->segments[0].channels[1].held.size(), 0);
}

TEST(SkillLibrary, ABrokenSignatureIsRefusedWithItsLocation) {
  SkillLibrary lib = makeLibrary();
  lib.sensory_signature = makeSignature();
  const nlohmann::json good = lfd_dmp::toJson(lib);
  auto broken = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = good;
    edit(j);
    return loadError(j);
  };
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["segments"].erase(1);
            }).find("sensory_signature.segments"),
            std::string::npos);
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["segments"][0]["channels"][1]["spread"][2] = 0.0;
            }).find("segments[0].channels[1].spread"),
            std::string::npos);
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["segments"][1]["channels"][0]["mean"].erase(0);
            }).find("expected 4 numbers"),
            std::string::npos);
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["sources"].erase(0);
            }).find("one source per channel"),
            std::string::npos);
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["segments"][0]["channels"][0]["threshold"] = -1;
            }).find("threshold"),
            std::string::npos);
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["segments"][1]["channels"][1]["held"].erase(0);
            }).find("segments[1].channels[1].held"),
            std::string::npos);
  EXPECT_NE(
      broken([](auto& j) { j["sensory_signature"]["rest_bands"][1] = -0.5; }).find("rest_bands"),
      std::string::npos);
  EXPECT_NE(broken([](auto& j) {
              j["sensory_signature"]["rest_bands"].erase(0);
            }).find("one band per channel"),
            std::string::npos);
}
