// The service body (handleSegmentRequest) on bags written by the test: every bad input ends in
// success=false + a precise error (or a warning), and a good request finds the grasp.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>

#include "demo_bag_writer.hpp"
#include "lfd_segmentation/segment_service.hpp"

namespace {

namespace fs = std::filesystem;
using lfd_segmentation_test::DemoBagOptions;

class SegmentService : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("lfd_service_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    params_ = lfd_segmentation::loadParamsFile(std::string(LFD_CONFIG_DIR) + "/segmentation.yaml");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static std::string bag(const std::string& name, DemoBagOptions o = {}) {
    const std::string path = (dir_ / (name + ".bag")).string();
    if (!fs::exists(path)) lfd_segmentation_test::writeDemoBag(path, o);
    return path;
  }
  static std::vector<std::string> goodBags(int count) {
    std::vector<std::string> bags;
    for (int d = 0; d < count; ++d) {
      DemoBagOptions o;
      o.seed = 100 + d;
      o.duration = 7.0 + 0.5 * d;
      o.start_time = 50.0 + 20 * d;
      bags.push_back(bag("good" + std::to_string(d), o));
    }
    return bags;
  }
  lfd_msgs::Segment::Response call(const std::vector<std::string>& bags,
                                   lfd_msgs::Segment::Request request = {}) {
    request.bag_paths = bags;
    lfd_msgs::Segment::Response response;
    lfd_segmentation::handleSegmentRequest(params_, request, response);
    return response;
  }
  void expectError(const lfd_msgs::Segment::Response& r, const std::string& needle) {
    EXPECT_FALSE(r.success);
    EXPECT_NE(r.error.find(needle), std::string::npos) << r.error;
    EXPECT_TRUE(r.demos.empty());
  }

  static fs::path dir_;
  static lfd_segmentation::SegmentationParams params_;
};
fs::path SegmentService::dir_;
lfd_segmentation::SegmentationParams SegmentService::params_;

// The cache of the last request's bags and selection: a second request on the same bags with
// another method gives what an uncached request gives, and a bag that changed on disk is read
// again (a new file at the same path, another size and time).
TEST_F(SegmentService, ACachedSelectionGivesTheUncachedAnswer) {
  std::vector<std::string> bags = goodBags(3);
  lfd_segmentation::PreparedCache cache;
  lfd_msgs::Segment::Request request;
  request.bag_paths = bags;
  lfd_msgs::Segment::Response first, cached;
  lfd_segmentation::handleSegmentRequest(params_, request, first, &cache);
  ASSERT_TRUE(first.success) << first.error;
  EXPECT_FALSE(cache.key.empty());
  EXPECT_EQ(cache.demos.size(), 3u);
  request.combination = "average";
  lfd_segmentation::handleSegmentRequest(params_, request, cached, &cache);
  const auto plain = call(bags, request);
  ASSERT_TRUE(cached.success && plain.success);
  EXPECT_EQ(cached.selected_features, plain.selected_features);
  for (std::size_t d = 0; d < bags.size(); ++d)
    EXPECT_EQ(cached.demos[d].changepoints, plain.demos[d].changepoints);
  // Replace the second bag by a longer demo: the cache must not answer for the old file.
  const std::string key = cache.key;
  const std::string replaced = (dir_ / "replaced.bag").string();
  DemoBagOptions o;
  o.seed = 7;
  o.duration = 9.5;
  lfd_segmentation_test::writeDemoBag(replaced, o);
  fs::copy_file(replaced, bags[1], fs::copy_options::overwrite_existing);
  lfd_msgs::Segment::Response again;
  lfd_segmentation::handleSegmentRequest(params_, request, again, &cache);
  ASSERT_TRUE(again.success) << again.error;
  EXPECT_NE(cache.key, key);
  EXPECT_NEAR(again.demos[1].num_samples, 9.5 * params_.rate, 2.0);
  fs::remove(bags[1]);  // good1 is written afresh by the next test that needs it
}

