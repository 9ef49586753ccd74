#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "lfd_core/util/parallel_for.hpp"

namespace {

TEST(ParallelFor, RunsEveryIndexOnce) {
  for (int threads : {1, 3, 0, -2}) {
    std::vector<std::atomic<int>> runs(1000);
    lfd::parallelFor(runs.size(), threads, [&](std::size_t i) { ++runs[i]; });
    for (std::size_t i = 0; i < runs.size(); ++i) ASSERT_EQ(runs[i], 1) << i << ", " << threads;
  }
  int calls = 0;
  lfd::parallelFor(0, 4, [&](std::size_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelFor, OneThreadRunsOnTheCaller) {
  std::set<std::thread::id> ids;
  lfd::parallelFor(20, 1, [&](std::size_t) { ids.insert(std::this_thread::get_id()); });
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

TEST(ParallelFor, UsesUpToTheGivenThreads) {
  std::mutex m;
  std::set<std::thread::id> ids;
  lfd::parallelFor(64, 3, [&](std::size_t) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // give every worker a job
    std::lock_guard<std::mutex> lock(m);
    ids.insert(std::this_thread::get_id());
  });
  EXPECT_GE(ids.size(), 2u);
  EXPECT_LE(ids.size(), 3u);
}

// A worker's failure reaches the caller once every job has run and every thread has ended: the
// slow jobs after the failing one still finish, none is running when the call returns, and the
// error rethrown is the one of the lowest index, whichever thread met it first.
TEST(ParallelFor, RethrowsTheFirstFailureAfterAllJobsFinished) {
  constexpr std::size_t kJobs = 40;
  std::atomic<int> running{0}, finished{0};
  std::vector<std::atomic<bool>> done(kJobs);
  try {
    lfd::parallelFor(kJobs, 4, [&](std::size_t i) {
      ++running;
      if (i == 7 || i == 3) {
        --running;
        throw std::runtime_error("job " + std::to_string(i));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(i % 5 == 0 ? 20 : 1));
      done[i] = true;
      ++finished;
      --running;
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "job 3");
  }
  EXPECT_EQ(running, 0);
  EXPECT_EQ(finished, static_cast<int>(kJobs) - 2);
  for (std::size_t i = 0; i < kJobs; ++i) EXPECT_EQ(done[i].load(), i != 3 && i != 7) << i;
}

TEST(ParallelFor, ExceptionsOfAnyTypeAndOnOneThread) {
  EXPECT_THROW(lfd::parallelFor(5, 1,
                                [](std::size_t i) {
                                  if (i == 4) throw 42;
                                }),
               int);
  int ran = 0;
  EXPECT_THROW(lfd::parallelFor(5, 1,
                                [&](std::size_t i) {
                                  ++ran;
                                  if (i == 0) throw std::logic_error("first");
                                }),
               std::logic_error);
  EXPECT_EQ(ran, 5);  // the failure stops no other job
}

// Each worker gets its own scratch, reused by all its jobs and never shared between threads.
TEST(ParallelFor, ScratchIsPerWorker) {
  struct Scratch {
    std::atomic<bool> busy{false};
    int jobs = 0;
  };
  std::mutex m;
  std::set<const Scratch*> seen;
  std::atomic<int> total{0}, shared{0};
  lfd::parallelForWithScratch<Scratch>(200, 3, [&](std::size_t, Scratch& s) {
    if (s.busy.exchange(true)) ++shared;
    ++s.jobs;
    ++total;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    {
      std::lock_guard<std::mutex> lock(m);
      seen.insert(&s);
    }
    s.busy = false;
  });
  EXPECT_EQ(shared, 0);
  EXPECT_EQ(total, 200);
  EXPECT_GE(seen.size(), 1u);
  EXPECT_LE(seen.size(), 3u);
}

TEST(ParallelFor, ScratchKeepsItsStateAcrossJobs) {
  std::vector<std::size_t> sizes;
  lfd::parallelForWithScratch<std::vector<int>>(4, 1, [&](std::size_t i, std::vector<int>& s) {
    s.push_back(static_cast<int>(i));
    sizes.push_back(s.size());
  });
  EXPECT_EQ(sizes, (std::vector<std::size_t>{1, 2, 3, 4}));
}

}  // namespace
