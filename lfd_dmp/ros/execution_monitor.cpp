#include "lfd_dmp/execution_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace lfd_dmp {

namespace {

// "segment '<name>' at <phase>% (<t> s into the motion): " -- where every alarm happened.
std::string where(std::size_t segment, double phase, double time,
                  const std::vector<PlannedSegment>& segments) {
  char text[256];
  const std::string name =
      segment < segments.size() ? segments[segment].name : std::to_string(segment);
  std::snprintf(text, sizeof(text),
                "segment '%s' at %.0f%% (%.2f s into the motion): ", name.c_str(), 100.0 * phase,
                time);
  return text;
}

}  // namespace

std::string describeAlarm(const lfd::Deviation& d, const std::vector<PlannedSegment>& segments) {
  char text[384];
  std::snprintf(text, sizeof(text),
                "%s measured %.4g, the demonstrations showed %.4g (anomaly score %.2f)",
                d.channel_name.c_str(), d.measured, d.expected, d.score);
  return where(d.segment, d.phase, d.time, segments) + text;
}

std::string describeSilence(const Silence& s, const std::vector<PlannedSegment>& segments) {
  char text[384];
  std::snprintf(text, sizeof(text),
                "%s silent for %.3f s (allowed %.3f s; its messages came every %.4f s)",
                s.topic.c_str(), s.gap, s.allowed, s.period);
  return where(s.segment, s.phase, s.time, segments) + text;
}

std::string describeFrozen(const Frozen& f, const std::vector<PlannedSegment>& segments) {
  char text[384];
  std::snprintf(text, sizeof(text),
                "%s frozen: the same readings for %.3f s (allowed %.3f s): its sensors say nothing "
                "about the world",
                f.topic.c_str(), f.unchanged, f.allowed);
  return where(f.segment, f.phase, f.time, segments) + text;
}

ExecutionMonitor::ExecutionMonitor(ros::NodeHandle& nh, lfd::SensorySignature signature,
                                   double max_silence, double min_wall_silence, double max_frozen)
    : signature_(std::move(signature)),
      max_silence_(max_silence),
      min_wall_silence_(min_wall_silence),
      max_frozen_(max_frozen),
      monitor_(signature_) {
  if (!(max_frozen > 0) || !std::isfinite(max_frozen))
    throw std::invalid_argument("max_frozen must be finite and > 0");
  if (!(max_silence > 0) || !std::isfinite(max_silence))
    throw std::invalid_argument("max_silence must be finite and > 0");
  if (!(min_wall_silence >= 0) || !std::isfinite(min_wall_silence))
    throw std::invalid_argument("min_wall_silence must be finite and >= 0");
  channels_ = std::make_unique<SensorChannels>(
      nh, signature_,
      [this](const ros::Time& stamp, const Eigen::VectorXd& values) { onReading(stamp, values); });
}

void ExecutionMonitor::start(const ExecutionPlan& plan, const ros::Time& t0) {
  auto spans = spansOf(plan);
  std::lock_guard<std::mutex> lock(mutex_);
  spans_ = std::move(spans);
  t0_ = t0;
  worst_ = lfd::Deviation();
  alarm_.reset();
  latest_alarm_.reset();
  monitor_.start();  // this run's first readings are its rest levels
  active_ = true;
}

void ExecutionMonitor::retime(const ExecutionPlan& plan) {
  auto spans = spansOf(plan);
  std::lock_guard<std::mutex> lock(mutex_);
  spans_ = std::move(spans);
}

std::vector<std::pair<double, double>> ExecutionMonitor::spansOf(const ExecutionPlan& plan) const {
  if (plan.segments.size() != signature_.segments.size())
    throw std::invalid_argument("the plan has " + std::to_string(plan.segments.size()) +
                                " segments, the sensory signature " +
                                std::to_string(signature_.segments.size()));
  std::vector<std::pair<double, double>> spans;
  double start = 0.0;
  for (const PlannedSegment& s : plan.segments) {
    spans.emplace_back(start, start + s.duration);
    start += s.duration;
  }
  return spans;
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

std::optional<lfd::Deviation> ExecutionMonitor::takeLatestAlarm() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<lfd::Deviation> out;
  out.swap(latest_alarm_);
  return out;
}

std::pair<std::size_t, double> ExecutionMonitor::segmentAt(double t) const {
  std::size_t s = 0;
  while (s + 1 < spans_.size() && t >= spans_[s].second) ++s;
  const auto [begin, end] = spans_[s];
  return {s, (t - begin) / (end - begin)};
}

std::optional<Silence> ExecutionMonitor::silence(const ros::Time& now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_ || now < t0_ || spans_.empty()) return std::nullopt;
  const double t = (now - t0_).toSec();
  if (t >= spans_.back().second) return std::nullopt;
  const auto [segment, phase] = segmentAt(t);
  std::optional<Silence> worst;
  const ros::WallTime wall_now = ros::WallTime::now();
  for (const SensorChannels::Activity& a : channels_->activity()) {
    if (a.count > 0 && (wall_now - a.arrived).toSec() <= min_wall_silence_) continue;  // alive
    Silence s;
    s.topic = a.topic;
    s.period = a.count > 1 ? (a.last - a.first).toSec() / static_cast<double>(a.count - 1) : 0.0;
    // Ten periods: a stream may be late by a few messages (a lockstep chunk is 50 ms).
    s.allowed = std::max(max_silence_, 10.0 * s.period);
    const ros::Time since = a.count > 0 && a.last > t0_ ? a.last : t0_;
    s.gap = (now - since).toSec();
    if (a.count == 0) s.allowed = std::max(s.allowed, 2.0 * max_silence_);  // no period known yet
    if (s.gap <= s.allowed || (worst && s.gap / s.allowed <= worst->gap / worst->allowed)) continue;
    s.time = t;
    s.segment = segment;
    s.phase = phase;
    worst = s;
  }
  return worst;
}

std::optional<Frozen> ExecutionMonitor::frozen(const ros::Time& now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_ || now < t0_ || spans_.empty()) return std::nullopt;
  const double t = (now - t0_).toSec();
  if (t >= spans_.back().second) return std::nullopt;
  std::optional<Frozen> worst;
  for (const SensorChannels::Activity& a : channels_->activity()) {
    if (a.count < 2 || a.last <= t0_) continue;  // silence() speaks for a stream that stopped
    const double unchanged = (a.last - std::max(a.changed, t0_)).toSec();
    if (unchanged <= max_frozen_ || (worst && unchanged <= worst->unchanged)) continue;
    const auto [segment, phase] = segmentAt(t);
    worst = Frozen{a.topic, unchanged, max_frozen_, segment, phase, t};
  }
  return worst;
}

void ExecutionMonitor::onReading(const ros::Time& stamp, const Eigen::VectorXd& values) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_ || stamp < t0_) return;
  const double t = (stamp - t0_).toSec();
  if (t >= spans_.back().second) return;  // settling: no demonstration says what comes after
  const auto [s, phase] = segmentAt(t);
  const lfd::Deviation d = monitor_.observe(s, phase, t, values);
  if (d.score > worst_.score) worst_ = d;
  if (d.score > 1.0 && !alarm_) alarm_ = d;
  if (d.score > 1.0) latest_alarm_ = d;
}

}  // namespace lfd_dmp
