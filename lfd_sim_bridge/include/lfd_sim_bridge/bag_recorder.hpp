// One demonstration bag: generic (ShapeShifter) messages stamped with their header time, written to
// `<path>.active` and renamed to `<path>` on close, like `rosbag record` does, so a bag that exists
// under its final name is always complete. Crash safety: an existing `.active` (a crashed
// recording, maybe the only copy of a demo) is never opened for writing, and the open chunk is
// closed every `max_unflushed` of bag time, so a kill -9 loses at most about that much data;
// recoverCrashedBag() reindexes what a crash left behind. A live recording holds an exclusive
// flock on its `.active` from before the name appears until after the rename: the lock dies with
// its process, so recovery tells a crashed recording (unlocked) from another recorder's live one.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <lfd_msgs/DemoMetadata.h>
#include <ros/message_event.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <topic_tools/shape_shifter.h>

namespace lfd_sim_bridge {

// Header stamp of a serialized message whose definition starts with a std_msgs/Header field;
// returns false when the type has no leading header (e.g. tf2_msgs/TFMessage).
bool headerStampOf(const topic_tools::ShapeShifter& msg, ros::Time* stamp);

class DemoBag {
 public:
  // Opens `<bag_path>.active` (creating parent folders) and writes `metadata` on /lfd/metadata at
  // `start`. Throws std::runtime_error with the reason when the bag cannot be created.
  DemoBag(const std::string& bag_path, lfd_msgs::DemoMetadata metadata, const ros::Time& start,
          const ros::Duration& max_unflushed = ros::Duration(0.1));
  ~DemoBag();  // closes (and renames) if still open, so no data is lost on error paths

  DemoBag(const DemoBag&) = delete;
  DemoBag& operator=(const DemoBag&) = delete;

  // Writes one message at `stamp`. Messages stamped before the start belong to the previous
  // demonstration and are dropped (returns false).
  bool write(const std::string& topic, const ros::Time& stamp,
             const ros::MessageEvent<const topic_tools::ShapeShifter>& event);

  // Closes the bag and renames `<path>.active` to `<path>`.
  void close();

  const std::string& path() const { return path_; }
  const ros::Time& start() const { return start_; }
  uint64_t messagesWritten() const { return written_; }
  const std::map<std::string, uint64_t>& perTopic() const { return per_topic_; }

 private:
  void releaseLock();

  std::string path_;
  ros::Time start_;
  rosbag::Bag bag_;
  ros::Duration max_unflushed_;
  ros::Time chunk_start_;
  bool open_ = false;
  int lock_fd_ = -1;  // holds the flock on `<path>.active` while it is being recorded
  uint64_t written_ = 0;
  std::map<std::string, uint64_t> per_topic_;
};

// One crashed recording found by recoverCrashedBags.
struct RecoveredBag {
  std::string active;     // the crash's `<name>.bag.active`, now renamed `<name>.bag.crashed`
  std::string recovered;  // `<name>.bag.recovered`: reindexed, readable (empty if it failed)
  std::string error;      // why the reindex failed
};

// `<bag_path>.active` when a crashed recording left it (no live recorder holds its lock): kept
// (renamed `.crashed`, so it is found once) and reindexed with `rosbag reindex` into
// `<bag_path>.recovered`. Neither name ends in .bag, so datasets never count a partial
// demonstration as a complete one. Nothing (no file, or a live recording): std::nullopt.
std::optional<RecoveredBag> recoverCrashedBag(const std::string& bag_path);

// recoverCrashedBag() for every `*.bag.active` in `folder` (the recorder's start-up
// `recovery_folders`); live recordings are left alone.
std::vector<RecoveredBag> recoverCrashedBags(const std::string& folder);

}  // namespace lfd_sim_bridge
