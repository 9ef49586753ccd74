// Runs job(i) for i in [0, count) on up to `threads` threads (<= 0 = all cores; the calling
// thread is one of them). Every job runs; the first failure (by index) is rethrown after all have
// finished, so no thread outlives the call and no error is lost to a race. The suite's one worker
// loop: DTW batches, per-demonstration segmentations and alignments all run through it.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace lfd {

/// parallel_for whose jobs take scratch memory: each worker default-constructs one `Scratch` and
/// passes it to every job(i, scratch) it runs, so buffers are reused across jobs instead of
/// reallocated (DTW's cost matrices). A scratch is never shared by two threads.
template <typename Scratch, typename Job>
void parallelForWithScratch(std::size_t count, int threads, Job job) {
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  auto worker = [&]() {
    Scratch scratch{};
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        job(i, scratch);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(threads), count));
  // The calling thread is one of the workers. A thread that cannot be started leaves its share
  // to the others rather than ending the call with threads still running.
  std::vector<std::thread> pool;
  try {
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  } catch (...) {
  }
  worker();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

template <typename Job>
void parallelFor(std::size_t count, int threads, Job job) {
  struct NoScratch {};
  parallelForWithScratch<NoScratch>(count, threads, [&job](std::size_t i, NoScratch&) { job(i); });
}

}  // namespace lfd