// Regression: a bag replaced by a corrupt file of the same size and modification time (touch -r
// old new; mv new bag) still got the cached success: the cache was keyed by path, size and mtime.
// Keyed by the identity of the descriptor read (inode, ctime...), the request reads the new file
// and fails naming it.
TEST_F(SegmentService, ABagReplacedBySameSizeSameTimeCorruptFileIsNotTheCachedOne) {
  const std::vector<std::string> bags = goodBags(2);
  std::vector<std::string> request_bags;
  for (std::size_t d = 0; d < bags.size(); ++d) {  // copies: the other tests keep their bags
    request_bags.push_back((dir_ / ("stale" + std::to_string(d) + ".bag")).string());
    fs::copy_file(bags[d], request_bags.back(), fs::copy_options::overwrite_existing);
  }
  lfd_segmentation::PreparedCache cache;
  lfd_msgs::Segment::Request request;
  request.bag_paths = request_bags;
  lfd_msgs::Segment::Response first;
  lfd_segmentation::handleSegmentRequest(params_, request, first, &cache);
  ASSERT_TRUE(first.success) << first.error;

  const std::string& victim = request_bags[1];
  struct stat old {};
  ASSERT_EQ(::stat(victim.c_str(), &old), 0);
  const std::string fake = (dir_ / "fake.bag").string();
  std::ofstream(fake, std::ios::binary) << std::string(static_cast<std::size_t>(old.st_size), 'x');
  const struct timespec times[2] = {old.st_atim, old.st_mtim};
  ASSERT_EQ(::utimensat(AT_FDCWD, fake.c_str(), times, 0), 0);  // touch -r old new
  fs::rename(fake, victim);                                     // mv new bag
  struct stat now {};
  ASSERT_EQ(::stat(victim.c_str(), &now), 0);
  ASSERT_EQ(now.st_size, old.st_size);
  ASSERT_EQ(now.st_mtim.tv_sec, old.st_mtim.tv_sec);
  ASSERT_EQ(now.st_mtim.tv_nsec, old.st_mtim.tv_nsec);

  lfd_msgs::Segment::Response again;
  lfd_segmentation::handleSegmentRequest(params_, request, again, &cache);
  EXPECT_FALSE(again.success) << "the cached success answered for a corrupt bag";
  EXPECT_NE(again.error.find("cannot open bag"), std::string::npos) << again.error;
  EXPECT_NE(again.error.find("stale1.bag"), std::string::npos) << again.error;
  for (const std::string& b : request_bags) fs::remove(b);
}

// Regression: a service resolves a relative path against its own working directory, which the
// client neither sees nor chose. Every bag path (every part of one) must be absolute; the error
// names the field.
TEST_F(SegmentService, RelativeBagPathsAreRefusedNamingTheField) {
  const std::vector<std::string> bags = goodBags(2);
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_);  // where the relative names would resolve: they exist there
  const auto r = call({bags[0], fs::path(bags[1]).filename().string()});
  expectError(r, "bag_paths[1]: path 'good1.bag' is relative");
  expectError(call({bags[0], bags[1] + ",good0.bag"}), "bag_paths[1]: path 'good0.bag'");
  fs::current_path(cwd);
  expectError(r, "absolute path");
}

// Regression: every string of a request within limits/max_request_string_bytes, checked before any
// work (a 10 MB string was echoed into errors and logs); the error quotes at most 200 characters.
TEST_F(SegmentService, AnOverlongRequestStringIsRefusedBeforeAnyWork) {
  lfd_msgs::Segment::Request request;
  request.combination = std::string(10 << 20, 'c');
  const auto r = call(goodBags(2), request);
  expectError(r,
              "combination: a string of 10485760 bytes, over the limit of 262207 "
              "(limits/max_request_string_bytes)");
  EXPECT_LT(r.error.size(), 500u);
  EXPECT_LT(r.elapsed, 1.0);
  const auto paths = call({goodBags(1)[0], "/tmp/" + std::string(300000, 'p') + ".bag"});
  expectError(paths, "bag_paths[1]: a string of 300009 bytes");
}

