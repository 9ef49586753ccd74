// Live execution monitoring (issue 25): every reading of the library's monitored sensors is judged
// against the sensory signature of the segment the motion is in (lfd_core/sensory_signature.hpp),
// at the phase the plan has reached at the reading's stamp. It keeps the worst anomaly score and
// the first alarm (a deviation beyond what the demonstrations showed, lasting the signature's
// persistence); the executor decides what an alarm does (config: stop or report).
#pragma once

#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "lfd_core/sensory_signature.hpp"
#include "lfd_dmp/executor.hpp"
#include "lfd_dmp/sensor_channels.hpp"

namespace lfd_dmp {

/// The alarm as one line: segment, sensor, expected versus measured, when.
std::string describeAlarm(const lfd::Deviation& d, const std::vector<PlannedSegment>& segments);

class ExecutionMonitor {
 public:
  /// Subscribes to the signature's sources. Throws std::invalid_argument when the signature cannot
  /// be read live (no topic per channel).
  ExecutionMonitor(ros::NodeHandle& nh, lfd::SensorySignature signature);

  /// Judges the readings of the motion of `plan` that starts at `t0` (segments in plan order,
  /// as many as the signature's: else std::invalid_argument).
  void start(const ExecutionPlan& plan, const ros::Time& t0);
  void stop();

  /// The worst reading so far (score: sustained deviation / threshold) and the first alarm.
  lfd::Deviation worst() const;
  std::optional<lfd::Deviation> alarm() const;
  /// Sensor data that could not be read ("" = none).
  std::string problem() const { return channels_ ? channels_->problem() : ""; }

 private:
  void onReading(const ros::Time& stamp, const Eigen::VectorXd& values);

  lfd::SensorySignature signature_;
  lfd::SignatureMonitor monitor_;
  std::vector<std::pair<double, double>> spans_;  ///< each segment's [start, end) s of the motion
  ros::Time t0_;
  bool active_ = false;
  lfd::Deviation worst_;
  std::optional<lfd::Deviation> alarm_;
  mutable std::mutex mutex_;
  std::unique_ptr<SensorChannels> channels_;  // last: its callbacks use the members above
};

}  // namespace lfd_dmp
