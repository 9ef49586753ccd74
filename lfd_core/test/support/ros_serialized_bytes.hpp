// Test helper: builds a message's bytes the way ROS 1 serializes them (little-endian, a uint32
// length before every string and variable array), so readers can be tested on exact buffers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

struct Bytes {
  std::vector<std::uint8_t> data;
  template <typename T>
  Bytes& put(T v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    data.insert(data.end(), p, p + sizeof(T));
    return *this;
  }
  Bytes& str(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    data.insert(data.end(), s.begin(), s.end());
    return *this;
  }
  // std_msgs/Header: seq 0, the stamp, frame "base".
  Bytes& header(std::uint32_t sec, std::uint32_t nsec) {
    return put<std::uint32_t>(0).put(sec).put(nsec).str("base");
  }
};
