// Test helper: a symlink swapped between a regular file and a FIFO while a reader
// opens it again and again. A reader that checks the path and then opens it by name can open the
// FIFO and block in open() forever; the watchdog notices a call running over `hang_seconds`,
// opens the FIFO for writing (which lets the blocked open() return) and reports the hang.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>

namespace lfd_test {

struct LinkSwapRaceResult {
  int calls = 0;       ///< reader calls made
  int hung_calls = 0;  ///< calls that blocked over hang_seconds (a FIFO opened by name)
  int read_calls = 0;  ///< calls that returned normally (the regular file was read)
};

/// Runs `read(link)` for `seconds` of wall time while another thread swaps `link` between
/// `file` and a FIFO made at `fifo`. Exceptions from `read` (a refusal) count as calls.
inline LinkSwapRaceResult raceLinkSwap(const std::string& link, const std::string& file,
                                       const std::string& fifo,
                                       const std::function<void(const std::string&)>& read,
                                       double seconds = 2.0, double hang_seconds = 1.0) {
  using Clock = std::chrono::steady_clock;
  ::mkfifo(fifo.c_str(), 0600);
  std::remove(link.c_str());
  ::symlink(file.c_str(), link.c_str());
  std::atomic<bool> stop{false};
  std::thread swapper([&] {  // rename() replaces the link atomically: it always exists
    const std::string temp = link + ".swap";
    for (bool to_fifo = true; !stop; to_fifo = !to_fifo) {
      std::remove(temp.c_str());
      ::symlink((to_fifo ? fifo : file).c_str(), temp.c_str());
      std::rename(temp.c_str(), link.c_str());
    }
  });
  std::atomic<long long> call_started{0};  // ns since epoch of the running call, 0 = none
  std::atomic<int> hung{0};
  std::thread watchdog([&] {
    while (!stop) {
      const long long started = call_started;
      const long long now = Clock::now().time_since_epoch().count();
      if (started != 0 && now - started > static_cast<long long>(hang_seconds * 1e9)) {
        const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // lets the blocked open go
        if (fd >= 0) {
          ::close(fd);
          ++hung;
          call_started = 0;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  LinkSwapRaceResult result;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    call_started = Clock::now().time_since_epoch().count();
    try {
      read(link);
      ++result.read_calls;
    } catch (const std::exception&) {
    }
    call_started = 0;
    ++result.calls;
  }
  stop = true;
  swapper.join();
  watchdog.join();
  result.hung_calls = hung;
  std::remove((link + ".swap").c_str());
  std::remove(link.c_str());
  std::remove(fifo.c_str());
  return result;
}

}  // namespace lfd_test
