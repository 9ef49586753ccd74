#include "lfd_dmp/execution_monitor.hpp"

#include <cstdio>

namespace lfd_dmp {

std::string describeAlarm(const lfd::Deviation& d, const std::vector<PlannedSegment>& segments) {
  char text[512];
  const std::string segment =
      d.segment < segments.size() ? segments[d.segment].name : std::to_string(d.segment);
  std::snprintf(text, sizeof(text),
                "segment '%s' at %.0f%% (%.2f s into the motion): %s measured %.4g, the "
                "demonstrations showed %.4g (anomaly score %.2f)",
                segment.c_str(), 100.0 * d.phase, d.time, d.channel_name.c_str(), d.measured,
                d.expected, d.score);
  return text;
}

ExecutionMonitor::ExecutionMonitor(ros::NodeHandle& nh, lfd::SensorySignature signature)
    : signature_(std::move(signature)), monitor_(signature_) {
  channels_ = std::make_unique<SensorChannels>(
      nh, signature_,
      [this](const ros::Time& stamp, const Eigen::VectorXd& values) { onReading(stamp, values); });
}

void ExecutionMonitor::start(const ExecutionPlan& plan, const ros::Time& t0) {
  if (plan.segments.size() != signature_.segments.size())
    throw std::invalid_argument("the plan has " + std::to_string(plan.segments.size()) +
                                " segments, the sensory signature " +
                                std::to_string(signature_.segments.size()));
  std::lock_guard<std::mutex> lock(mutex_);
  spans_.clear();
  double start = 0.0;
  for (const PlannedSegment& s : plan.segments) {
    spans_.emplace_back(start, start + s.duration);
    start += s.duration;
  }
  t0_ = t0;
  worst_ = lfd::Deviation();
  alarm_.reset();
  monitor_.reset();
  active_ = true;
}

void ExecutionMonitor::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  active_ = false;
}

lfd::Deviation ExecutionMonitor::worst() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return worst_;
}

std::optional<lfd::Deviation> ExecutionMonitor::alarm() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return alarm_;
}

void ExecutionMonitor::onReading(const ros::Time& stamp, const Eigen::VectorXd& values) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_ || stamp < t0_) return;
  const double t = (stamp - t0_).toSec();
  std::size_t s = 0;
  while (s + 1 < spans_.size() && t >= spans_[s].second) ++s;
  if (t >= spans_.back().second) return;  // settling: no demonstration says what comes after
  const auto [begin, end] = spans_[s];
  const lfd::Deviation d = monitor_.observe(s, (t - begin) / (end - begin), t, values);
  if (d.score > worst_.score) worst_ = d;
  if (d.score > 1.0 && !alarm_) alarm_ = d;
}

}  // namespace lfd_dmp