// Regression: 10,000 feature columns took 1.1 GB. Features beyond limits/max_features are refused
// as the topics' fields are expanded, before the bags are read whole and resampled.
TEST_F(SegmentService, TooManyFeaturesAreRefusedBeforeResampling) {
  lfd_segmentation::SegmentationParams few = params_;
  few.limits.max_features = 10;
  lfd_msgs::Segment::Request request;
  request.bag_paths = goodBags(2);
  lfd_msgs::Segment::Response r;
  lfd_segmentation::handleSegmentRequest(few, request, r);
  expectError(r, "over the limit of 10 (limits/max_features)");
  EXPECT_NE(r.error.find("good0.bag"), std::string::npos) << r.error;
  EXPECT_EQ(params_.limits.max_features, 256u);  // the shipped bound takes these bags
}

// Regression: a topic whose connection declares geometry_msgs/PoseStamped but whose message holds
// other bytes read as "Buffer Overrun". The error names the file, the topic, the declared type,
// the message's index and time, and says the bytes do not match; the service answers.
TEST_F(SegmentService, MessageBytesThatDoNotMatchTheDeclaredTypeAreNamed) {
  DemoBagOptions o;
  o.pose_holds_a_twist = true;
  const auto r = call({goodBags(1)[0], bag("pose_holds_a_twist", o)});
  expectError(r,
              "pose_holds_a_twist.bag': message 400 on '/ee_pose' (declared "
              "'geometry_msgs/PoseStamped') at t = 104.000 s: its bytes do not match the "
              "declared message definition");
}

TEST_F(SegmentService, GoodRequestValidatesTheGraspChangepoint) {
  const auto bags = goodBags(3);
  const auto r = call(bags);
  ASSERT_TRUE(r.success) << r.error;
  ASSERT_EQ(r.demos.size(), 3u);
  EXPECT_FALSE(r.selected_features.empty());
  EXPECT_EQ(r.selected_features.size(), r.selected_weights.size());
  EXPECT_EQ(r.sensor_features.size(), 2u);  // touch pads; the wrist F/T is context
  EXPECT_FALSE(r.features.empty());
  for (const auto& f : r.features) EXPECT_EQ(f.correlation.size(), 9u);
  // Every validated changepoint is the grasp; ClaSP may place a step up to ~one window late, so
  // one demo may lose it to its zone (ClaSP precision is tested in lfd_core).
  int validated = 0;
  for (int d = 0; d < 3; ++d) {
    const auto& demo = r.demos[d];
    DemoBagOptions o;
    o.duration = 7.0 + 0.5 * d;
    o.start_time = 50.0 + 20 * d;
    EXPECT_LE(demo.changepoints.size(), 1u) << "demo " << d;
    EXPECT_FALSE(demo.candidates.empty());
    for (double t : demo.changepoint_times) {
      EXPECT_NEAR(t, lfd_segmentation_test::graspTime(o), 0.1 * o.duration);
      ++validated;
    }
    EXPECT_NEAR(demo.start_time, o.start_time, 0.05);
    EXPECT_DOUBLE_EQ(demo.sample_rate, params_.rate);
    EXPECT_FALSE(demo.zones.empty());
  }
  EXPECT_GE(validated, 2);
  EXPECT_GT(r.elapsed, 0.0);
}

TEST_F(SegmentService, OverridesAreApplied) {
  lfd_msgs::Segment::Request request;
  request.combination = "average";
  request.num_changepoints = 2;
  request.min_segment_seconds = 1.0;
  const auto r = call(goodBags(2), request);
  ASSERT_TRUE(r.success) << r.error;
  EXPECT_EQ(r.demos[0].min_segment_length, 50u);
  request.combination = "median";
  expectError(call(goodBags(2), request), "median");
  request.combination = "";
  request.threshold = 2.0;
  expectError(call(goodBags(2), request), "threshold");
}

