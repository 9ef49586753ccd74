// Live execution monitoring: every reading of the library's monitored sensors is judged
// against the sensory signature of the segment the motion is in
// (lfd_core/dmp/sensory_signature.hpp), at the phase the plan has reached at the reading's stamp.
// It keeps the worst anomaly score and the first alarm (a deviation beyond what the demonstrations
// showed, lasting the signature's persistence); the executor decides what an alarm does (config:
// stop or report).
#pragma once

#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lfd_core/dmp/sensory_signature.hpp"
#include "lfd_dmp/executor.hpp"
#include "lfd_dmp/sensor_channels.hpp"

namespace lfd_dmp {

/// The alarm as one line: segment, sensor, expected versus measured, when.
std::string describeAlarm(const lfd::Deviation& d, const std::vector<PlannedSegment>& segments);

/// A source topic that stopped: no message for longer than it may be silent.
struct Silence {
  std::string topic;
  double gap = 0.0;      ///< s since its last message (since the motion start if none came)
  double allowed = 0.0;  ///< s: 10 of its mean periods, at least max_silence
  double period = 0.0;   ///< s between its messages so far (0: fewer than 2)
  std::size_t segment = 0;
  double phase = 0.0, time = 0.0;  ///< where the motion is (s since its start)
};
std::string describeSilence(const Silence& s, const std::vector<PlannedSegment>& segments);

/// A source topic whose readings stopped changing: the same non-zero values in every message for
/// longer than it may be (a stale driver).
struct Frozen {
  std::string topic;
  double unchanged = 0.0;  ///< s since its readings last changed (since the motion start at most)
  double allowed = 0.0;    ///< s
  std::size_t segment = 0;
  double phase = 0.0, time = 0.0;  ///< where the motion is (s since its start)
};
std::string describeFrozen(const Frozen& f, const std::vector<PlannedSegment>& segments);

class ExecutionMonitor {
 public:
  /// Subscribes to the signature's sources. Throws std::invalid_argument when the signature cannot
  /// be read live (no topic per channel).
  /// max_silence: s a source topic may go without a message (at least 10 of its periods).
  /// min_wall_silence: wall s without any message arriving before a source counts as silent. A
  /// simulation stepped many times faster than real time advances its clock by seconds while a
  /// loaded machine delays one subscriber's callbacks by a fraction of a wall second; a stream
  /// that keeps arriving, late, is alive. On a robot (sim time = wall time) max_silence decides.
  /// max_frozen: s a source's readings may repeat exactly (Frozen).
  ExecutionMonitor(ros::NodeHandle& nh, lfd::SensorySignature signature, double max_silence,
                   double min_wall_silence, double max_frozen);

  /// Judges the readings of the motion of `plan` that starts at `t0` (segments in plan order,
  /// as many as the signature's: else std::invalid_argument).
  void start(const ExecutionPlan& plan, const ros::Time& t0);
  /// The running motion was replanned (an object moved): its segments' times from `plan`, what
  /// was judged so far kept.
  void retime(const ExecutionPlan& plan);
  void stop();

  /// The worst reading so far (score: sustained deviation / threshold) and the first alarm.
  lfd::Deviation worst() const;
  std::optional<lfd::Deviation> alarm() const;
  /// The latest reading over its threshold since the previous call (none: every reading since
  /// was within): an alarm raised after the first (a grasp lost after a reported yank) is not
  /// hidden by it, and one that lasted only between two calls is not missed.
  std::optional<lfd::Deviation> takeLatestAlarm();
  /// The source that has been silent the longest beyond what it may be, at `now` during the
  /// motion; none before the start, after the end or while stopped. `now` is best the stamp of
  /// the latest joint state: a loaded machine then delays both alike (the clock would run ahead).
  std::optional<Silence> silence(const ros::Time& now) const;
  /// The source whose readings have repeated exactly the longest beyond max_frozen at `now` (as
  /// silence()). Its sensors then say nothing about the world: an empty hand read on a frozen
  /// sensor is no lost grasp.
  std::optional<Frozen> frozen(const ros::Time& now) const;
  /// The sensor topics not connected yet (SensorChannels::unconnected).
  std::vector<std::string> unconnected() const { return channels_->unconnected(); }
  /// Sensor data that could not be read ("" = none).
  std::string problem() const { return channels_ ? channels_->problem() : ""; }

 private:
  void onReading(const ros::Time& stamp, const Eigen::VectorXd& values);
  /// Each segment's [start, end) s into the motion; checks the count against the signature's.
  std::vector<std::pair<double, double>> spansOf(const ExecutionPlan& plan) const;
  /// The segment of the motion at `t` s from its start and the phase in it (mutex_ held).
  std::pair<std::size_t, double> segmentAt(double t) const;

  lfd::SensorySignature signature_;
  double max_silence_, min_wall_silence_, max_frozen_;
  lfd::SignatureMonitor monitor_;
  std::vector<std::pair<double, double>> spans_;  ///< each segment's [start, end) s of the motion
  ros::Time t0_;
  bool active_ = false;
  lfd::Deviation worst_;
  std::optional<lfd::Deviation> alarm_, latest_alarm_;
  mutable std::mutex mutex_;
  std::unique_ptr<SensorChannels> channels_;  // last: its callbacks use the members above
};

}  // namespace lfd_dmp
