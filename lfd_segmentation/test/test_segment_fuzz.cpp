// Property test of the segmentation service body: seeded random requests mixing good
// bags with extreme inputs (missing, empty, duplicated, very long and '..' paths, a named pipe, a
// folder, a device, a corrupt bag, a bag with a message stamped hours late or a 1e308 sample) and
// extreme numbers (NaN, inf, 1e300, 1e-300, negative, huge counts). Each answer must be a clear
// error or a sane result (changepoints inside the demo, finite times), no request may take long,
// the bags keep their bytes, and a valid request succeeds at the end. 200 requests, seed 12;
// about 1 s.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <limits>
#include <random>

#include "demo_bag_writer.hpp"
#include "lfd_segmentation/segment_service.hpp"

namespace {

namespace fs = std::filesystem;
using lfd_segmentation_test::DemoBagOptions;

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(SegmentServiceFuzz, RandomExtremeRequestsGiveAResultOrAClearError) {
  const fs::path dir = fs::temp_directory_path() / ("lfd_seg_fuzz_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  lfd_segmentation::SegmentationParams params =
      lfd_segmentation::loadParamsFile(std::string(LFD_CONFIG_DIR) + "/segmentation.yaml");
  params.paths.allowed_roots = {dir.string()};
  std::vector<std::string> good;
  for (int d = 0; d < 3; ++d) {
    DemoBagOptions o;
    o.seed = 100 + d;
    o.duration = 7.0 + 0.5 * d;
    good.push_back((dir / ("good" + std::to_string(d) + ".bag")).string());
    lfd_segmentation_test::writeDemoBag(good.back(), o);
  }
  DemoBagOptions late, huge;
  late.late_twist_seconds = 20000;
  huge.huge_twist = 1e308;
  const std::string late_bag = (dir / "late.bag").string(), huge_bag = (dir / "huge.bag").string();
  lfd_segmentation_test::writeDemoBag(late_bag, late);
  lfd_segmentation_test::writeDemoBag(huge_bag, huge);
  const std::string corrupt = (dir / "corrupt.bag").string();
  std::ofstream(corrupt) << std::string(4096, 'x');
  const std::string fifo = (dir / "pipe.bag").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::vector<std::string> paths = good;
  for (const std::string& p :
       {late_bag, huge_bag, corrupt, fifo, dir.string(), std::string("/dev/zero"), std::string(""),
        (dir / "missing.bag").string(), (dir / ".." / "x.bag").string(),
        (dir / std::string(4000, 'b')).string(), std::string("/etc/passwd"),
        good[0] + "," + good[1]})
    paths.push_back(p);
  std::vector<std::string> bytes;
  for (const std::string& g : good) bytes.push_back(readAll(g));

  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> numbers = {0,     -1,     0.5,    1,   2,    3,  60,
                                       1e300, -1e300, 1e-300, inf, -inf, nan};
  const std::vector<int> counts = {0, -1, 1, 2, 16, 17, 1000000, std::numeric_limits<int>::max()};
  std::mt19937 rng(12);
  auto pick = [&](const auto& v) { return v[rng() % v.size()]; };
  int successes = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < 200; ++k) {
    lfd_msgs::Segment::Request request;
    const int n = static_cast<int>(rng() % 5);
    for (int b = 0; b < n; ++b) request.bag_paths.push_back(rng() % 2 ? pick(good) : pick(paths));
    if (rng() % 8 == 0) request.bag_paths.assign(80, good[0]);  // over limits/max_bags
    request.combination = pick(std::vector<std::string>{"", "", "average", "median", "product"});
    if (rng() % 2) request.threshold = pick(numbers);
    if (rng() % 2) request.min_segment_seconds = pick(numbers);
    if (rng() % 2) request.window_seconds = pick(numbers);
    if (rng() % 2) request.num_changepoints = pick(counts);
    lfd_msgs::Segment::Response r;
    // On a thread: code that blocks on the pipe is released (the test opens the other end) and
    // the request fails instead of hanging the test.
    auto done = std::async(std::launch::async,
                           [&] { lfd_segmentation::handleSegmentRequest(params, request, r); });
    if (done.wait_for(std::chrono::seconds(20)) == std::future_status::timeout) {
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) ::close(fd);
      ADD_FAILURE() << "request " << k << " blocked for 20 s";
    }
    done.get();
    std::string what;
    for (const auto& p : request.bag_paths) what += " " + p.substr(0, 60);
    if (r.success) {
      ++successes;
      ASSERT_EQ(r.demos.size(), request.bag_paths.size()) << what;
      for (const auto& d : r.demos) {
        for (std::size_t c = 0; c < d.changepoints.size(); ++c) {
          EXPECT_LT(d.changepoints[c], d.num_samples) << what;
          EXPECT_TRUE(std::isfinite(d.changepoint_times[c])) << what;
        }
      }
    } else {
      EXPECT_FALSE(r.error.empty()) << what;
    }
    EXPECT_LT(r.elapsed, 20.0) << what;
    for (std::size_t g = 0; g < good.size(); ++g) ASSERT_EQ(readAll(good[g]), bytes[g]) << what;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("200 requests, %d succeeded, %.1f s\n", successes, seconds);
  lfd_msgs::Segment::Request valid;
  valid.bag_paths = good;
  lfd_msgs::Segment::Response r;
  lfd_segmentation::handleSegmentRequest(params, valid, r);
  EXPECT_TRUE(r.success) << r.error;
  fs::remove_all(dir);
}

}  // namespace
