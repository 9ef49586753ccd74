// Unit tests of the demonstration metadata (demo_metadata.hpp): what the demonstrator writes into
// /lfd/metadata's extra_json reads back equal, whatever the strings hold, in the documented schema.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "lfd_sim_bridge/demo_metadata.hpp"
#include "lfd_sim_bridge/task_file.hpp"

namespace demo = lfd_sim_bridge::demo;
namespace task = lfd_sim_bridge::task;

namespace {

const std::string kConfig = std::string(LFD_CONFIG_DIR) + "/";

task::Pose pose(double x, double y, double z, double qw, double qx, double qy, double qz) {
  task::Pose p;
  p.position = Eigen::Vector3d(x, y, z);
  p.orientation = Eigen::Quaterniond(qw, qx, qy, qz);
  return p;
}

void expectPose(const task::Pose& read, const task::Pose& written, const std::string& what) {
  EXPECT_EQ(read.position, written.position) << what;
  EXPECT_EQ(read.orientation.coeffs(), written.orientation.coeffs()) << what;
}

// Everything `m` holds, as read back from its JSON: exactly, numbers and strings alike.
void expectRoundTrip(const demo::DemoMetadata& m) {
  const std::string text = demo::metadataJson(m);
  const demo::MetadataRecord r = demo::readMetadataJson(text);
  const task::TaskDefinition& t = *m.task;
  const task::Configuration& c = *m.configuration;
  EXPECT_EQ(r.task, t.name);
  EXPECT_EQ(r.frame, "world");
  EXPECT_EQ(r.scene_frame, "world");
  ASSERT_EQ(r.objects.size(), t.objects.size()) << text;
  for (std::size_t i = 0; i < t.objects.size(); ++i) {
    EXPECT_EQ(r.objects[i].first, t.objects[i]);
    expectPose(r.objects[i].second, c.objects.at(t.objects[i]), t.objects[i]);
  }
  expectPose(r.scene_goal, c.goal, "scene.goal");
  const std::vector<std::string> joints = t.joints(*m.scene);
  ASSERT_EQ(r.joints.size(), joints.size()) << text;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    EXPECT_EQ(r.joints[i].first, joints[i]);
    const auto q = c.joints.find(joints[i]);
    EXPECT_EQ(r.joints[i].second, q == c.joints.end() ? 0.0 : q->second) << joints[i];
  }
  std::vector<std::string> phases, windows;
  for (const task::PhaseSpec& p : t.phases) {
    phases.push_back(p.name);
    if (p.window) windows.push_back(p.name);
  }
  EXPECT_EQ(r.phases, phases);
  EXPECT_EQ(r.windows, windows);
  EXPECT_EQ(r.object, t.objects.empty() ? "" : t.objects.front());
  EXPECT_EQ(r.has_object_start, !t.objects.empty());
  if (!t.objects.empty()) expectPose(r.object_start, c.objects.at(t.objects.front()), "start");
  expectPose(r.goal, c.goal, "goal");
  EXPECT_EQ(r.table_top, m.scene->table_top);
  EXPECT_EQ(r.seed, m.seed);
  EXPECT_EQ(r.speed, m.speed);
  ASSERT_EQ(r.aim.size(), m.aim_offsets.size());
  for (const auto& [name, offset] : m.aim_offsets) {
    ASSERT_EQ(r.aim.count(name), 1u) << name;
    EXPECT_EQ(r.aim.at(name).first, offset.first) << name;
    EXPECT_EQ(r.aim.at(name).second, offset.second) << name;
  }
  EXPECT_EQ(r.tremor_rms, m.tremor_rms);
  EXPECT_EQ(r.planned_duration, m.planned_duration);
  EXPECT_EQ(r.task_file, t.path);
}

