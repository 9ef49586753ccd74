#include "lfd_sim_bridge/sensor_table.hpp"

#include <stdexcept>

namespace lfd_sim {
namespace {

[[noreturn]] void fail(const lfd::SensorEntry& entry, const std::string& what) {
  throw std::invalid_argument("sensor table row " + entry.topic + " (" + entry.type + "): " + what);
}

const MessageLayout& layoutOf(const lfd::SensorEntry& entry) {
  std::string known;
  for (const MessageLayout& layout : sensorMessageLayouts()) {
    if (layout.type == entry.type) return layout;
    known += (known.empty() ? "" : ", ") + layout.type;
  }
  fail(entry, "unknown message type; the bridge publishes " + known);
}

std::string fieldNames(const MessageLayout& layout) {
  std::string names;
  for (const FieldLayout& f : layout.fields) names += (names.empty() ? "" : ", ") + f.name;
  return names;
}

SensorBinding bindRow(const lfd::SensorEntry& entry) {
  SensorBinding b;
  b.entry = entry;
  b.layout = &layoutOf(entry);
  b.group.name = entry.topic;
  for (const auto& [field, sensors] : entry.fields) {
    bool known = false;
    for (const FieldLayout& f : b.layout->fields) known = known || f.name == field;
    if (!known) fail(entry, "no field '" + field + "' (" + fieldNames(*b.layout) + ")");
  }
  for (const FieldLayout& f : b.layout->fields) {
    const std::size_t begin = b.group.sensors.size();
    for (const auto& [field, sensors] : entry.fields) {
      if (field != f.name) continue;
      if (!f.many && sensors.size() != 1)
        fail(entry,
             "field '" + field + "' takes one sensor, not " + std::to_string(sensors.size()));
      b.group.sensors.insert(b.group.sensors.end(), sensors.begin(), sensors.end());
    }
    b.field_ranges.emplace_back(begin, b.group.sensors.size());
  }
  return b;
}

}  // namespace

const std::vector<MessageLayout>& sensorMessageLayouts() {
  static const std::vector<MessageLayout> kLayouts = {
      {"geometry_msgs/WrenchStamped", {{"force", 3, false}, {"torque", 3, false}}},
      {"sensor_msgs/Imu",
       {{"orientation", 4, false},
        {"angular_velocity", 3, false},
        {"linear_acceleration", 3, false}}},
      {"lfd_msgs/Touch", {{"values", 1, true}}}};
  return kLayouts;
}

std::vector<SensorBinding> bindSensorTable(const std::vector<lfd::SensorEntry>& table) {
  std::vector<SensorBinding> bindings;
  for (const lfd::SensorEntry& entry : table) bindings.push_back(bindRow(entry));
  return bindings;
}

std::vector<SensorGroup> sensorGroups(const std::vector<SensorBinding>& bindings) {
  std::vector<SensorGroup> groups;
  for (const SensorBinding& b : bindings) groups.push_back(b.group);
  return groups;
}

void checkSensorDimensions(const std::vector<SensorBinding>& bindings,
                           const std::function<int(const std::string&)>& dimension_of) {
  for (const SensorBinding& b : bindings) {
    for (std::size_t f = 0; f < b.layout->fields.size(); ++f) {
      const FieldLayout& field = b.layout->fields[f];
      for (std::size_t k = b.field_ranges[f].first; k < b.field_ranges[f].second; ++k) {
        const std::string& sensor = b.group.sensors[k];
        const int dim = dimension_of(sensor);
        if (dim != field.dimension)
          fail(b.entry, "field '" + field.name + "' needs a sensor of dimension " +
                            std::to_string(field.dimension) + "; '" + sensor + "' has " +
                            std::to_string(dim));
      }
    }
  }
}

}  // namespace lfd_sim
