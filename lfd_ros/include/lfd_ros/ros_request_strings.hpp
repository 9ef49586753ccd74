// The string budget of a ROS request (service request, action goal), for the nodes: every string
// field of the message, found through the message's own definition, so a field added later is
// bounded too: lfd_core's ROS-free budget applied to roscpp's serialization (header-only).
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>

#include <cstdint>
#include <vector>

#include "lfd_core/io/input_budget.hpp"

namespace lfd {

/// Refuses a request one of whose strings is over `budget` (checkMessageStrings), naming the field
/// and the key. Call it before any other work on the request.
template <typename M>
void checkRequestStrings(const M& request, const StringBudget& budget) {
  // The schema of M, parsed once per type from the definition generated with it.
  static const rosmsg::MessageSchema kSchema = rosmsg::MessageSchema::parse(
      ros::message_traits::datatype<M>(), ros::message_traits::definition<M>());
  const std::uint32_t size = ros::serialization::serializationLength(request);
  std::vector<std::uint8_t> bytes(size);
  ros::serialization::OStream out(bytes.data(), size);
  ros::serialization::serialize(out, request);
  checkMessageStrings(kSchema, bytes.data(), bytes.size(), budget);
}

}  // namespace lfd
