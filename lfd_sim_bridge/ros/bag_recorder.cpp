#include "lfd_sim_bridge/bag_recorder.hpp"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <ros/serialization.h>

namespace lfd_sim_bridge {
namespace {

// First field line of a ROS message definition (comments and blank lines skipped).
std::string firstFieldLine(const std::string& definition) {
  std::istringstream in(definition);
  std::string line;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos) continue;
    return line.substr(begin);
  }
  return "";
}

bool startsWithHeader(const std::string& definition) {
  std::istringstream fields(firstFieldLine(definition));
  std::string type, name;
  fields >> type >> name;
  return (type == "Header" || type == "std_msgs/Header") && name == "header";
}

}  // namespace

bool headerStampOf(const topic_tools::ShapeShifter& msg, ros::Time* stamp) {
  // std_msgs/Header serializes as uint32 seq, uint32 sec, uint32 nsec: the stamp is bytes 4..11.
  if (!startsWithHeader(msg.getMessageDefinition()) || msg.size() < 12) return false;
  std::vector<uint8_t> buffer(msg.size());
  ros::serialization::OStream out(buffer.data(), buffer.size());
  msg.write(out);
  uint32_t sec = 0, nsec = 0;
  std::memcpy(&sec, buffer.data() + 4, 4);
  std::memcpy(&nsec, buffer.data() + 8, 4);
  *stamp = ros::Time(sec, nsec);
  return true;
}

DemoBag::DemoBag(const std::string& bag_path, lfd_msgs::DemoMetadata metadata,
                 const ros::Time& start)
    : path_(bag_path), start_(start) {
  namespace fs = std::filesystem;
  if (bag_path.empty() || fs::path(bag_path).is_relative())
    throw std::runtime_error("bag path must be absolute, got '" + bag_path + "'");
  if (fs::path(bag_path).extension() != ".bag")
    throw std::runtime_error("bag path must end in .bag, got '" + bag_path + "'");
  std::error_code ec;
  fs::create_directories(fs::path(bag_path).parent_path(), ec);
  if (ec) throw std::runtime_error("cannot create folder for '" + bag_path + "': " + ec.message());
  if (fs::exists(bag_path)) throw std::runtime_error("bag '" + bag_path + "' already exists");
  try {
    bag_.open(bag_path + ".active", rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot open '" + bag_path + ".active': " + e.what());
  }
  open_ = true;
  if (metadata.header.stamp.isZero()) metadata.header.stamp = start;
  // One nanosecond before the start: readers order by time, and a sample stamped exactly at the
  // start must not come before the metadata.
  const ros::Time meta_time = start > ros::Time(0, 1) ? start - ros::Duration(0, 1) : start;
  bag_.write("/lfd/metadata", meta_time, metadata);
  ++written_;
  ++per_topic_["/lfd/metadata"];
}

DemoBag::~DemoBag() {
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[recorder] closing %s failed: %s\n", path_.c_str(), e.what());
  }
}

bool DemoBag::write(const std::string& topic, const ros::Time& stamp,
                    const ros::MessageEvent<const topic_tools::ShapeShifter>& event) {
  if (!open_ || stamp < start_) return false;
  bag_.write(topic, stamp, event.getConstMessage(), event.getConnectionHeaderPtr());
  ++written_;
  ++per_topic_[topic];
  return true;
}

void DemoBag::close() {
  if (!open_) return;
  open_ = false;
  bag_.close();
  if (std::rename((path_ + ".active").c_str(), path_.c_str()) != 0)
    throw std::runtime_error("cannot rename '" + path_ + ".active' to '" + path_ + "'");
}

}  // namespace lfd_sim_bridge
