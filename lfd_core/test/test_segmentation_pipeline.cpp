#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace {

// Grasp-like demonstrations: the gripper closes at `grasp` (40 % of the demo), the speed has one
// bump per phase, the touch sensor steps up when the fingers close. Noise and a constant column
// must not disturb the result.
struct SyntheticDemo {
  lfd::FeatureMatrix matrix;
  std::size_t grasp = 0;
};

std::vector<SyntheticDemo> makeDemos(int count, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<SyntheticDemo> demos;
  for (int d = 0; d < count; ++d) {
    const int n = 400 + 25 * d;
    SyntheticDemo demo;
    demo.grasp = static_cast<std::size_t>(0.4 * n);
    lfd::FeatureMatrix& m = demo.matrix;
    m.names = {"gripper", "speed", "noise", "constant", "touch"};
    m.data.resize(n, m.names.size());
    for (int i = 0; i < n; ++i) {
      const double t = double(i) / (n - 1);
      const bool closed = i >= int(demo.grasp);
      m.time.push_back(0.01 * i);
      m.data(i, 0) = (closed ? 0.0 : 0.08) + 0.0005 * noise(rng);
      const double phase = closed ? (t - 0.4) / 0.6 : t / 0.4;
      m.data(i, 1) = std::sin(M_PI * phase) * (closed ? 0.2 : 0.3) +
                     0.05 * std::sin(2 * M_PI * i / (closed ? 9.0 : 23.0)) + 0.003 * noise(rng);
      m.data(i, 2) = noise(rng);
      m.data(i, 3) = 2.0;
      m.data(i, 4) = (closed ? 5.0 : 0.0) + 0.05 * noise(rng);
    }
    demos.push_back(std::move(demo));
  }
  return demos;
}

std::vector<lfd::FeatureMatrix> matrices(const std::vector<SyntheticDemo>& demos) {
  std::vector<lfd::FeatureMatrix> out;
  for (const auto& d : demos) out.push_back(d.matrix);
  return out;
}

TEST(SegmentationPipeline, FindsTheGraspChangepointInEveryDemo) {
  const auto demos = makeDemos(4);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"});
  ASSERT_TRUE(result.relevance_computed);
  ASSERT_FALSE(result.selected_features.empty());
  EXPECT_EQ(std::find(result.selected_features.begin(), result.selected_features.end(), "noise"),
            result.selected_features.end());
  EXPECT_EQ(std::find(result.selected_features.begin(), result.selected_features.end(), "touch"),
            result.selected_features.end())
      << "a sensor feature must never be segmented";
  ASSERT_EQ(result.demos.size(), demos.size());
  for (std::size_t d = 0; d < demos.size(); ++d) {
    const auto& r = result.demos[d];
    ASSERT_EQ(r.changepoints.size(), 1u) << "demo " << d;
    const double tolerance = 0.1 * r.num_samples;  // ClaSP localizes within ~w/2 of a step
    EXPECT_NEAR(double(r.changepoints[0]), double(demos[d].grasp), tolerance) << "demo " << d;
    EXPECT_NEAR(r.changepoint_times[0], 0.01 * r.changepoints[0], 1e-9);
    ASSERT_FALSE(r.zones.empty());
    EXPECT_TRUE(r.zones[0].contains(demos[d].grasp));
  }
}

