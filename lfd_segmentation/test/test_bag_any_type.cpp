// Bags of message types this build has never seen: written raw with topic_tools::ShapeShifter
// (definition + bytes only), read back by path through the definitions stored in the bag.
#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <topic_tools/shape_shifter.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "lfd_segmentation/bag_features.hpp"
#include "ros_serialized_bytes.hpp"

namespace {

namespace fs = std::filesystem;
using lfd_segmentation::FeatureRole;
using lfd_segmentation::TopicConfig;

// A controller state in the style of pr2_controllers_msgs/JointTrajectoryControllerState, with the
// dependency types written with and without their package.
const char* const kArmDefinition = R"(Header header
string[] joint_names
Point actual
robot_pkg/Point error
float32 gripper
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
================================================================================
MSG: robot_pkg/Point
float64[] positions
duration time_from_start
)";

// A world model whose stamps are all zero (as the PR2's /ar_world_model): the receive time counts.
const char* const kWorldDefinition = R"(Object[] objects
================================================================================
MSG: robot_pkg/Object
Header header
string id
bool visible
float64[3] position
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
)";

void writeRaw(rosbag::Bag& bag, const std::string& topic, const std::string& type,
              const std::string& definition, double t, Bytes bytes) {
  topic_tools::ShapeShifter shape;
  shape.morph("0123456789abcdef0123456789abcdef", type, definition, "");
  ros::serialization::IStream in(bytes.data.data(), static_cast<std::uint32_t>(bytes.data.size()));
  shape.read(in);
  bag.write(topic, ros::Time(t), shape);
}

Bytes armMessage(double t, double q0, double q1) {
  Bytes b;
  const auto sec = static_cast<std::uint32_t>(t);
  b.header(sec, static_cast<std::uint32_t>(std::lround((t - sec) * 1e9)));
  b.put<std::uint32_t>(2).str("j0").str("j1");
  b.put<std::uint32_t>(2).put(q0).put(q1).put<std::int32_t>(0).put<std::int32_t>(0);
  b.put<std::uint32_t>(2).put(-0.1 * q0).put(-0.1 * q1).put<std::int32_t>(0).put<std::int32_t>(0);
  b.put<float>(0.08f);
  return b;
}

Bytes worldMessage(double x) {
  Bytes b;
  b.put<std::uint32_t>(1);
  b.header(0, 0).str("leg").put<std::uint8_t>(1).put(x).put(0.2).put(0.3);
  return b;
}

// One part: 100 Hz arm states stamped 20 ms before they were received, 20 Hz world models.
void writePart(const std::string& path, double start, double duration) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (long i = 0; i < std::lround(duration * 100); ++i) {
    const double t = start + i * 0.01;
    writeRaw(bag, "/arm/state", "robot_pkg/ArmState", kArmDefinition, t + 0.02,
             armMessage(t, 1.0 + t - 100, 2.0));
    if (i % 5 == 0)
      writeRaw(bag, "/world", "robot_pkg/World", kWorldDefinition, t, worldMessage(t - 100));
  }
  bag.close();
}

class BagAnyType : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("lfd_any_type_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    writePart(part(1), 100.0, 2.0);
    writePart(part(2), 102.7, 1.0);  // 0.7 s unrecorded between the parts
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string part(int k) { return (dir_ / ("part" + std::to_string(k) + ".bag")).string(); }
  static fs::path dir_;
};
fs::path BagAnyType::dir_;

const lfd::Stream& stream(const std::vector<lfd::Stream>& streams, const std::string& name) {
  for (const lfd::Stream& s : streams)
    if (s.name == name) return s;
  throw std::runtime_error("no stream " + name);
}

TEST_F(BagAnyType, ReadsFieldsOfUnknownTypesByPath) {
  const std::vector<TopicConfig> topics{
      {"/arm/state", FeatureRole::kState, {"actual/positions/j0", "actual/positions/1", "gripper"}},
      {"/arm/state", FeatureRole::kSensor, {"error/positions/*"}},
      {"/world", FeatureRole::kState, {"objects/0/position/0", "objects/*/visible"}}};
  std::vector<FeatureRole> roles;
  const auto streams = lfd_segmentation::readBagStreams(part(1), topics, &roles);
  ASSERT_EQ(streams.size(), 7u);
  EXPECT_EQ(streams[3].name, "/arm/state/error/positions/j0");  // "*" expanded by joint name
  EXPECT_EQ(roles[3], FeatureRole::kSensor);
  const lfd::Stream& q0 = stream(streams, "/arm/state/actual/positions/j0");
  ASSERT_EQ(q0.time.size(), 200u);
  EXPECT_NEAR(q0.time[10], 100.1, 1e-9);  // the header stamp, not the receive time (+20 ms)
  EXPECT_NEAR(q0.values[10], 1.1, 1e-9);
  EXPECT_DOUBLE_EQ(stream(streams, "/arm/state/actual/positions/1").values[5], 2.0);
  EXPECT_DOUBLE_EQ(stream(streams, "/arm/state/gripper").values[0], double(0.08f));
  EXPECT_NEAR(stream(streams, "/arm/state/error/positions/j1").values[0], -0.2, 1e-12);
  const lfd::Stream& x = stream(streams, "/world/objects/0/position/0");
  ASSERT_EQ(x.time.size(), 40u);
  EXPECT_NEAR(x.time[3], 100.15, 1e-9);  // zero stamps: the receive time
  EXPECT_NEAR(x.values[3], 0.15, 1e-9);
  EXPECT_DOUBLE_EQ(stream(streams, "/world/objects/0/visible").values[0], 1.0);
}

