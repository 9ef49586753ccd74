// Unit tests of the task and scene files (task_file.hpp): the shipped files load and follow the
// protocol's counts, and every malformed file is refused with an error naming the file and the key.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include "lfd_sim_bridge/task_file.hpp"

namespace task = lfd_sim_bridge::task;

namespace {

const std::string kConfig = std::string(LFD_CONFIG_DIR) + "/";
const char* const kTasks[] = {"grasp", "push", "place", "wipe", "drawer"};

task::Scene scene() {
  return task::loadScene(kConfig + "scene.yaml");
}

// A valid small task; tests replace one part of it.
std::string validTask(const std::string& phases = "", const std::string& extra = "") {
  const std::string default_phases = R"(
phases:
  - name: approach
    steps:
      - {gripper: open, duration: 0.5}
      - {move: {frame: stick, position: [0, 0, 0.1], symmetry: 2}, duration: 2.0}
  - name: grasp
    window: true
    steps:
      - {gripper: close, until_contact: both, duration: 1.0, settle: 0.3}
  - name: move
    steps:
      - {carry: stick, to: {frame: goal}, duration: 2.0}
)";
  return "objects: [stick]\n" + extra + (phases.empty() ? default_phases : phases) + R"(
success:
  - {rule: object_at_goal, object: stick, distance: xyz, tolerance_m: 0.03}
configurations:
  sim:
    - {id: 0, stick: [0.5, -0.3, 0.815, 0.1], goal: [0.5, -0.2, 0.95, 0.1]}
  teleop:
    - {id: 0, stick: [0.5, -0.3, 0.815, 0.1], goal: [0.5, -0.2, 0.95, 0.1]}
)";
}

std::string write(const std::string& content, const std::string& name = "mytask") {
  const std::string path = testing::TempDir() + name + ".yaml";
  std::ofstream(path) << content;
  return path;
}

// The load fails with a message naming the file and containing `says`.
void expectRefused(const std::string& content, const std::string& says) {
  const std::string path = write(content);
  try {
    task::loadTask(path, scene());
    ADD_FAILURE() << "accepted a task file that should say: " << says;
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(says), std::string::npos) << what;
  }
}

}  // namespace

TEST(TaskFile, ShippedTasksLoadWithTheProtocolsCounts) {
  const task::Scene s = scene();
  for (const char* name : kTasks) {
    const task::TaskDefinition t = task::loadTask(task::taskFilePath(kConfig + "tasks", name), s);
    EXPECT_EQ(t.name, name);
    EXPECT_GE(t.configurations.at("sim").size(), 9u) << name;
    EXPECT_GE(t.configurations.at("teleop").size(), 6u) << name;
    EXPECT_EQ(t.unseen.at("sim").size(), 10u) << name;
    EXPECT_EQ(t.unseen.at("teleop").size(), 10u) << name;
    EXPECT_FALSE(t.phases.front().window);
    EXPECT_FALSE(t.phases.back().window);
  }
  const task::TaskDefinition drawer = task::loadTask(kConfig + "tasks/drawer.yaml", s);
  EXPECT_EQ(drawer.joints(s), std::vector<std::string>{"drawer_slide"});
  EXPECT_TRUE(task::loadTask(kConfig + "tasks/wipe.yaml", s).objects.empty());
}

TEST(TaskFile, SceneHoldsTheWorkcellsObjects) {
  const task::Scene s = scene();
  EXPECT_DOUBLE_EQ(s.table_top, 0.80);
  ASSERT_NE(s.find("drawer"), nullptr);
  EXPECT_TRUE(s.find("drawer")->fixed);
  EXPECT_EQ(s.find("drawer")->frames.at("handle").joint, "drawer_slide");
  EXPECT_EQ(s.find("drawer")->frames.at("handle").body, "drawer_handle");
  EXPECT_NEAR(s.find("box")->half_size.x(), 0.04, 1e-12);
  EXPECT_EQ(s.find("mug"), nullptr);
}

TEST(TaskFile, AValidFileLoads) {
  const task::TaskDefinition t = task::loadTask(write(validTask()), scene());
  EXPECT_EQ(t.name, "mytask");
  ASSERT_EQ(t.phases.size(), 3u);
  EXPECT_TRUE(t.phases[1].window);
  EXPECT_EQ(t.phases[1].steps[0].until_contact, task::Contact::kBoth);
  EXPECT_EQ(t.phases[0].steps[1].target.symmetry, 2);
  EXPECT_TRUE(t.unseen.at("sim").empty());  // optional
}