TEST_F(SegmentService, EmptyRequest) {
  expectError(call({}), "empty request");
}

TEST_F(SegmentService, SingleDemoFallsBackWithAWarning) {
  const auto r = call({goodBags(1)[0]});
  ASSERT_TRUE(r.success) << r.error;
  ASSERT_FALSE(r.warnings.empty());
  bool warned = false;
  for (const auto& w : r.warnings)
    warned = warned || w.find("single demonstration") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_TRUE(r.features.empty());
}

TEST_F(SegmentService, MissingTopic) {
  DemoBagOptions o;
  o.with_touch = false;
  expectError(call({goodBags(1)[0], bag("no_touch", o)}), "no messages on topic /touch");
}

TEST_F(SegmentService, NaNSample) {
  DemoBagOptions o;
  o.nan_in_twist = true;
  expectError(call({goodBags(1)[0], bag("nan", o)}), "/ee_twist/twist/linear/x");
}

TEST_F(SegmentService, DemoShorterThanTwiceMinSegment) {
  lfd_msgs::Segment::Request request;
  request.min_segment_seconds = 5.0;
  expectError(call(goodBags(2), request), "2 * min_s");
}

TEST_F(SegmentService, ConstantSignalIsIgnoredWithAWarning) {
  DemoBagOptions o;
  o.constant_gripper = true;
  o.seed = 7;
  const auto r = call({bag("constant_a", o), bag("constant_b", o)});
  ASSERT_TRUE(r.success) << r.error;
  bool warned = false;
  for (const auto& w : r.warnings)
    warned = warned || w.find("R_GRIPPER' is constant") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST_F(SegmentService, UnreadableAndTruncatedBags) {
  expectError(call({"/nonexistent/demo.bag", goodBags(1)[0]}), "cannot open bag");
  const std::string truncated = (dir_ / "truncated.bag").string();
  fs::copy_file(goodBags(1)[0], truncated, fs::copy_options::overwrite_existing);
  fs::resize_file(truncated, fs::file_size(truncated) / 3);
  expectError(call({goodBags(1)[0], truncated}), "truncated.bag");
}

TEST_F(SegmentService, FeaturesThatDifferBetweenDemos) {
  DemoBagOptions o;
  o.touch_name = "r_touch_palm";
  expectError(call({goodBags(1)[0], bag("other_touch", o)}), "features differ");
}

// Regression: a named pipe as a bag path blocked the node in open() forever. If the code under test
// blocks, the test opens the pipe's other end itself so it can fail instead of hanging.
TEST_F(SegmentService, NamedPipeIsRefusedAtOnce) {
  const std::string fifo = (dir_ / "pipe.bag").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto answer = std::async(std::launch::async, [&] { return call({goodBags(1)[0], fifo}); });
  if (answer.wait_for(std::chrono::seconds(10)) == std::future_status::timeout) {
    const int fd = ::open(fifo.c_str(), O_WRONLY);  // releases the blocked reader
    ::close(fd);
    ADD_FAILURE() << "a named pipe blocked the request";
  }
  expectError(answer.get(), "named pipe");
  fs::remove(fifo);
}

TEST_F(SegmentService, PathsOutsideTheRootsOrWithParentReferencesAreRefused) {
  lfd_segmentation::SegmentationParams rooted = params_;
  rooted.paths.allowed_roots = {(dir_ / "root").string()};
  fs::create_directories(dir_ / "root");
  const std::string inside = (dir_ / "root" / "good0.bag").string();
  fs::copy_file(goodBags(1)[0], inside, fs::copy_options::overwrite_existing);
  lfd_msgs::Segment::Request request;
  lfd_msgs::Segment::Response r;
  request.bag_paths = {inside, goodBags(2)[1]};
  lfd_segmentation::handleSegmentRequest(rooted, request, r);
  expectError(r, "allowed_roots");
  request.bag_paths = {inside, (dir_ / "root" / ".." / "root" / "good0.bag").string()};
  lfd_segmentation::handleSegmentRequest(rooted, request, r);
  expectError(r, "'..'");
}

TEST_F(SegmentService, TooManyBagsAreRefusedNamingTheLimit) {
  lfd_segmentation::SegmentationParams small = params_;
  small.limits.max_bags = 2;
  lfd_msgs::Segment::Request request;
  request.bag_paths = goodBags(3);
  lfd_msgs::Segment::Response r;
  lfd_segmentation::handleSegmentRequest(small, request, r);
  expectError(r, "limits/max_bags");
}

// Regression: entries written as parts of one demo ("a.bag,b.bag,...") passed max_bags, which
// counted entries: 32 of them expanded to 290 bags (120 s, 581 MB). The budget counts the bags
// the request expands to, and their bytes, before reading any, with the shipped limits.
TEST_F(SegmentService, PartsOfDemosCountAgainstTheBudgetBeforeAnyWork) {
  const std::vector<std::string> bags = goodBags(2);
  std::vector<std::string> entries;
  for (const std::string& b : bags) {
    std::string parts = b;
    for (int k = 1; k < 70; ++k) parts += "," + b;  // 70 parts: 140 bags in two entries
    entries.push_back(parts);
  }
  ASSERT_LE(entries.size(), params_.limits.max_bags);
  const auto start = std::chrono::steady_clock::now();
  const lfd_msgs::Segment::Response r = call(entries);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  expectError(r, "140 bag files, over the limit of 128 (limits/max_bag_files)");

  lfd_segmentation::SegmentationParams small = params_;
  small.limits.max_total_bytes = fs::file_size(bags[0]) + fs::file_size(bags[1]) / 2;
  lfd_msgs::Segment::Request request;
  request.bag_paths = bags;
  lfd_msgs::Segment::Response bytes;
  lfd_segmentation::handleSegmentRequest(small, request, bytes);
  expectError(bytes, "(limits/max_total_bytes)");
}

// Regression: one message stamped 20,000 s late made the service unresponsive for over 90 s.
TEST_F(SegmentService, AMessageStampedHoursLateIsRefusedFast) {
  DemoBagOptions o;
  o.late_twist_seconds = 20000;
  const auto r = call({goodBags(1)[0], bag("late", o)});
  expectError(r, "limits/max_demo_seconds");
  EXPECT_NE(r.error.find("/ee_twist"), std::string::npos) << r.error;
  EXPECT_LT(r.elapsed, 5.0);
}

TEST_F(SegmentService, ValuesThatWouldOverflowDistancesAreRefused) {
  DemoBagOptions o;
  o.huge_twist = -1e308;
  const auto r = call({goodBags(1)[0], bag("huge", o)});
  expectError(r, "limits/max_abs_value");
  EXPECT_NE(r.error.find("/ee_twist/twist/linear/x"), std::string::npos) << r.error;
}

// Regression: inf or 1e300 min_segment_seconds and a window as long as the demo returned success
// with 0 changepoints.
TEST_F(SegmentService, DurationsNoDemoCanHaveAreClearErrors) {
  for (double bad :
       {std::numeric_limits<double>::infinity(), 1e300, std::numeric_limits<double>::quiet_NaN()}) {
    lfd_msgs::Segment::Request request;
    request.min_segment_seconds = bad;
    expectError(call(goodBags(2), request), "limits/max_demo_seconds");
    request = {};
    request.window_seconds = bad;
    expectError(call(goodBags(2), request), "limits/max_demo_seconds");
  }
  lfd_msgs::Segment::Request request;
  request.window_seconds = 60.0;  // within the limit, longer than the 7 s demos
  expectError(call(goodBags(2), request), "covers the whole demo");
  request = {};
  request.threshold = std::numeric_limits<double>::quiet_NaN();
  expectError(call(goodBags(2), request), "threshold");
  request = {};
  request.num_changepoints = 1000000;
  expectError(call(goodBags(2), request), "max_changepoints");
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
