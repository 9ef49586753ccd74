#include "lfd_sim_bridge/sensor_publishers.hpp"

#include <geometry_msgs/WrenchStamped.h>
#include <lfd_msgs/Touch.h>
#include <sensor_msgs/Imu.h>

#include <functional>
#include <map>
#include <stdexcept>
#include <string>

namespace lfd_sim_bridge {
namespace {

// The readings of one layout field of a row: its sensors' values, in the table's order.
class FieldValues {
 public:
  FieldValues(const lfd_sim::SensorBinding& b, const lfd_sim::SensorReading& r) : b_(b), r_(r) {}
  // The field's only sensor, or nullptr when the row leaves it out.
  const std::vector<double>* one(std::size_t field) const {
    const auto [begin, end] = b_.field_ranges[field];
    return begin < end ? &r_.values[begin] : nullptr;
  }
  std::vector<std::string> names(std::size_t field) const {
    const auto [begin, end] = b_.field_ranges[field];
    return {r_.sensors.begin() + begin, r_.sensors.begin() + end};
  }
  std::vector<double> firstOfEach(std::size_t field) const {
    std::vector<double> out;
    for (std::size_t k = b_.field_ranges[field].first; k < b_.field_ranges[field].second; ++k)
      out.push_back(r_.values[k].at(0));
    return out;
  }

 private:
  const lfd_sim::SensorBinding& b_;
  const lfd_sim::SensorReading& r_;
};

void toVector3(const std::vector<double>* v, geometry_msgs::Vector3* msg) {
  if (!v) return;  // a field the row leaves out reads zero
  msg->x = (*v)[0];
  msg->y = (*v)[1];
  msg->z = (*v)[2];
}

// Field indices follow sensorMessageLayouts(): force, torque.
void fill(const FieldValues& f, geometry_msgs::WrenchStamped* msg) {
  toVector3(f.one(0), &msg->wrench.force);
  toVector3(f.one(1), &msg->wrench.torque);
}

// orientation (w, x, y, z; identity when left out), angular_velocity, linear_acceleration.
void fill(const FieldValues& f, sensor_msgs::Imu* msg) {
  msg->orientation.w = 1.0;
  if (const std::vector<double>* q = f.one(0)) {
    msg->orientation.w = (*q)[0];
    msg->orientation.x = (*q)[1];
    msg->orientation.y = (*q)[2];
    msg->orientation.z = (*q)[3];
  }
  toVector3(f.one(1), &msg->angular_velocity);
  toVector3(f.one(2), &msg->linear_acceleration);
}

// values: one per touch sensor, named by the sensor.
void fill(const FieldValues& f, lfd_msgs::Touch* msg) {
  msg->names = f.names(0);
  msg->values = f.firstOfEach(0);
}

template <typename Msg>
class TypedSensorPublisher : public SensorPublisher {
 public:
  TypedSensorPublisher(ros::NodeHandle& nh, const lfd_sim::SensorBinding& binding, uint32_t queue)
      : binding_(binding), pub_(nh.advertise<Msg>(binding.entry.topic, queue)) {}

  void publish(const lfd_sim::SensorReading& reading, const ros::Time& stamp) override {
    if (pub_.getNumSubscribers() == 0) return;
    Msg msg;
    msg.header.stamp = stamp;
    msg.header.frame_id = binding_.entry.frame;
    fill(FieldValues(binding_, reading), &msg);
    pub_.publish(msg);
  }

 private:
  lfd_sim::SensorBinding binding_;
  ros::Publisher pub_;
};

using Factory = std::function<std::unique_ptr<SensorPublisher>(
    ros::NodeHandle&, const lfd_sim::SensorBinding&, uint32_t)>;

template <typename Msg>
Factory factory() {
  return [](ros::NodeHandle& nh, const lfd_sim::SensorBinding& b, uint32_t queue) {
    return std::make_unique<TypedSensorPublisher<Msg>>(nh, b, queue);
  };
}

// One entry per type of sensorMessageLayouts().
const std::map<std::string, Factory>& factories() {
  static const std::map<std::string, Factory> kAll = {
      {"geometry_msgs/WrenchStamped", factory<geometry_msgs::WrenchStamped>()},
      {"sensor_msgs/Imu", factory<sensor_msgs::Imu>()},
      {"lfd_msgs/Touch", factory<lfd_msgs::Touch>()}};
  return kAll;
}

}  // namespace

std::vector<std::unique_ptr<SensorPublisher>> makeSensorPublishers(
    ros::NodeHandle& nh, const std::vector<lfd_sim::SensorBinding>& bindings, uint32_t queue_size) {
  std::vector<std::unique_ptr<SensorPublisher>> publishers;
  for (const lfd_sim::SensorBinding& b : bindings) {
    const auto it = factories().find(b.entry.type);
    if (it == factories().end())  // a layout without a publisher: a bug, named
      throw std::logic_error("no publisher for sensor message type " + b.entry.type);
    publishers.push_back(it->second(nh, b, queue_size));
  }
  return publishers;
}

}  // namespace lfd_sim_bridge
