// Property test of dmp_tool: seeded random commands built from extreme values (huge,
// tiny, non-finite, negative, empty, non-unit quaternions, wrong dimensions, duplicated flags,
// very long strings, paths that are pipes, folders or the inputs). Every answer must be exit 0
// with a readable output or exit 1/2 with an error line; the inputs must keep their bytes; and a
// valid command must still work afterwards. 1500 commands, seed 12; under 1 s.
#include "lfd_dmp/dmp_tool.hpp"
#include "lfd_dmp/skill_library.hpp"
#include "lfd_dmp/trajectory_csv.hpp"

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
#include <random>
#include <sstream>

namespace {

namespace fs = std::filesystem;

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class DmpToolFuzz : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("lfd_dmp_fuzz_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    csv_ = (dir_ / "demo.csv").string();
    std::ofstream out(csv_);
    out << "t,x,y,z,qw,qx,qy,qz,gripper\n";
    for (int i = 0; i < 200; ++i) {
      const double s = i / 199.0;
      out << 2 * s << "," << 0.3 + 0.3 * s << "," << 0.05 * std::sin(M_PI * s) << ",0.8,"
          << std::cos(0.2 * s) << ",0,0," << std::sin(0.2 * s) << "," << 0.08 - 0.06 * s << "\n";
    }
    out.close();
    library_ = (dir_ / "skill.json").string();
    std::ostringstream o, e;
    ASSERT_EQ(lfd_dmp::runDmpTool({"learn", "--csv", csv_, "--out", library_}, o, e), 0) << e.str();
    fifo_ = (dir_ / "pipe").string();
    ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string csv_, library_, fifo_;
};

TEST_F(DmpToolFuzz, RandomExtremeCommandsGiveAResultOrAClearError) {
  constexpr int kCommands = 1500;
  std::mt19937 rng(12);
  // clang-format off
  const std::vector<std::string> numbers = {
      "0", "-1", "1", "2", "0.005", "1e-12", "1e-300", "1e300", "-1e300", "nan", "inf", "-inf",
      "300", "1001", "4294967296", "", "abc", "1,2", "0.7,0.02,0.85", "1,2,3,4", "0,0,0,0",
      "2,0,0,0", "1e308,1e308,1e308", std::string(5000, '9')};
  const std::vector<std::string> files = {csv_, library_, fifo_, dir_.string(), "/dev/null",
                                          "", (dir_ / "missing").string(),
                                          (dir_ / std::string(300, 'a')).string(),
                                          (dir_ / "out.json").string(), (dir_ / "o.csv").string()};
  const std::vector<std::string> number_flags = {"--basis", "--segment", "--demo", "--start",
                                                 "--goal", "--start-quat", "--goal-quat",
                                                 "--start-gripper", "--goal-gripper", "--tau",
                                                 "--dt", "--duration", "--goal-filter"};
  // clang-format on
  const std::string csv_bytes = readAll(csv_), library_bytes = readAll(library_);
  auto pick = [&](const std::vector<std::string>& v) { return v[rng() % v.size()]; };
  const auto t0 = std::chrono::steady_clock::now();
  int ok = 0;
  for (int k = 0; k < kCommands; ++k) {
    std::vector<std::string> args = {pick({"learn", "rollout", "info", "", "--help"})};
    const int extra = static_cast<int>(rng() % 6);
    for (int a = 0; a < extra; ++a) {
      switch (rng() % 4) {
        case 0:
          args.push_back(pick({"--csv", "--library"}));
          args.push_back(pick(files));
          break;
        case 1:
          args.push_back("--out");
          args.push_back(pick(files));
          break;
        case 2:
          args.push_back(pick(number_flags));
          args.push_back(pick(numbers));
          break;
        default:
          args.push_back(pick({"--generalize", "--overwrite", "--bogus"}));
      }
    }
    std::ostringstream out, err;
    // On a thread: code that blocks on the pipe is released (the test opens the other end) and
    // the command fails instead of hanging the test.
    auto done = std::async(std::launch::async, [&] { return lfd_dmp::runDmpTool(args, out, err); });
    if (done.wait_for(std::chrono::seconds(10)) == std::future_status::timeout) {
      const int fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) ::close(fd);
      ADD_FAILURE() << "a command blocked for 10 s";
    }
    const int rc = done.get();
    std::string command;
    for (const auto& a : args) command += " " + a.substr(0, 40);
    ASSERT_TRUE(rc == 0 || rc == 1 || rc == 2) << command;
    if (rc != 0 && args[0] != "--help") {
      EXPECT_NE(err.str().find("error"), std::string::npos) << command << "\n" << err.str();
    }
    ok += rc == 0;
    ASSERT_EQ(readAll(csv_), csv_bytes) << "the input CSV changed:" << command;
    ASSERT_EQ(readAll(library_), library_bytes) << "the input library changed:" << command;
    ASSERT_TRUE(fs::is_fifo(fifo_)) << command;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%d commands, %d succeeded, %.2f s\n", kCommands, ok, seconds);
  EXPECT_LT(seconds, 60.0);
  std::ostringstream o, e;
  EXPECT_EQ(lfd_dmp::runDmpTool({"rollout", "--library", library_, "--out",
                                 (dir_ / "final.csv").string(), "--overwrite"},
                                o, e),
            0)
      << e.str();
}

}  // namespace
