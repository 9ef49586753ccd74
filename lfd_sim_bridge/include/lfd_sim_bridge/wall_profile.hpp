#pragma once
// Where a node's wall time goes, by activity: the demonstrator's per-demo breakdown (service round
// trips, waits, planning) and the bridge's physics vs publishing. bench/pipeline/profile_demo.py
// reads them to find the overhead between simulated steps. Two steady-clock reads per measured
// scope, a few tens of ns: cheap enough to stay on.

#include <chrono>
#include <map>
#include <sstream>
#include <string>

namespace lfd_sim_bridge {

class WallProfile {
 public:
  using Clock = std::chrono::steady_clock;

  // Adds the scope's wall time to `activity` when it ends.
  class Scope {
   public:
    Scope(WallProfile* profile, const char* activity)
        : profile_(profile), activity_(activity), start_(Clock::now()) {}
    ~Scope() {
      if (profile_)
        profile_->add(activity_, std::chrono::duration<double>(Clock::now() - start_).count());
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    WallProfile* profile_;
    const char* activity_;
    Clock::time_point start_;
  };

  Scope measure(const char* activity) { return Scope(this, activity); }
  void add(const std::string& activity, double seconds) {
    seconds_[activity] += seconds;
    ++counts_[activity];
  }
  double total() const {
    double sum = 0.0;
    for (const auto& [activity, s] : seconds_) sum += s;
    return sum;
  }
  const std::map<std::string, double>& seconds() const { return seconds_; }
  const std::map<std::string, long>& counts() const { return counts_; }
  void clear() {
    seconds_.clear();
    counts_.clear();
  }

  // YAML/JSON flow mappings, e.g. {"physics": 1.250, "publishing": 0.500} (ms resolution) and
  // how many times each activity was measured, {"physics": 5000, "publishing": 5000}.
  std::string flowMap() const { return flowMapOf(seconds_, 3); }
  std::string countsFlowMap() const { return flowMapOf(counts_, 0); }

 private:
  template <typename Value>
  static std::string flowMapOf(const std::map<std::string, Value>& values, int decimals) {
    std::ostringstream out;
    out.setf(std::ios::fixed);
    out.precision(decimals);
    out << "{";
    const char* separator = "";
    for (const auto& [activity, value] : values) {
      out << separator << "\"" << activity << "\": " << value;
      separator = ", ";
    }
    out << "}";
    return out.str();
  }

  std::map<std::string, double> seconds_;
  std::map<std::string, long> counts_;
};

}  // namespace lfd_sim_bridge
