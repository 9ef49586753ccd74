// The configuration files that name the robot's topics agree with its robot file: the recorder
// records the sensor table's rows (named there only) at the rate the bridge publishes them, and
// every topic the segmentation reads is recorded, its gripper field reading any robot's gripper
// joint. A robot file whose table renames a topic the segmentation reads fails here,
// before a dataset is recorded without it.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <string>

#include "lfd_core/kinematics/robot_setup.hpp"

namespace {

const std::string kConfig = std::string(LFD_CONFIG_DIR) + "/";

// What the recorder records (recorder_node): recorder.yaml's topics and the sensor table's rows
// at sensor_rate; topic -> rate.
std::map<std::string, double> recordedTopics() {
  const YAML::Node config = YAML::LoadFile(kConfig + "recorder.yaml");
  std::map<std::string, double> topics;
  for (const YAML::Node& t : config["topics"])
    topics[t["name"].as<std::string>()] = t["rate"].as<double>();
  for (const lfd::SensorEntry& row : lfd::loadRobotSetup(LFD_ROBOT_FILE).sensors)
    topics[row.topic] = config["sensor_rate"].as<double>();
  return topics;
}

TEST(ConfigAgreement, SensorRowsAreRecordedOnceAtThePublishRate) {
  const YAML::Node recorder = YAML::LoadFile(kConfig + "recorder.yaml");
  const double publish_rate = YAML::LoadFile(kConfig + "bridge.yaml")["publish_rate"].as<double>();
  EXPECT_EQ(recorder["sensor_rate"].as<double>(), publish_rate);
  const lfd::RobotSetup robot = lfd::loadRobotSetup(LFD_ROBOT_FILE);
  ASSERT_FALSE(robot.sensors.empty());
  for (const YAML::Node& t : recorder["topics"])
    for (const lfd::SensorEntry& row : robot.sensors)
      EXPECT_NE(t["name"].as<std::string>(), row.topic) << "named in recorder.yaml and robot.yaml";
}

TEST(ConfigAgreement, TheSegmentationReadsRecordedTopicsAndTheRobotsGripper) {
  const std::map<std::string, double> recorded = recordedTopics();
  const YAML::Node topics = YAML::LoadFile(kConfig + "segmentation.yaml")["topics"];
  ASSERT_TRUE(topics && topics.size() > 0);
  bool gripper_seen = false;
  for (const YAML::Node& t : topics) {
    const std::string topic = t["topic"].as<std::string>();
    EXPECT_TRUE(recorded.count(topic)) << "segmentation.yaml reads " << topic << ", not recorded";
    if (topic != "/gripper/state") continue;
    gripper_seen = true;
    // Any robot's gripper: the gripper state names one joint, read whatever its name.
    for (const YAML::Node& field : t["fields"]) EXPECT_EQ(field.as<std::string>(), "position/*");
  }
  EXPECT_TRUE(gripper_seen);
}

}  // namespace