// One demo of four carries an extra change late in its second phase (the gripper slips a little,
// the touch force drops and the hand shakes, like a hesitation mid-skill). Three demos agree on
// one changepoint, so that demo keeps its most significant one and reports the other as pruned;
// the other demos are untouched.
TEST(SegmentationPipeline, ConsensusDropsTheExtraChangepointOfOneDemo) {
  auto demos = makeDemos(4);
  lfd::FeatureMatrix& odd = demos[2].matrix;
  const Eigen::Index slip = static_cast<Eigen::Index>(0.75 * static_cast<double>(odd.rows()));
  odd.data.col(0).tail(odd.rows() - slip).array() += 0.06;
  odd.data.col(4).tail(odd.rows() - slip).array() -= 4.0;
  for (Eigen::Index i = slip; i < odd.rows(); ++i)
    odd.data(i, 1) += 0.1 * std::sin(2 * M_PI * static_cast<double>(i) / 15.0);

  lfd::SegmentationPipelineConfig config;
  config.consensus_count = false;
  const auto plain = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, config);
  const auto& two = plain.demos[2];
  ASSERT_EQ(two.changepoints.size(), 2u);  // the slip is a changepoint on its own
  EXPECT_NEAR(double(two.changepoints[1]), double(slip), 0.1 * odd.rows());
  std::map<std::size_t, double> log_p;
  for (const lfd::SplitCandidate& c : two.clasp.candidates)
    if (c.accepted) log_p[c.index] = c.log10_p_value;
  const std::size_t stronger =
      log_p.at(two.changepoints[0]) < log_p.at(two.changepoints[1]) ? 0 : 1;

  config.consensus_count = true;
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"}, config);
  for (std::size_t d = 0; d < demos.size(); ++d) {
    if (d == 2) continue;
    EXPECT_EQ(result.demos[d].changepoints, plain.demos[d].changepoints) << "demo " << d;
    EXPECT_TRUE(result.demos[d].pruned.empty());
  }
  const auto& one = result.demos[2];
  ASSERT_EQ(one.changepoints.size(), 1u);
  ASSERT_EQ(one.pruned.size(), 1u);
  EXPECT_EQ(one.changepoints[0], two.changepoints[stronger]);
  EXPECT_EQ(one.pruned[0], two.changepoints[1 - stronger]);
  EXPECT_NEAR(one.pruned_times[0], odd.timeAt(one.pruned[0]), 1e-12);
  EXPECT_NE(std::find_if(result.warnings.begin(), result.warnings.end(),
                         [](const std::string& w) {
                           return w.find("demonstration 2: 2 changepoints where 3 of the 4") !=
                                  std::string::npos;
                         }),
            result.warnings.end());
}

TEST(SegmentationPipeline, SingleDemoFallsBackWithAWarning) {
  const auto demos = makeDemos(1);
  const auto result = lfd::runSegmentationPipeline(matrices(demos), {"touch"});
  EXPECT_FALSE(result.relevance_computed);
  EXPECT_EQ(result.selected_features, (std::vector<std::string>{"gripper", "speed", "noise"}));
  bool warned = false;
  for (const auto& w : result.warnings) warned = warned || w.find("single") != std::string::npos;
  EXPECT_TRUE(warned);
  ASSERT_EQ(result.demos.size(), 1u);
}

TEST(SegmentationPipeline, ConstantFeatureIsIgnoredWithAWarning) {
  const auto result = lfd::runSegmentationPipeline(matrices(makeDemos(2)), {"touch"});
  bool warned = false;
  for (const auto& w : result.warnings)
    warned = warned || w.find("'constant'") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_THROW(result.relevance.feature("constant"), std::invalid_argument);
}

