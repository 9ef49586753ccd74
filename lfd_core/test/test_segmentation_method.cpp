#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "lfd_core/segmentation/segmentation_method.hpp"
#include "lfd_core/segmentation/zone_search_segmentation.hpp"

namespace {

// Two-phase demonstrations: the gripper closes at 40 %, the touch sensor steps up with it.
std::vector<lfd::FeatureMatrix> makeDemos(int count) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<lfd::FeatureMatrix> demos;
  for (int d = 0; d < count; ++d) {
    const int n = 300 + 20 * d, grasp = static_cast<int>(0.4 * n);
    lfd::FeatureMatrix m;
    m.names = {"gripper", "speed", "touch"};
    m.data.resize(n, 3);
    for (int i = 0; i < n; ++i) {
      const bool closed = i >= grasp;
      m.time.push_back(0.01 * i);
      m.data(i, 0) = (closed ? 0.0 : 0.08) + 0.0005 * noise(rng);
      m.data(i, 1) = std::sin(2 * M_PI * i / (closed ? 9.0 : 23.0)) + 0.003 * noise(rng);
      m.data(i, 2) = (closed ? 5.0 : 0.0) + 0.05 * noise(rng);
    }
    demos.push_back(std::move(m));
  }
  return demos;
}

TEST(SegmentationMethod, RegistryReturnsEveryMethodByName) {
  const std::vector<std::string> names = lfd::segmentationMethodNames();
  EXPECT_EQ(names, (std::vector<std::string>{"zone_search", "paper", "joint"}));
  for (const std::string& name : names) {
    const auto method = lfd::makeSegmentationMethod(name);
    ASSERT_NE(method, nullptr);
    EXPECT_EQ(method->name(), name);
  }
}

TEST(SegmentationMethod, ProceduresMapOntoRegisteredNames) {
  for (const std::string& name : lfd::segmentationMethodNames())
    EXPECT_EQ(lfd::toString(lfd::parseSegmentationProcedure(name)), name);
}

TEST(SegmentationMethod, UnknownNameListsTheKnownOnes) {
  try {
    lfd::makeSegmentationMethod("zone-search");
    FAIL() << "an unknown name must throw";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'zone-search'"), std::string::npos) << message;
    for (const std::string& name : lfd::segmentationMethodNames())
      EXPECT_NE(message.find(name), std::string::npos) << message;
  }
}

void expectSame(const lfd::SegmentationPipelineResult& a,
                const lfd::SegmentationPipelineResult& b) {
  ASSERT_EQ(a.demos.size(), b.demos.size());
  for (std::size_t d = 0; d < a.demos.size(); ++d) {
    EXPECT_EQ(a.demos[d].changepoints, b.demos[d].changepoints) << "demo " << d;
    EXPECT_EQ(a.demos[d].changepoint_times, b.demos[d].changepoint_times) << "demo " << d;
    EXPECT_EQ(a.demos[d].rejected, b.demos[d].rejected) << "demo " << d;
    EXPECT_EQ(a.demos[d].pruned, b.demos[d].pruned) << "demo " << d;
    EXPECT_EQ(a.demos[d].events, b.demos[d].events) << "demo " << d;
    EXPECT_EQ(a.demos[d].min_segment_length, b.demos[d].min_segment_length) << "demo " << d;
    EXPECT_EQ(a.demos[d].clasp.candidates.size(), b.demos[d].clasp.candidates.size());
  }
  EXPECT_EQ(a.selected_features, b.selected_features);
  EXPECT_EQ(a.warnings, b.warnings);
}

TEST(SegmentationMethod, SegmentPreparedRunsTheNamedMethod) {
  const auto demos = makeDemos(4);
  lfd::SegmentationPipelineConfig config;
  config.seconds = lfd::TimeParameters{};
  config.procedure = lfd::SegmentationProcedure::kZoneSearch;
  const lfd::PreparedSegmentation prepared = lfd::prepareSegmentation(demos, {"touch"}, config);
  const auto through_pipeline = lfd::segmentPrepared(prepared, demos, config);
  const auto direct = lfd::ZoneSearchSegmentation().segment(prepared, demos, config);
  const auto by_name = lfd::makeSegmentationMethod("zone_search")->segment(prepared, demos, config);
  expectSame(through_pipeline, direct);
  expectSame(through_pipeline, by_name);
  // The synthetic grasp is found, so the comparison is not between two empty results.
  for (const auto& demo : direct.demos) EXPECT_FALSE(demo.changepoints.empty());
}

}  // namespace