TEST(TaskFile, MalformedFilesAreRefusedNamingTheKey) {
  expectRefused("objects: [stick]\nphases: [}", "cannot be read");
  expectRefused(validTask("", "speed: 2\n"), "unknown key 'speed'");
  expectRefused(validTask("", "variation: {mug: {x: 0.1}}\n"), "variation.mug");
  expectRefused("objects: [mug]\n", "objects[0]: 'mug' is not an object of the scene file");
  const std::string missing_success = validTask();
  expectRefused(missing_success.substr(0, missing_success.find("success:")), "success: missing");
  // One phase with the given steps.
  const std::pair<const char*, const char*> bad_steps[] = {
      {"{teleport: {frame: goal}, duration: 1}",
       "phases[0].steps[0]: expected exactly one primitive"},
      {"{move: {frame: goal}, hold: 1, duration: 1}",
       "phases[0].steps[0]: expected exactly one primitive"},
      {"{move: {frame: teapot}, duration: 1}",
       "phases[0].steps[0].move.frame: unknown frame 'teapot'"},
      {"{move: {frame: goal}, duration: -1}", "phases[0].steps[0].duration: must be > 0"},
      {"{move: {frame: goal}, duration: 1, until_contact: any}, {hold: 1}",
       "phases[0].steps[0].until_contact: a step that waits for contact ends its phase"},
      {"{carry: stick, to: {frame: goal}, duration: 1}",
       "phases[0].steps[0]: carry before any gripper close"},
      {"{gripper: open, until_contact: both, duration: 1}", "only a close waits for contact"},
  };
  for (const auto& [steps, says] : bad_steps)
    expectRefused(
        validTask(std::string("phases:\n  - name: approach\n    steps: [") + steps + "]\n"), says);
  expectRefused(
      validTask("phases:\n  - name: approach\n    window: true\n    steps: [{hold: 1}]\n"),
      "the first and the last phase are skills");
  expectRefused(validTask("phases:\n  - name: approach\n    steps: [{hold: 1}]\n"
                          "  - name: approach\n    steps: [{hold: 1}]\n"),
                "phases[1].name: 'approach' repeats");
  expectRefused(validTask("", "frames:\n  here: {frame: tcp}\n"),
                "frames.here.frame: a frame is fixed");
}

TEST(TaskFile, BadConfigurationsAreRefusedNamingTheEntry) {
  std::string t = validTask();
  const std::string sim_entry =
      "    - {id: 0, stick: [0.5, -0.3, 0.815, 0.1], goal: [0.5, -0.2, 0.95, 0.1]}\n  teleop:";
  const auto with_sim = [&](const std::string& entries) {
    std::string out = t;
    out.replace(out.find(sim_entry), sim_entry.size(), entries + "\n  teleop:");
    return out;
  };
  expectRefused(with_sim("    - {id: 0, goal: [0.5, -0.2, 0.95]}"), "configurations.sim[0].stick");
  expectRefused(with_sim("    - {id: 0, stick: [0.5, -0.3], goal: [0.5, -0.2, 0.95]}"),
                "configurations.sim[0].stick");
  expectRefused(with_sim("    - {id: 0, stick: [0.5, -0.3, x], goal: [0.5, -0.2, 0.95]}"),
                "'x' is not a number");
  expectRefused(
      with_sim("    - {id: 0, stick: [0.5, -0.3, 0.8], goal: [0.5, -0.2, 0.95], box: [0, 0, 0]}"),
      "unknown key 'box'");
  expectRefused(
      with_sim("    - {id: 0, stick: [0.5, -0.3, 0.8], goal: [0.5, -0.2, 0.95], joints: {lid: 1}}"),
      "configurations.sim[0].joints.lid: not a joint");
  expectRefused(with_sim("    - {id: 3, stick: [0.5, -0.3, 0.8], goal: [0.5, -0.2, 0.9]}\n"
                         "    - {id: 3, stick: [0.5, -0.3, 0.8], goal: [0.5, -0.2, 0.9]}"),
                "id 3 repeats");
  expectRefused(with_sim("    []"), "configurations.sim");
}