void expectError(const std::vector<lfd::FeatureMatrix>& demos, const std::string& needle,
                 const lfd::SegmentationPipelineConfig& config = {},
                 const std::vector<std::string>& sensors = {"touch"}) {
  try {
    lfd::runSegmentationPipeline(demos, sensors, config);
    FAIL() << "expected an error mentioning '" << needle << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(SegmentationPipeline, BadInputGivesClearErrors) {
  const auto good = matrices(makeDemos(3));
  expectError({}, "no demonstrations");

  auto renamed = good;
  renamed[2].names[1] = "velocity";
  expectError(renamed, "features differ");

  auto with_nan = good;
  with_nan[1].data(7, 0) = std::nan("");
  expectError(with_nan, "demonstration 1: feature 'gripper' has NaN");

  auto with_inf = good;
  with_inf[0].data(3, 4) = INFINITY;
  expectError(with_inf, "feature 'touch' has Inf");

  lfd::SegmentationPipelineConfig long_min_s;
  long_min_s.segmentation.min_segment_length = 300;
  expectError(good, "2 * min_s", long_min_s);

  expectError(good, "sensor feature 'missing'", {}, {"missing"});
  expectError(good, "every feature is a sensor", {},
              {"gripper", "speed", "noise", "constant", "touch"});

  auto all_constant = good;
  for (auto& m : all_constant) m.data.leftCols(3).setConstant(1.0);
  expectError(all_constant, "constant");

  auto empty = good;
  empty[0].data.resize(0, 5);
  empty[0].time.clear();
  expectError(empty, "demonstration 0");
}

// The same grasp, recorded at any rate: a continuous-time demo (gripper closing over 0.2 s at
// `grasp_s`, one speed bump per phase, touch stepping up at the grasp) sampled at `rate` Hz.
lfd::FeatureMatrix sampledDemo(double rate, double duration, double grasp_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  lfd::FeatureMatrix m;
  m.names = {"gripper", "speed", "touch"};
  const int n = static_cast<int>(std::lround(duration * rate));
  m.data.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    const double t = i / rate;
    m.time.push_back(t);
    const double closing = std::clamp((t - grasp_s) / 0.2, 0.0, 1.0);
    m.data(i, 0) = 0.08 * (1.0 - closing) + 0.0005 * noise(rng);
    const bool carried = t >= grasp_s;
    const double phase = carried ? (t - grasp_s) / (duration - grasp_s) : t / grasp_s;
    m.data(i, 1) = std::sin(M_PI * phase) * (carried ? 0.2 : 0.3) +
                   0.05 * std::sin(2 * M_PI * t / (carried ? 0.3 : 0.8)) + 0.003 * noise(rng);
    m.data(i, 2) = (carried ? 5.0 : 0.0) + 0.05 * noise(rng);
  }
  return m;
}

// Seconds, not samples: the same demos resampled to 25, 50, 100 and 200 Hz give the same
// changepoint times within 0.05 s (with sample counts fixed for 50 Hz, 200 Hz would see windows,
// lags and min_s four times shorter in time).
TEST(SegmentationPipeline, SameChangepointsAtAnyRate) {
  lfd::SegmentationPipelineConfig config;
  config.seconds = lfd::TimeParameters{};
  const std::vector<double> grasps = {3.0, 3.4, 2.8, 3.2};
  std::map<double, std::vector<std::vector<double>>> times;  // rate -> demo -> changepoints
  for (double rate : {25.0, 50.0, 100.0, 200.0}) {
    std::vector<lfd::FeatureMatrix> demos;
    for (std::size_t d = 0; d < grasps.size(); ++d)
      demos.push_back(sampledDemo(rate, 8.0, grasps[d], static_cast<unsigned>(7 + d)));
    const auto result = lfd::runSegmentationPipeline(demos, {"touch"}, config);
    for (std::size_t d = 0; d < grasps.size(); ++d) {
      EXPECT_NEAR(result.demos[d].sample_rate, rate, 1e-6);
      EXPECT_EQ(result.demos[d].min_segment_length, static_cast<std::size_t>(std::lround(rate)));
      times[rate].push_back(result.demos[d].changepoint_times);
    }
  }
  for (std::size_t d = 0; d < grasps.size(); ++d) {
    const auto& reference = times[50.0][d];
    ASSERT_EQ(reference.size(), 1u) << "demo " << d;
    EXPECT_NEAR(reference[0], grasps[d], 0.05) << "demo " << d;
    for (double rate : {25.0, 100.0, 200.0}) {
      ASSERT_EQ(times[rate][d].size(), reference.size()) << rate << " Hz, demo " << d;
      EXPECT_NEAR(times[rate][d][0], reference[0], 0.05) << rate << " Hz, demo " << d;
    }
  }
}

TEST(SegmentationPipeline, SecondsNeedAClock) {
  auto demos = matrices(makeDemos(3));
  demos[1].time.clear();
  lfd::SegmentationPipelineConfig config;
  config.seconds = lfd::TimeParameters{};
  expectError(demos, "demonstration 1: no clock", config);
}

// A dead (constant) sensor: a warning naming it, no zone, no changepoint, no crash.
TEST(SegmentationPipeline, DeadSensorWarnsAndGivesNoZone) {
  auto demos = matrices(makeDemos(3));
  demos[1].data.col(4).setConstant(0.0);
  const auto result = lfd::runSegmentationPipeline(demos, {"touch"});
  EXPECT_TRUE(result.demos[1].zones.empty());
  EXPECT_TRUE(result.demos[1].changepoints.empty());
  EXPECT_NE(std::find_if(result.warnings.begin(), result.warnings.end(),
                         [](const std::string& w) {
                           return w.find("demonstration 1: sensor 'touch' is constant") !=
                                  std::string::npos;
                         }),
            result.warnings.end());
  EXPECT_EQ(result.demos[0].changepoints.size(), 1u);
}

// The feature selection does not depend on the combination: preparing once and segmenting with
// each method gives what a full run per method gives.
TEST(SegmentationPipeline, OneFeatureSelectionServesEveryCombination) {
  const auto demos = matrices(makeDemos(4));
  const lfd::PreparedSegmentation prepared = lfd::prepareSegmentation(demos, {"touch"});
  EXPECT_TRUE(prepared.base.demos.empty());
  for (const char* name : {"average", "weighted_product", "distance_average"}) {
    lfd::SegmentationPipelineConfig config;
    config.segmentation.combination = lfd::parseProfileCombination(name);
    const auto shared = lfd::segmentPrepared(prepared, demos, config);
    const auto full = lfd::runSegmentationPipeline(demos, {"touch"}, config);
    EXPECT_EQ(shared.selected_features, full.selected_features) << name;
    ASSERT_EQ(shared.demos.size(), full.demos.size());
    for (std::size_t d = 0; d < demos.size(); ++d)
      EXPECT_EQ(shared.demos[d].changepoints, full.demos[d].changepoints) << name << " " << d;
  }
}

// The paper's procedure: paper_candidates candidates anywhere, none anchored, then the zone
// filter: the accepted ones are the candidates inside a zone, the rejected ones the others.
TEST(SegmentationPipeline, PaperProcedureFiltersCandidatesFoundAnywhere) {
  const auto demos = matrices(makeDemos(4));
  lfd::SegmentationPipelineConfig config;
  config.procedure = lfd::SegmentationProcedure::kPaper;
  config.paper_candidates = 3;
  config.segmentation.min_segment_length = 30;
  const auto result = lfd::runSegmentationPipeline(demos, {"touch"}, config);
  for (const lfd::DemoSegmentationResult& d : result.demos) {
    EXPECT_EQ(d.clasp.changepoints.size(), 3u);
    EXPECT_EQ(d.changepoints.size() + d.rejected.size(), 3u);
    for (const lfd::SplitCandidate& c : d.clasp.candidates) EXPECT_FALSE(c.anchored);
    for (std::size_t cp : d.changepoints)
      EXPECT_TRUE(std::any_of(d.zones.begin(), d.zones.end(),
                              [&](const lfd::Interval& z) { return z.contains(cp); }));
    for (std::size_t cp : d.rejected)
      EXPECT_TRUE(std::none_of(d.zones.begin(), d.zones.end(),
                               [&](const lfd::Interval& z) { return z.contains(cp); }));
  }
  EXPECT_EQ(lfd::parseSegmentationProcedure("paper"), lfd::SegmentationProcedure::kPaper);
  EXPECT_THROW(lfd::parseSegmentationProcedure("papers"), std::invalid_argument);
}

// Consensus counts only the demos with evidence: three demos whose sensor is dead (no event, so
// no changepoint) must not out-vote the one demo whose changepoint has its own sensory event.
TEST(SegmentationPipeline, DemosWithoutEventsDoNotVote) {
  auto synthetic = makeDemos(5);
  auto demos = matrices(synthetic);
  for (std::size_t d : {1u, 2u, 3u}) demos[d].data.col(4).setConstant(0.0);
  const auto result = lfd::runSegmentationPipeline(demos, {"touch"});
  for (std::size_t d : {0u, 4u}) {
    ASSERT_EQ(result.demos[d].changepoints.size(), 1u) << "demo " << d;
    EXPECT_TRUE(result.demos[d].pruned.empty()) << "demo " << d;
    EXPECT_NEAR(double(result.demos[d].changepoints[0]), double(synthetic[d].grasp),
                0.1 * result.demos[d].num_samples);
  }
}

}  // namespace
