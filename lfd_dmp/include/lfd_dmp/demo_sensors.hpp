// The sensors a demonstration bag recorded, for the sensory signature: the topics the
// segmentation's topic list marks `monitor` (a gripper's opening, a wrist F/T, touch pads), read
// and resampled by the segmentation's own bag reader, so that the monitor sees the very features
// the segmentation saw.
#pragma once

#include <string>
#include <vector>

#include "lfd_dmp/skill_learner.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

namespace lfd_dmp {

struct MonitoredSensors {
  std::vector<lfd_segmentation::TopicConfig> topics;  ///< those marked monitor
  double rate = 50.0;                                 ///< Hz, the segmentation's clock
  lfd_segmentation::RequestLimits limits;
};

/// The monitored topics of a segmentation parameter file (config/segmentation.yaml or a robot's
/// --topics file). Throws std::invalid_argument for an unreadable file or bad parameters.
MonitoredSensors loadMonitoredSensors(const std::string& params_file);

/// Reads `bag`'s monitored sensors into `demo->sensors` / `sensor_sources`. A bag that lacks one
/// of them (or has unreadable sensor data) keeps no sensors and gets a warning: the demo still
/// teaches its motion, it only stays out of the signature.
void readDemoSensors(const std::string& bag, const MonitoredSensors& sensors, DemoRecording* demo);

}  // namespace lfd_dmp