TEST(TaskFile, BadSceneFilesAreRefusedNamingTheKey) {
  const std::string path = write("table_top: 0.8\nbase_link_in_world: [0, 0]\n", "scene");
  try {
    task::loadScene(path);
    ADD_FAILURE() << "accepted a scene without a proper base_link_in_world";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("base_link_in_world"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(task::loadScene("/nonexistent/scene.yaml"), std::runtime_error);
}

// Regression: the bounds of the scene's task_limits (max_step_seconds 120,
// max_nesting_depth 16), which lfd_tools.tasks reads too.
TEST(TaskFile, TimesOverTheScenesBoundAreRefused) {
  const std::string over = "is over 120";
  auto replaced = [](std::string text, const std::string& from, const std::string& to) {
    return text.replace(text.find(from), from.size(), to);
  };
  expectRefused(replaced(validTask(), "duration: 2.0}", "duration: 1.0e+9}"), over);
  expectRefused(replaced(validTask(), "settle: 0.3", "settle: 1.0e+9"), over);
  expectRefused(replaced(validTask(), "{gripper: open, duration: 0.5}", "{hold: 1.0e+9}"), over);
  expectRefused(replaced(validTask(), "{gripper: open, duration: 0.5}", "{release: 121}"), over);
  expectRefused(replaced(validTask(), "{gripper: open, duration: 0.5}", "{hold: -1}"),
                "must be >= 0 s");
  EXPECT_NO_THROW(
      task::loadTask(write(replaced(validTask(), "duration: 2.0}", "duration: 120}")), scene()));
}

TEST(TaskFile, NumbersThatAreNotFiniteOrWholeAreRefused) {
  auto with_stick = [](const std::string& stick) {
    std::string text = validTask();
    const std::string from = "stick: [0.5, -0.3, 0.815, 0.1]";
    return text.replace(text.find(from), from.size(), "stick: " + stick);
  };
  expectRefused(with_stick("[0.5, .nan, 0.815, 0.1]"),
                "configurations.sim[0].stick[1]: is not finite");
  expectRefused(with_stick("[0.5, -.inf, 0.815, 0.1]"), "is not finite");
  expectRefused(with_stick("[0.5, 1e999, 0.815, 0.1]"), "configurations.sim[0].stick[1]");
  std::string text = validTask();
  text.replace(text.find("{id: 0"), 6, "{id: 1.0e+300");
  expectRefused(text, "configurations.sim[0].id: expected a whole number >= 0");
}

TEST(TaskFile, DeepNestingIsRefusedBeforeItIsRead) {
  for (int depth : {17, 1000, 100000}) {
    const std::string nest = std::string(depth, '[') + std::string(depth, ']');
    expectRefused("description: " + nest + "\n" + validTask(), "nested deeper than 16 levels");
  }
  EXPECT_NO_THROW(task::loadTask(
      write("description: " + std::string(15, '[') + std::string(15, ']') + "\n" + validTask()),
      scene()));
}

TEST(TaskFile, BytesThatAreNotPrintableTextAreRefused) {
  expectRefused("description: \xff\n" + validTask(), "line 1 is not UTF-8 text");
  expectRefused("description: \xc3\x28\n" + validTask(), "not UTF-8 text");
  expectRefused(validTask() + "# \xe2\x82", "not UTF-8 text");  // cut off in a character
  expectRefused("description: a" + std::string(1, '\0') + "b\n" + validTask(), "not printable");
  expectRefused("description: \x7f\n" + validTask(), "not printable");
  EXPECT_NO_THROW(task::loadTask(write("\xef\xbb\xbf" + validTask()), scene()));  // a BOM
  EXPECT_NO_THROW(task::loadTask(write("description: caf\xc3\xa9\n" + validTask()), scene()));
}

TEST(TaskFile, KeysGivenTwiceAndTagsAreRefused) {
  expectRefused("objects: [stick]\n" + validTask(), "key 'objects' given twice");
  expectRefused("description: !foo bar\n" + validTask(), "tag '!foo'");
  expectRefused("? [a, b]\n: 1\n" + validTask(), "a key must be a plain value");
}

TEST(TaskFile, ASceneWithoutTaskLimitsIsRefused) {
  std::ifstream in(kConfig + "scene.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("task_limits:"), 12, "task_limitz:");
  const std::string path = write(text, "scene");
  try {
    task::loadScene(path);
    ADD_FAILURE() << "accepted a scene without task_limits";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("task_limits"), std::string::npos) << e.what();
  }
}
