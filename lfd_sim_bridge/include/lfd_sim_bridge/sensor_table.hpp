// The robot's sensor table (lfd::SensorEntry rows of its robot file) bound to the message types the
// bridge publishes: which fields each type has, how many sensors of which dimension fill a field,
// and the order a row's sensors are read in (the message's field order). ROS-free: the ROS side
// (ros/sensor_publishers.cpp) fills messages from a binding without naming a sensor.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"

namespace lfd_sim {

struct FieldLayout {
  std::string name;   // the message field, e.g. force
  int dimension = 0;  // of each sensor feeding it
  bool many = false;  // any number of sensors (touch pads), else exactly one
};

struct MessageLayout {
  std::string type;  // ROS message type, e.g. geometry_msgs/WrenchStamped
  std::vector<FieldLayout> fields;
};

// Every type a sensor row may publish.
const std::vector<MessageLayout>& sensorMessageLayouts();

// One row bound to its message type: the sensors in the layout's field order (what the workcell
// reads, as `group`), and for each field of the layout the range of group.sensors feeding it
// (empty when the row leaves the field out).
struct SensorBinding {
  lfd::SensorEntry entry;
  SensorGroup group;                                              // name: the row's topic
  std::vector<std::pair<std::size_t, std::size_t>> field_ranges;  // parallel to layout fields
  const MessageLayout* layout = nullptr;
};

// Throws std::invalid_argument naming the row (its topic) and the problem: an unknown type or
// field, or a field of one sensor given several.
std::vector<SensorBinding> bindSensorTable(const std::vector<lfd::SensorEntry>& table);

// The groups the workcell reads for `bindings`, in their order.
std::vector<SensorGroup> sensorGroups(const std::vector<SensorBinding>& bindings);

// Each sensor's dimension in the model (`dimension_of`, e.g. WorkcellSim::sensorDimension) must be
// its field's; throws std::invalid_argument naming the row, the field and the sensor.
void checkSensorDimensions(const std::vector<SensorBinding>& bindings,
                           const std::function<int(const std::string&)>& dimension_of);

}  // namespace lfd_sim
