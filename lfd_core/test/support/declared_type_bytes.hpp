// Test helper for bag readers (ROS packages' tests): writes a message whose connection declares
// type M (its datatype, md5 and full definition, as a recorder would) but whose bytes are any
// given ones, e.g. those of another type or a truncated message. rosbag reads such a message back
// as an M and roscpp fails on it with "Buffer Overrun".
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <topic_tools/shape_shifter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace lfd_test {

template <typename M>
void writeAsDeclaredType(rosbag::Bag& bag, const std::string& topic, const ros::Time& t,
                         std::vector<std::uint8_t> bytes) {
  topic_tools::ShapeShifter shape;
  shape.morph(ros::message_traits::md5sum<M>(), ros::message_traits::datatype<M>(),
              ros::message_traits::definition<M>(), "");
  ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  shape.read(in);
  bag.write(topic, t, shape);
}

/// The serialized bytes of `msg`.
template <typename M>
std::vector<std::uint8_t> serializedBytes(const M& msg) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(msg));
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(out, msg);
  return bytes;
}

}  // namespace lfd_test
