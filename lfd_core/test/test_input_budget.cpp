// The request budget: the files a request expands to, and their bytes, are
// refused before any work, naming the config key; a FIFO among them is refused at once. Every
// string of a request within one bound.
#include "lfd_core/io/input_budget.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

#include "ros_serialized_bytes.hpp"
#include "support/error_of.hpp"

namespace {

namespace fs = std::filesystem;

class InputBudgetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("lfd_budget_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    for (int k = 0; k < 3; ++k) {
      files_.push_back((dir_ / ("d" + std::to_string(k) + ".bag")).string());
      std::ofstream(files_.back()) << std::string(100, 'x');
    }
    budget_.what = "bags";
    budget_.max_files = 3;
    budget_.max_files_key = "limits/max_bag_files";
    budget_.max_total_bytes = 300;
    budget_.max_total_bytes_key = "limits/max_total_bytes";
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::vector<std::string> files_;
  lfd::InputBudget budget_;
};

TEST_F(InputBudgetTest, WithinTheBudgetReturnsTheTotalSize) {
  EXPECT_EQ(lfd::checkInputBudget(files_, budget_), 300u);
}

TEST_F(InputBudgetTest, TooManyFilesAreRefusedBeforeAnyIsOpened) {
  std::vector<std::string> many = files_;
  many.push_back((dir_ / "missing.bag").string());  // never opened: the count refuses first
  EXPECT_EQ(errorOf([&] { lfd::checkInputBudget(many, budget_); }),
            "4 bags, over the limit of 3 (limits/max_bag_files)");
}

TEST_F(InputBudgetTest, TooManyBytesAreRefusedNamingTheKey) {
  budget_.max_total_bytes = 250;
  EXPECT_NE(errorOf([&] {
              lfd::checkInputBudget(files_, budget_);
            }).find("over the limit of 250 bytes (limits/max_total_bytes)"),
            std::string::npos);
}

TEST_F(InputBudgetTest, ANamedPipeAmongTheFilesIsRefused) {
  const std::string fifo = (dir_ / "pipe.bag").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(errorOf([&] {
              lfd::checkInputBudget({files_[0], fifo}, budget_);
            }).find("named pipe"),
            std::string::npos);
}

}  // namespace

// Regression: one bound for every string of a request; the refusal names the field and the key and
// quotes at most 200 characters (a 10 MB string was echoed whole into errors, logs, feedback).
TEST(RequestStrings, AStringOverTheBudgetIsRefusedNamingTheFieldAndKey) {
  lfd::StringBudget budget;
  budget.max_bytes = 100;
  budget.key = "limits/max_request_string_bytes";
  EXPECT_EQ(errorOf([&] { lfd::checkRequestString("task", std::string(100, 'a'), budget); }), "");
  const std::string huge(10 << 20, 'x');
  const std::string error = errorOf([&] { lfd::checkRequestString("task", huge, budget); });
  EXPECT_EQ(error.rfind("task: a string of 10485760 bytes, over the limit of 100 "
                        "(limits/max_request_string_bytes): 'xxx",
                        0),
            0u)
      << error.substr(0, 300);
  EXPECT_LT(error.size(), 400u);
  EXPECT_EQ(lfd::kDefaultMaxRequestStringBytes, 64u * 4096u + 63u);
}

// Every string of a serialized request, at any depth and in every array, named by its path.
TEST(RequestStrings, EveryStringOfAMessageIsCheckedByItsPath) {
  const lfd::rosmsg::MessageSchema schema =
      lfd::rosmsg::MessageSchema::parse("p/Req", R"(string task
string[] bag_paths
float64[] numbers
Meta metadata
Meta[] more
================================================================================
MSG: p/Meta
Header header
string note
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
)");
  auto message = [](const std::string& path, const std::string& frame) {
    Bytes b;
    b.str("grasp");
    b.put<std::uint32_t>(2).str("/tmp/a.bag").str(path);
    b.put<std::uint32_t>(3).put(1.0).put(2.0).put(3.0);
    b.header(1, 2).str("note");
    b.put<std::uint32_t>(1).put<std::uint32_t>(0).put<std::uint32_t>(0).put<std::uint32_t>(0);
    b.str(frame).str("");
    return b;
  };
  lfd::StringBudget budget;
  budget.max_bytes = 64;
  budget.key = "~limits/max_request_string_bytes";
  const Bytes fine = message("/tmp/b.bag", "world");
  EXPECT_EQ(errorOf([&] {
              lfd::checkMessageStrings(schema, fine.data.data(), fine.data.size(), budget);
            }),
            "");
  const Bytes long_path = message(std::string(65, 'p'), "world");
  EXPECT_EQ(errorOf([&] {
              lfd::checkMessageStrings(schema, long_path.data.data(), long_path.data.size(),
                                       budget);
            }).rfind("bag_paths[1]: a string of 65 bytes", 0),
            0u);
  const Bytes long_frame = message("/tmp/b.bag", std::string(1000, 'f'));
  EXPECT_EQ(errorOf([&] {
              lfd::checkMessageStrings(schema, long_frame.data.data(), long_frame.data.size(),
                                       budget);
            }).rfind("more[0].header.frame_id: a string of 1000 bytes", 0),
            0u);
  // Bytes that are no message of the schema are an error, never a read past the buffer.
  Bytes cut = fine;
  cut.data.resize(cut.data.size() - 3);
  EXPECT_THROW(lfd::checkMessageStrings(schema, cut.data.data(), cut.data.size(), budget),
               lfd::rosmsg::MessageError);
}
