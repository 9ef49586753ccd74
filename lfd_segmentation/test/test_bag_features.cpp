#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "demo_bag_writer.hpp"
#include "lfd_segmentation/bag_features.hpp"
#include "link_swap_race.hpp"

namespace {

namespace fs = std::filesystem;
using lfd_segmentation::FeatureRole;
using lfd_segmentation::TopicConfig;

fs::path tempDir() {
  const fs::path dir = fs::temp_directory_path() / ("lfd_seg_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

std::vector<TopicConfig> defaultTopics() {
  return lfd_segmentation::loadParamsFile(std::string(LFD_CONFIG_DIR) + "/segmentation.yaml")
      .topics;
}

TEST(BagFeatures, ReadsConfiguredFieldsOnOneClock) {
  const std::string bag = (tempDir() / "good.bag").string();
  lfd_segmentation_test::DemoBagOptions o;
  lfd_segmentation_test::writeDemoBag(bag, o);
  const auto demo = lfd_segmentation::readBagFeatures(bag, defaultTopics(), 50.0);
  const lfd::FeatureMatrix& m = demo.matrix;
  EXPECT_GE(m.indexOf("/ee_twist/twist/linear/x"), 0);
  EXPECT_GE(m.indexOf("/ee_pose/pose/orientation/w"), 0);
  EXPECT_GE(m.indexOf("/gripper/state/position/R_GRIPPER"), 0);
  EXPECT_GE(m.indexOf("/touch/values/r_touch_left"), 0);  // values/* expanded
  EXPECT_GE(m.indexOf("/touch/values/r_touch_right"), 0);
  EXPECT_GE(m.indexOf("/wrist_ft/wrench/force/z"), 0);
  for (const std::string& name : m.names) EXPECT_EQ(name.find("/lfd/phase"), std::string::npos);
  EXPECT_EQ(demo.state_features.size(), 16u);  // 7 pose, 6 twist + 2 speed norms, gripper
  EXPECT_GE(m.indexOf("/ee_twist/twist/linear/norm"), 0);
  EXPECT_EQ(demo.sensor_features.size(), 2u);   // the touch pads
  EXPECT_EQ(demo.context_features.size(), 6u);  // the wrist F/T: read, used by neither
  EXPECT_EQ(demo.state_features.size() + demo.sensor_features.size() + demo.context_features.size(),
            std::size_t(m.cols()));
  // 50 Hz over the common span of 100 Hz and 50 Hz streams (~7.98 s).
  ASSERT_GT(m.rows(), 390);
  EXPECT_LT(m.rows(), 402);
  EXPECT_NEAR(m.time[1] - m.time[0], 0.02, 1e-9);
  EXPECT_NEAR(m.time[0], o.start_time, 1e-6);
  const int gripper = m.require("/gripper/state/position/R_GRIPPER");
  EXPECT_NEAR(m.data(10, gripper), 0.08, 0.005);
  EXPECT_NEAR(m.data(m.rows() - 10, gripper), 0.02, 0.005);
  const int touch = m.require("/touch/values/r_touch_left");
  EXPECT_NEAR(m.data(10, touch), 0.0, 0.2);
  EXPECT_NEAR(m.data(m.rows() - 10, touch), 4.0, 0.2);
}

TEST(BagFeatures, ZeroOrderHoldKeepsDiscreteValues) {
  const std::string bag = (tempDir() / "zoh.bag").string();
  lfd_segmentation_test::writeDemoBag(bag);
  std::vector<TopicConfig> topics{{"/gripper/state",
                                   FeatureRole::kState,
                                   {"effort/R_GRIPPER"},
                                   lfd::Interpolation::kZeroOrderHold}};
  const auto demo = lfd_segmentation::readBagFeatures(bag, topics, 33.0);
  for (Eigen::Index r = 0; r < demo.matrix.rows(); ++r) {
    const double v = demo.matrix.data(r, 0);
    EXPECT_TRUE(v == 0.0 || v == 5.0) << v;
  }
}

void expectInvalid(const std::string& bag, const std::vector<TopicConfig>& topics,
                   const std::string& needle) {
  try {
    lfd_segmentation::readBagFeatures(bag, topics, 50.0);
    FAIL() << "expected an error mentioning " << needle;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(BagFeatures, MissingTopicOrFieldIsAClearError) {
  const std::string bag = (tempDir() / "missing.bag").string();
  lfd_segmentation_test::DemoBagOptions o;
  o.with_touch = false;
  lfd_segmentation_test::writeDemoBag(bag, o);
  expectInvalid(bag, defaultTopics(), "no messages on topic /touch");
  expectInvalid(bag, {{"/ee_twist", FeatureRole::kState, {"twist/linear/w"}}},
                "no field 'twist/linear/w'");
  expectInvalid(bag, {{"/gripper/state", FeatureRole::kState, {"position/L_GRIPPER"}}},
                "no data for field 'position/L_GRIPPER'");
  expectInvalid(bag, {{"/gripper/state", FeatureRole::kState, {"speed/R_GRIPPER"}}},
                "no field 'speed/R_GRIPPER'");
  expectInvalid(bag, {{"/lfd/phase", FeatureRole::kState, {"index"}}}, "ground truth");
}

TEST(BagFeatures, NaNSampleIsReportedWithItsFeature) {
  const std::string bag = (tempDir() / "nan.bag").string();
  lfd_segmentation_test::DemoBagOptions o;
  o.nan_in_twist = true;
  lfd_segmentation_test::writeDemoBag(bag, o);
  expectInvalid(bag, defaultTopics(), "/ee_twist/twist/linear/x");
}

TEST(BagFeatures, UnreadableOrTruncatedBagIsARuntimeError) {
  EXPECT_THROW(lfd_segmentation::readBagFeatures("/nonexistent/demo.bag", defaultTopics(), 50),
               std::runtime_error);
  const std::string bag = (tempDir() / "truncated.bag").string();
  lfd_segmentation_test::writeDemoBag(bag);
  fs::resize_file(bag, fs::file_size(bag) / 2);
  EXPECT_THROW(lfd_segmentation::readBagFeatures(bag, defaultTopics(), 50), std::runtime_error);
  const std::string garbage = (tempDir() / "garbage.bag").string();
  std::ofstream(garbage) << "this is not a bag";
  EXPECT_THROW(lfd_segmentation::readBagFeatures(garbage, defaultTopics(), 50), std::runtime_error);
}

// Regression: a link swapped between a bag and a FIFO while the reader runs never hangs it
// (the path was checked, then opened again by name: open() blocked on the FIFO forever).
TEST(BagFeatures, LinkSwappedToFifoNeverHangsTheReader) {
  const fs::path dir = tempDir();
  const std::string bag = (dir / "real.bag").string();
  lfd_segmentation_test::DemoBagOptions o;
  o.duration = 1.0;
  lfd_segmentation_test::writeDemoBag(bag, o);
  const std::vector<TopicConfig> topics = defaultTopics();
  const lfd_test::LinkSwapRaceResult r = lfd_test::raceLinkSwap(
      (dir / "link.bag").string(), bag, (dir / "pipe.bag").string(),
      [&](const std::string& link) { lfd_segmentation::readBagStreams(link, topics); });
  EXPECT_EQ(r.hung_calls, 0) << "of " << r.calls << " calls";
  EXPECT_GT(r.read_calls, 0);  // the bag itself is still read when the link points at it
}

// Regression: one /ee_pose stamped 5 s late is kept, in stamp order, and warned about by the
// same policy as the learner's reader (lfd_core/io/stamp_order.hpp).
TEST(BagFeatures, AMessageStampedLateIsPutInOrderAndWarned) {
  const std::string bag = (tempDir() / "late_pose.bag").string();
  lfd_segmentation_test::DemoBagOptions o;
  o.duration = 10.0;
  o.late_pose_seconds = 5.005;  // between two samples' stamps
  lfd_segmentation_test::writeDemoBag(bag, o);
  std::vector<std::string> warnings;
  const std::vector<lfd::Stream> streams =
      lfd_segmentation::readBagStreams(bag, defaultTopics(), nullptr, &warnings);
  const auto pose = std::find_if(streams.begin(), streams.end(), [](const lfd::Stream& s) {
    return s.name == "/ee_pose/pose/position/x";
  });
  ASSERT_NE(pose, streams.end());
  EXPECT_EQ(pose->time.size(), 1000u);  // nothing dropped
  EXPECT_TRUE(std::is_sorted(pose->time.begin(), pose->time.end()));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("/ee_pose: of 1000 messages, 1 stamped out of order"),
            std::string::npos)
      << warnings[0];
  const auto demo = lfd_segmentation::readBagFeatures(bag, defaultTopics(), 50.0);
  ASSERT_EQ(demo.warnings.size(), 1u);  // the service and the CLI pass it on
  EXPECT_NE(demo.warnings[0].find("late_pose.bag"), std::string::npos);
}

TEST(SegmentationParams, LoadsTheShippedConfigAndRejectsBadValues) {
  const auto p =
      lfd_segmentation::loadParamsFile(std::string(LFD_CONFIG_DIR) + "/segmentation.yaml");
  EXPECT_DOUBLE_EQ(p.pipeline.relevance.threshold, 0.9);
  EXPECT_EQ(p.pipeline.segmentation.combination, lfd::ProfileCombination::kWeightedProduct);
  EXPECT_DOUBLE_EQ(p.pipeline.events.threshold_ratio, 0.4);
  EXPECT_EQ(p.topics.size(), 5u);
  EXPECT_THROW(lfd_segmentation::paramsFromYaml(YAML::Load("threshold: 1.5")),
               std::invalid_argument);
  EXPECT_THROW(lfd_segmentation::paramsFromYaml(YAML::Load("combination: median")),
               std::invalid_argument);
  EXPECT_THROW(lfd_segmentation::paramsFromYaml(YAML::Load("rate: -1")), std::invalid_argument);
  EXPECT_THROW(lfd_segmentation::paramsFromYaml(
                   YAML::Load("topics: [{topic: /lfd/phase, fields: [index]}]")),
               std::invalid_argument);
  EXPECT_THROW(lfd_segmentation::paramsFromYaml(
                   YAML::Load("topics: [{topic: /x, role: actuator, fields: [a]}]")),
               std::invalid_argument);
  lfd_segmentation::SegmentationParams s;
  s.rate = 50;
  s.min_segment_seconds = 1.0;
  s.window_seconds = 0.4;
  EXPECT_EQ(s.pipelineConfig().segmentation.min_segment_length, 50u);
  EXPECT_EQ(s.pipelineConfig().window_size, 20u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