TEST(DemoMetadata, OddStringsAndNumbersReadBackEqual) {
  task::Scene scene;
  scene.table_top = 0.8;
  task::SceneObject drawer;
  drawer.name = "dr\"awer\\";
  drawer.joints["sl\tide \xc3\xa9"] = {};  // "é"
  scene.objects.push_back(drawer);

  task::TaskDefinition t;
  t.name = "odd \"task\" \\ \n\r\t\b\f\x01\x1f\x7f \xc3\xa9 \xe2\x9c\x93 \xf0\x9f\xa4\x96";
  t.path = "/tmp/a \"b\"\\c/\xc3\xbc ber.yaml";
  t.objects = {"box \"1\"", "dr\"awer\\", std::string("nul\0byte", 8),
               "\x1f"
               "ctl",
               ""};
  task::PhaseSpec phase;
  phase.name = "re\"ach\\";
  t.phases.push_back(phase);
  phase.name = "gr\nasp \xe6\x8f\xa1";
  phase.window = true;
  t.phases.push_back(phase);

  task::Configuration c;
  double v = 0.1;
  for (const std::string& o : t.objects) {
    c.objects[o] = pose(v, 1.0 / 3.0, -1e-300, 0.5, 0.5, -0.5, 0.5);
    v *= -7.3;
  }
  c.goal = pose(-0.0, 123456.789, 2.5e-5, 0.9999999999999999, 0.0, 1e-17, 0.0);
  c.joints["sl\tide \xc3\xa9"] = 0.123456789012345678;

  demo::DemoMetadata m;
  m.task = &t;
  m.scene = &scene;
  m.configuration = &c;
  m.seed = -2147483647;
  m.speed = 1.0 / 3.0;
  m.tremor_rms = 5e-324;  // the smallest double
  m.planned_duration = 1.7976931348623157e308;
  m.aim_offsets["box \"1\""] = {Eigen::Vector3d(1, 2, 3), -1.0 / 7.0};
  m.aim_offsets
      ["\x1f"
       "ctl"] = {Eigen::Vector3d(-0.0, 1e-9, 0.1 + 0.2), M_PI};
  expectRoundTrip(m);

  // The text is plain JSON of the documented keys, in the documented order.
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(demo::metadataJson(m));
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"task", "frame", "scene", "phases", "windows", "object",
                                            "object_start", "goal", "table_top", "seed", "speed",
                                            "aim", "tremor_rms", "planned_duration", "task_file"}));
  keys.clear();
  for (const auto& item : j["scene"].items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"frame", "objects", "goal", "joints"}));
  EXPECT_TRUE(j["seed"].is_number_integer());
  EXPECT_EQ(j["task"].get<std::string>(), t.name);
}

TEST(DemoMetadata, ShippedTasksReadBackEqual) {
  const task::Scene scene = task::loadScene(kConfig + "scene.yaml");
  int checked = 0;
  for (const char* name : {"grasp", "push", "place", "wipe", "drawer"}) {
    const task::TaskDefinition t =
        task::loadTask(task::taskFilePath(kConfig + "tasks", name), scene);
    for (const auto& [mode, configurations] : t.configurations)
      for (const task::Configuration& c : configurations) {
        demo::DemoMetadata m;
        m.task = &t;
        m.scene = &scene;
        m.configuration = &c;
        m.seed = c.id;
        m.speed = 0.8 + 0.01 * c.id;
        m.tremor_rms = mode == "teleop" ? 0.0015 : 0.0;
        m.planned_duration = 9.87654321;
        for (const std::string& o : t.objects)
          m.aim_offsets[o] = {Eigen::Vector3d(0.001, -0.002, 0), 0.03};
        SCOPED_TRACE(std::string(name) + " " + mode + " " + std::to_string(c.id));
        expectRoundTrip(m);
        ++checked;
      }
  }
  EXPECT_GT(checked, 20);
}

TEST(DemoMetadata, WithoutObjectsThereIsNoObjectStart) {
  const task::Scene scene = task::loadScene(kConfig + "scene.yaml");
  const task::TaskDefinition wipe = task::loadTask(kConfig + "tasks/wipe.yaml", scene);
  ASSERT_TRUE(wipe.objects.empty());
  demo::DemoMetadata m;
  m.task = &wipe;
  m.scene = &scene;
  m.configuration = &wipe.configurations.at("sim").front();
  const nlohmann::json j = nlohmann::json::parse(demo::metadataJson(m));
  EXPECT_EQ(j["object"], "");
  EXPECT_FALSE(j.contains("object_start"));
  EXPECT_TRUE(j["scene"]["objects"].is_object());
  EXPECT_TRUE(j["aim"].is_object());
}

TEST(DemoMetadata, MalformedTextIsRefusedNamingWhat) {
  EXPECT_THROW(demo::readMetadataJson("{not json"), std::runtime_error);
  EXPECT_THROW(demo::readMetadataJson("{}"), std::runtime_error);
  try {
    demo::readMetadataJson(R"({"task": "t", "frame": "world", "scene": {"frame": "world",
        "objects": {"box": {"position": [1, 2], "orientation": [1, 0, 0, 0]}}}})");
    FAIL() << "a two-number position was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.objects.box"), std::string::npos) << e.what();
  }
  demo::DemoMetadata none;
  EXPECT_THROW(demo::metadataJson(none), std::invalid_argument);
}

TEST(DemoMetadata, StringLiterals) {
  EXPECT_EQ(demo::jsonString("plain"), "\"plain\"");
  EXPECT_EQ(demo::jsonString("q\"b\\"), "\"q\\\"b\\\\\"");
  EXPECT_EQ(nlohmann::json::parse(demo::jsonString("a\nb\t\x01 \xc3\xa9")), "a\nb\t\x01 \xc3\xa9");
  // A byte that is not UTF-8 cannot be in JSON text: it becomes U+FFFD rather than an error.
  EXPECT_EQ(nlohmann::json::parse(demo::jsonString("bad \xff byte")), "bad \xef\xbf\xbd byte");
}

}  // namespace
