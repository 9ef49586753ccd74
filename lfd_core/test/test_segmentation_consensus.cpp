// Consensus across demonstrations (segmentation_consensus.hpp) on hand-made results: the agreed
// count is a plurality of the voting demos, extra changepoints go least significant first, and a
// demo short of changepoints takes its best in-zone candidates that reach the fill p-value.
#include <gtest/gtest.h>

#include <vector>

#include "lfd_core/segmentation/segmentation_consensus.hpp"

namespace {

using Indices = std::vector<std::size_t>;

lfd::FeatureMatrix demoMatrix() {
  lfd::FeatureMatrix m;
  m.names = {"x"};
  m.data = Eigen::MatrixXd::Zero(1000, 1);
  for (int i = 0; i < 1000; ++i) m.time.push_back(0.01 * i);
  return m;
}

// A demo result with accepted changepoints (index, log10 p) and, optionally, weaker candidates.
lfd::DemoSegmentationResult demo(const std::vector<std::pair<std::size_t, double>>& accepted,
                                 const std::vector<std::pair<std::size_t, double>>& weak = {}) {
  lfd::DemoSegmentationResult d;
  d.events = {1};  // it has evidence: it votes
  d.min_segment_length = 50;
  d.zones = {{80, 120}, {280, 320}, {480, 520}, {680, 720}};
  for (const auto& [index, log_p] : accepted) {
    d.changepoints.push_back(index);
    lfd::SplitCandidate c;
    c.index = index;
    c.log10_p_value = log_p;
    c.accepted = true;
    c.range_begin = 0;
    c.range_end = 1000;
    d.clasp.candidates.push_back(c);
  }
  for (const auto& [index, log_p] : weak) {
    lfd::SplitCandidate c;
    c.index = index;
    c.log10_p_value = log_p;
    c.range_begin = index - 60;  // a range still whole: no changepoint inside
    c.range_end = index + 60;
    d.clasp.candidates.push_back(c);
  }
  std::sort(d.changepoints.begin(), d.changepoints.end());
  return d;
}

// Counts 2, 2, 2, 0, 4, 3: no majority, but 2 is held by three demos, more than any other count.
TEST(SegmentationConsensus, APluralityPrunesTheDemosWithMore) {
  lfd::SegmentationPipelineResult r;
  r.demos = {demo({{100, -30}, {300, -20}}),
             demo({{100, -30}, {300, -20}}),
             demo({{100, -30}, {300, -20}}),
             demo({}),
             demo({{100, -28}, {300, -38}, {500, -33}, {700, -20}}),
             demo({{100, -25}, {300, -6}, {500, -32}})};
  const std::vector<lfd::FeatureMatrix> demos(6, demoMatrix());
  lfd::agreeOnChangepointCount(demos, true, 0.0, &r);
  EXPECT_EQ(r.demos[4].changepoints, (Indices{300, 500}));
  EXPECT_EQ(r.demos[4].pruned, (Indices{100, 700}));
  EXPECT_EQ(r.demos[5].changepoints, (Indices{100, 500}));
  EXPECT_EQ(r.demos[5].pruned, (Indices{300}));
  EXPECT_NEAR(r.demos[5].pruned_times[0], 3.0, 1e-12);
  EXPECT_TRUE(r.demos[3].changepoints.empty());  // no fill asked for
  EXPECT_EQ(r.warnings.size(), 2u);
}

// A tie between two counts is no agreement, nor is a count held by fewer than three demos.
TEST(SegmentationConsensus, ATieOrTooFewVotesIsNoAgreement) {
  lfd::SegmentationPipelineResult r;
  r.demos = {demo({{100, -30}}),
             demo({{100, -30}}),
             demo({{100, -30}}),
             demo({{100, -30}, {300, -20}}),
             demo({{100, -30}, {300, -20}}),
             demo({{100, -30}, {300, -20}})};
  const std::vector<lfd::FeatureMatrix> demos(6, demoMatrix());
  lfd::agreeOnChangepointCount(demos, true, 0.0, &r);
  EXPECT_TRUE(r.warnings.empty());
  r.demos.resize(4);
  r.demos[2] = demo({{100, -30}, {300, -20}, {500, -10}});
  lfd::agreeOnChangepointCount(std::vector<lfd::FeatureMatrix>(4, demoMatrix()), true, 0.0, &r);
  EXPECT_TRUE(r.warnings.empty());  // counts 1, 1, 3, 2: two votes at most
}

// Three demos have 2 changepoints; one found only the first, and ClaSP's best split in the zone
// of the second was weak (p = 1e-3) while another zone's was weaker still (1e-1). With a fill
// p-value of 1e-2 it takes the first of those; a demo without sensory events is never filled.
TEST(SegmentationConsensus, ADemoShortOfTheAgreedCountTakesItsBestInZoneCandidate) {
  lfd::SegmentationPipelineResult r;
  r.demos = {demo({{100, -30}, {300, -20}}), demo({{100, -30}, {300, -20}}),
             demo({{100, -30}, {300, -20}}), demo({{100, -30}}, {{300, -3}, {700, -1}}),
             demo({}, {{300, -3}})};
  r.demos[4].events.clear();
  const std::vector<lfd::FeatureMatrix> demos(5, demoMatrix());
  lfd::agreeOnChangepointCount(demos, true, 1e-2, &r);
  EXPECT_EQ(r.demos[3].changepoints, (Indices{100, 300}));
  EXPECT_EQ(r.demos[3].added, (Indices{300}));
  EXPECT_NEAR(r.demos[3].added_times[0], 3.0, 1e-12);
  EXPECT_TRUE(r.demos[4].changepoints.empty());
  // Without validation (no zones) nothing is added.
  r.demos[3] = demo({{100, -30}}, {{300, -3}});
  lfd::agreeOnChangepointCount(demos, false, 1e-2, &r);
  EXPECT_EQ(r.demos[3].changepoints, (Indices{100}));
}

}  // namespace