TEST_F(BagAnyType, UnknownFieldListsTheTopicsFields) {
  try {
    lfd_segmentation::readBagStreams(
        part(1), {{"/arm/state", FeatureRole::kState, {"actual/velocities/0"}}});
    FAIL() << "unknown field accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no field 'actual/velocities/0'"), std::string::npos) << what;
    EXPECT_NE(what.find("(it has positions, time_from_start)"), std::string::npos) << what;
    EXPECT_NE(what.find("actual/positions/<0..1> or <name: j0, j1>"), std::string::npos) << what;
    EXPECT_NE(what.find("\n  header/stamp"), std::string::npos) << what;
  }
  try {
    lfd_segmentation::readBagStreams(part(1),
                                     {{"/world", FeatureRole::kState, {"objects/3/position/0"}}});
    FAIL() << "a field no message carries was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no data for field 'objects/3/position/0'"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("objects/<0..0>/position/<0..2>"), std::string::npos)
        << e.what();
  }
  const std::string listing = lfd_segmentation::describeBag(part(1));
  EXPECT_NE(listing.find("/world (robot_pkg/World, 40 messages)"), std::string::npos) << listing;
  EXPECT_NE(listing.find("gripper"), std::string::npos) << listing;
}

TEST_F(BagAnyType, PartsInOrderMakeOneDemonstrationWithTheirGaps) {
  const std::vector<TopicConfig> topics{
      {"/arm/state", FeatureRole::kState, {"actual/positions/0"}}};
  const auto demo = lfd_segmentation::readBagFeatures(part(1) + "," + part(2), topics, 50.0);
  const lfd::FeatureMatrix& m = demo.matrix;
  EXPECT_NEAR(m.time.front(), 100.0, 1e-9);
  EXPECT_NEAR(m.time.back(), 103.68, 0.011);  // the span of both parts, gap included
  // Across the gap the signal is interpolated between the parts' own values.
  const auto row = static_cast<Eigen::Index>(std::lround((102.3 - 100.0) * 50));
  EXPECT_NEAR(m.data(row, 0), 1.0 + 2.3, 1e-6);
  EXPECT_THROW(
      lfd_segmentation::readBagFeatures(part(1) + "," + (dir_ / "nope.bag").string(), topics, 50.0),
      std::runtime_error);
}

TEST_F(BagAnyType, MessagesThatDoNotMatchTheirDefinitionAreErrors) {
  const std::string bad = (dir_ / "bad.bag").string();
  {
    rosbag::Bag bag(bad, rosbag::bagmode::Write);
    Bytes b = armMessage(1.0, 0.0, 0.0);
    b.data.resize(b.data.size() - 3);  // the float32 gripper cut short
    writeRaw(bag, "/arm/state", "robot_pkg/ArmState", kArmDefinition, 1.0, b);
  }
  const std::vector<TopicConfig> topics{{"/arm/state", FeatureRole::kState, {"gripper"}}};
  try {
    lfd_segmentation::readBagStreams(bad, topics);
    FAIL() << "truncated message accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("field 'gripper' of robot_pkg/ArmState"),
              std::string::npos)
        << e.what();
  }
  const std::string broken = (dir_ / "broken_definition.bag").string();
  {
    rosbag::Bag bag(broken, rosbag::bagmode::Write);
    writeRaw(bag, "/arm/state", "robot_pkg/ArmState", "Point actual\n", 1.0,
             armMessage(1.0, 0.0, 0.0));
  }
  try {
    lfd_segmentation::readBagStreams(broken, topics);
    FAIL() << "definition without its dependencies accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("robot_pkg/Point"), std::string::npos) << e.what();
  }
}

std::string run(const std::string& command, int* status) {
  std::string out;
  FILE* pipe = popen((command + " 2>/dev/null").c_str(), "r");
  char chunk[4096];
  while (std::size_t n = std::fread(chunk, 1, sizeof(chunk), pipe)) out.append(chunk, n);
  *status = WEXITSTATUS(pclose(pipe));
  return out;
}

// The CLI takes another robot's topics from a file (--topics) and lists a bag's fields.
TEST_F(BagAnyType, CliListsFieldsAndTakesTopicsFromAFile) {
  int status = -1;
  const std::string listing = run(std::string(SEGMENT_CLI) + " --list-fields " + part(1), &status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(listing.find("/arm/state (robot_pkg/ArmState, 200 messages)"), std::string::npos)
      << listing;
  EXPECT_NE(listing.find("  actual/positions/<0..1> or <name: j0, j1>\n"), std::string::npos)
      << listing;
  const std::string topics = (dir_ / "topics.yaml").string();
  std::ofstream(topics) << "topics:\n  - topic: /arm/state\n    fields: [actual/velocities/0]\n";
  const std::string out = (dir_ / "out.json").string();
  run(std::string(SEGMENT_CLI) + " --topics " + topics + " --output " + out + " " + part(1) + "," +
          part(2) + " " + part(1),
      &status);
  EXPECT_EQ(status, 1);
  std::ifstream in(out);
  const nlohmann::json json = nlohmann::json::parse(in);
  EXPECT_FALSE(json["success"].get<bool>());
  const std::string error = json["error"];
  EXPECT_NE(error.find("no field 'actual/velocities/0'"), std::string::npos) << error;
  EXPECT_NE(error.find("\n  gripper"), std::string::npos) << error;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
