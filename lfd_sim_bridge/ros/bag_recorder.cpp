#include "lfd_sim_bridge/bag_recorder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <ros/serialization.h>

namespace lfd_sim_bridge {
namespace {

constexpr uint32_t kChunkThreshold = 768 * 1024;  // rosbag's default, between forced closes

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
                 const ros::Time& start, const ros::Duration& max_unflushed)
    : path_(bag_path), start_(start), max_unflushed_(max_unflushed), chunk_start_(start) {
  namespace fs = std::filesystem;
  if (bag_path.empty() || fs::path(bag_path).is_relative())
    throw std::runtime_error("bag path must be absolute, got '" + bag_path + "'");
  if (fs::path(bag_path).extension() != ".bag")
    throw std::runtime_error("bag path must end in .bag, got '" + bag_path + "'");
  std::error_code ec;
  fs::create_directories(fs::path(bag_path).parent_path(), ec);
  if (ec) throw std::runtime_error("cannot create folder for '" + bag_path + "': " + ec.message());
  if (fs::exists(bag_path)) throw std::runtime_error("bag '" + bag_path + "' already exists");
  // O_EXCL: rosbag's Write mode truncates, and an existing .active is a crashed recording.
  const std::string active = bag_path + ".active";
  const int fd = ::open(active.c_str(), O_CREAT | O_EXCL | O_WRONLY, 0644);
  if (fd < 0) {
    throw std::runtime_error(errno == EEXIST
                                 ? "'" + active +
                                       "' exists (a crashed recording?); it is kept: "
                                       "choose another bag_path"
                                 : "cannot create '" + active + "': " + std::strerror(errno));
  }
  ::close(fd);
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
  // Closing the chunk writes it to the file (rosbag seeks, which flushes stdio): what a kill -9
  // can lose is the open chunk, so it never spans more than max_unflushed of bag time.
  const bool close_chunk = stamp - chunk_start_ >= max_unflushed_;
  if (close_chunk) bag_.setChunkThreshold(0);
  bag_.write(topic, stamp, event.getConstMessage(), event.getConnectionHeaderPtr());
  if (close_chunk) {
    bag_.setChunkThreshold(kChunkThreshold);
    chunk_start_ = stamp;
  }
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

namespace {

std::string shellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

std::vector<RecoveredBag> recoverCrashedBags(const std::string& folder, const std::string& skip) {
  namespace fs = std::filesystem;
  std::vector<RecoveredBag> found;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    const std::string suffix = ".bag.active";
    if (name.size() <= suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    if (!e.is_regular_file() || e.path().string() == skip) continue;
    RecoveredBag r;
    const std::string bag = e.path().string().substr(0, e.path().string().size() - 7);
    r.active = bag + ".crashed";
    if (fs::exists(r.active) || std::rename(e.path().c_str(), r.active.c_str()) != 0) {
      r.active = e.path().string();
      r.error = "cannot rename it to .crashed; left in place";
      found.push_back(r);
      continue;
    }
    // rosbag reindex rewrites a copy in --output-dir and leaves the crashed file as it is.
    const fs::path work = fs::path(folder) / (".reindex_" + std::to_string(::getpid()));
    fs::create_directories(work, ec);
    const std::string copy = (work / fs::path(r.active).filename()).string();
    const std::string cmd = "rosbag reindex --quiet --output-dir " + shellQuoted(work.string()) +
                            " " + shellQuoted(r.active) + " >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0 && fs::exists(copy)) {
      r.recovered = bag + ".recovered";
      fs::rename(copy, r.recovered, ec);
      if (ec) r.error = "reindexed but cannot move it: " + ec.message(), r.recovered.clear();
    } else {
      r.error = "rosbag reindex failed (is python3-rosbag installed?)";
    }
    fs::remove_all(work, ec);
    found.push_back(r);
  }
  return found;
}

}  // namespace lfd_sim_bridge
