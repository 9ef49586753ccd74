#include "lfd_sim_bridge/bag_recorder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
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
#include <lfd_core/io/user_text.hpp>

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

// True when a live recorder holds `active`'s lock (it dies with the process, so a crashed
// recording is never live). Opened without following a link and without blocking.
bool isLive(const std::string& active) {
  const int fd = ::open(active.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return false;
  const bool live = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return live;
}

// Creates `active` already locked (flock, exclusive): the file is made and locked under a temporary
// name, then linked to its name, which fails if it exists (a crashed recording, maybe the only
// copy of a demo, or another recorder's live one: rosbag's Write mode would truncate either).
// Nobody ever sees `active` unlocked while it is being recorded. Returns the locked descriptor.
int createLocked(const std::string& active) {
  std::string temp = active + ".lock.XXXXXX";
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);  // a child (rosbag reindex) gets no lock
  if (fd < 0)
    throw std::runtime_error("cannot create " + lfd::quoted(active) + ": " + std::strerror(errno));
  ::fchmod(fd, 0644);
  const bool locked = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  const bool linked = locked && ::link(temp.c_str(), active.c_str()) == 0;
  const int link_errno = errno;
  ::unlink(temp.c_str());
  if (linked) return fd;
  ::close(fd);
  if (locked && link_errno == EEXIST)
    throw std::runtime_error(
        lfd::quoted(active) + " exists (" +
        (isLive(active) ? "another recorder is recording it" : "a crashed recording") +
        "); it is kept: choose another bag_path");
  throw std::runtime_error("cannot create " + lfd::quoted(active) + ": " +
                           std::strerror(link_errno));
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
    throw std::runtime_error("bag path must be absolute, got " + lfd::quoted(bag_path));
  if (fs::path(bag_path).extension() != ".bag")
    throw std::runtime_error("bag path must end in .bag, got " + lfd::quoted(bag_path));
  std::error_code ec;
  fs::create_directories(fs::path(bag_path).parent_path(), ec);
  if (ec)
    throw std::runtime_error("cannot create folder for " + lfd::quoted(bag_path) + ": " +
                             ec.message());
  if (fs::exists(bag_path))
    throw std::runtime_error("bag " + lfd::quoted(bag_path) + " already exists");
  lock_fd_ = createLocked(bag_path + ".active");
  try {
    bag_.open(bag_path + ".active", rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    ::unlink((bag_path + ".active").c_str());  // empty, and ours: no crash to keep
    releaseLock();
    throw std::runtime_error("cannot open " + lfd::quoted(bag_path + ".active") + ": " + e.what());
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
  releaseLock();
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
  const bool renamed = std::rename((path_ + ".active").c_str(), path_.c_str()) == 0;
  releaseLock();  // after the rename: `.active` is never seen unlocked while it is live
  if (!renamed)
    throw std::runtime_error("cannot rename " + lfd::quoted(path_ + ".active") + " to " +
                             lfd::quoted(path_));
}

void DemoBag::releaseLock() {
  if (lock_fd_ >= 0) ::close(lock_fd_);
  lock_fd_ = -1;
}

namespace {

std::string shellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// `rosbag reindex` of `r->active` (the .crashed file) into `<bag_path>.recovered`; it rewrites a
// copy in --output-dir and leaves the crashed file as it is.
void reindex(const std::string& bag_path, RecoveredBag* r) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path folder = fs::path(bag_path).parent_path();
  const fs::path work = folder / (".reindex_" + std::to_string(::getpid()));
  fs::create_directories(work, ec);
  const std::string copy = (work / fs::path(r->active).filename()).string();
  const std::string cmd = "rosbag reindex --quiet --output-dir " + shellQuoted(work.string()) +
                          " " + shellQuoted(r->active) + " >/dev/null 2>&1";
  if (std::system(cmd.c_str()) == 0 && fs::exists(copy)) {
    r->recovered = bag_path + ".recovered";
    fs::rename(copy, r->recovered, ec);
    if (ec) r->error = "reindexed but cannot move it: " + ec.message(), r->recovered.clear();
  } else {
    r->error = "rosbag reindex failed (is python3-rosbag installed?)";
  }
  fs::remove_all(work, ec);
}

}  // namespace

std::optional<RecoveredBag> recoverCrashedBag(const std::string& bag_path) {
  namespace fs = std::filesystem;
  const std::string active = bag_path + ".active";
  // The lock is taken on the file itself and held while it is renamed: a recorder that starts
  // the same path meanwhile cannot take it (its link() finds the name taken, or it is gone).
  const int fd = ::open(active.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || ::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);  // not a file, or live: another recorder's, left alone
    return std::nullopt;
  }
  RecoveredBag r;
  r.active = bag_path + ".crashed";
  if (fs::exists(r.active) || std::rename(active.c_str(), r.active.c_str()) != 0) {
    ::close(fd);
    r.active = active;
    r.error = "cannot rename it to .crashed; left in place";
    return r;
  }
  ::close(fd);
  reindex(bag_path, &r);
  return r;
}

std::vector<RecoveredBag> recoverCrashedBags(const std::string& folder) {
  namespace fs = std::filesystem;
  std::vector<RecoveredBag> found;
  std::error_code ec;
  const std::string suffix = ".bag.active";
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    const std::string path = e.path().string();
    if (path.size() <= suffix.size() ||
        path.compare(path.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    if (auto r = recoverCrashedBag(path.substr(0, path.size() - 7))) found.push_back(*r);
  }
  return found;
}

}  // namespace lfd_sim_bridge
