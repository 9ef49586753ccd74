#include "lfd_dmp/demo_sensors.hpp"

#include "lfd_segmentation/bag_features.hpp"

namespace lfd_dmp {

MonitoredSensors loadMonitoredSensors(const std::string& params_file) {
  const lfd_segmentation::SegmentationParams params = lfd_segmentation::loadParamsFile(params_file);
  MonitoredSensors out;
  for (const auto& t : params.topics)
    if (t.monitor) out.topics.push_back(t);
  out.rate = params.rate;
  out.limits = params.limits;
  return out;
}

void readDemoSensors(const std::string& bag, const MonitoredSensors& sensors, DemoRecording* demo) {
  if (sensors.topics.empty()) return;
  try {
    lfd_segmentation::DemoFeatures f =
        lfd_segmentation::readBagFeatures(bag, sensors.topics, sensors.rate, sensors.limits);
    demo->sensor_sources.clear();
    for (const std::string& name : f.matrix.names) {
      std::string source;
      for (const auto& t : sensors.topics)
        if (name.rfind(t.topic + "/", 0) == 0 && t.topic.size() > source.size()) source = t.topic;
      demo->sensor_sources.push_back(source);
    }
    demo->sensors = std::move(f.matrix);
  } catch (const std::exception& e) {
    demo->warnings.push_back(bag + ": no sensors for the sensory signature: " + e.what());
  }
}

}  // namespace lfd_dmp
