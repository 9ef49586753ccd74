// A bag message read as its type with its bytes checked first, for the nodes' and tools' bag
// readers: lfd_core's ROS-free message reader applied to rosbag's messages (header-only).
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <rosbag/message_instance.h>
#include <boost/make_shared.hpp>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_core/io/bag_errors.hpp"
#include "lfd_core/io/ros_message_reader.hpp"

namespace lfd {

/// A message whose bytes do not fit its declared type; what() names the file, topic, declared
/// type, index and time (mismatchedMessageError).
struct MismatchedMessage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// `m` as an M, or null when its connection is of another type (as MessageInstance::instantiate).
/// The bytes are checked against M's definition before roscpp deserializes them: a connection
/// header that lies about the type, or a truncated message, made roscpp throw "Buffer Overrun"
/// (or size an array by a corrupt length). `index` counts the topic's messages in the bag and
/// `file` names the bag, for the MismatchedMessage thrown.
template <typename M>
boost::shared_ptr<M> instantiateChecked(const rosbag::MessageInstance& m, std::size_t index,
                                        const std::string& file) {
  const std::string md5 = ros::message_traits::md5sum<M>();
  if (md5 != "*" && m.getMD5Sum() != "*" && m.getMD5Sum() != md5) return nullptr;
  static const rosmsg::MessageSchema kSchema = rosmsg::MessageSchema::parse(
      ros::message_traits::datatype<M>(), ros::message_traits::definition<M>());
  std::vector<std::uint8_t> bytes(m.size());
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  m.write(out);
  auto msg = boost::make_shared<M>();
  try {
    rosmsg::checkMessageBytes(kSchema, bytes.data(), bytes.size());
    ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
    ros::serialization::deserialize(in, *msg);
  } catch (const std::exception& e) {
    throw MismatchedMessage(mismatchedMessageError(file, m.getTopic(), m.getDataType(), index,
                                                   m.getTime().toSec(), e.what()));
  }
  return msg;
}

}  // namespace lfd
