// One publisher per message type of the sensor table (sensor_table.hpp): each row of the robot
// file becomes a topic of its type, filled from the workcell's readings of the row's sensors.
#pragma once

#include <ros/ros.h>

#include <memory>
#include <vector>

#include "lfd_sim_bridge/sensor_table.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"

namespace lfd_sim_bridge {

class SensorPublisher {
 public:
  virtual ~SensorPublisher() = default;
  // Publishes `reading` (the row's group, stamped `stamp`) if anyone listens.
  virtual void publish(const lfd_sim::SensorReading& reading, const ros::Time& stamp) = 0;
};

// A publisher for each binding, advertised on its row's topic with `queue_size`.
std::vector<std::unique_ptr<SensorPublisher>> makeSensorPublishers(
    ros::NodeHandle& nh, const std::vector<lfd_sim::SensorBinding>& bindings, uint32_t queue_size);

}  // namespace lfd_sim_bridge
