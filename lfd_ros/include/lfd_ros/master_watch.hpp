// Every long-running lfd node outlives a restart of the ROS master (round two). roscpp
// registers a node's topics and services once, when they are made: after a restart the node ran on,
// unknown to the new master, never found by a client, and said nothing. The watch notices the
// master going away and another master coming back, says so with ROS_ERROR, and ends the node with
// kMasterRestartedExit; roslaunch's respawn="true" starts it again, and the new process registers
// with the new master.
// roslaunch sets a node's parameters once, on the master of its start, and not again on a respawn:
// before the node ends, the watch puts its private namespace (and the global keys it names, e.g.
// /use_sim_time) back on the new master, where the new master lacks them.
#pragma once

#include <ros/ros.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace lfd_ros {

/// Exit status of a node ended by a master restart: non-zero, so roslaunch reports it as an error
/// (and ends a launch whose node is required="true"; respawn="true" restarts the node).
constexpr int kMasterRestartedExit = 3;

/// Who answers at ROS_MASTER_URI: the master's process id and the run id roscore set (empty
/// before roscore has set it).
struct MasterIdentity {
  int pid = 0;
  std::string run_id;
  /// Another master: another process, or another run id (a master restarted with the same pid).
  bool differsFrom(const MasterIdentity& before) const;
};

/// Watches the master from a thread of its own (a node busy with a long request, or whose global
/// queue a loop of its own serves, is watched all the same). Declare it after ros::init in main()
/// and return exitCode(status) from main(): once the master restarted, ros::ok() turns false.
class MasterWatch {
 public:
  /// `global_params`: global parameters the node reads (set by its launch file, not under its
  /// name), restored with its private ones.
  explicit MasterWatch(std::vector<std::string> global_params = {});
  ~MasterWatch();
  MasterWatch(const MasterWatch&) = delete;
  MasterWatch& operator=(const MasterWatch&) = delete;

  /// The master restarted: the node is shutting down to be respawned.
  bool restarted() const { return restarted_; }
  /// `normal`, or kMasterRestartedExit once the master restarted.
  int exitCode(int normal = 0) const { return restarted_ ? kMasterRestartedExit : normal; }

 private:
  void run();
  void restoreParameters() const;

  MasterIdentity identity_;
  bool known_ = false;  // identity_ is the start's master (asked again until it answers)
  std::vector<std::pair<std::string, XmlRpc::XmlRpcValue>> params_;  // as the node started
  std::atomic<bool> restarted_{false};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace lfd_ros
