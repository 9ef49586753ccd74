// The request budget (issue 23 row 2): the files a request expands to, and their bytes, are
// refused before any work, naming the config key; a FIFO among them is refused at once.
#include "lfd_core/input_budget.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

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
