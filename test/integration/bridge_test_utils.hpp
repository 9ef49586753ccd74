// Shared by the bridge_* rostests: a probe that records what the bridge publishes (on sim time)
// and small wait helpers with wall-clock timeouts, so a dead bridge fails a test instead of
// hanging it. The test's main() must run a ros::AsyncSpinner.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace bridge_test {

// Polls `done` until true or `timeout` wall seconds pass.
inline bool waitFor(const std::function<bool()>& done, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    if (done()) return true;
    ros::WallDuration(0.002).sleep();
  }
  return done();
}

struct Sample {
  double t;
  double q;
};

class BridgeProbe {
 public:
  explicit BridgeProbe(ros::NodeHandle& nh) {
    joint_sub_ = nh.subscribe("/joint_states", 1000, &BridgeProbe::onJoints, this);
    clock_sub_ = nh.subscribe("/clock", 1000, &BridgeProbe::onClock, this);
    for (const std::string& object : {"stick", "box"}) {
      object_subs_.push_back(nh.subscribe<geometry_msgs::PoseStamped>(
          "/objects/" + object + "/pose", 100,
          [this, object](const geometry_msgs::PoseStamped::ConstPtr& msg) {
            std::lock_guard<std::mutex> lock(mutex_);
            objects_[object] = *msg;
          }));
    }
  }

  // Joint position history of one joint since `record(name)` was called.
  void record(const std::string& joint) {
    std::lock_guard<std::mutex> lock(mutex_);
    recorded_joint_ = joint;
    history_.clear();
  }
  std::vector<Sample> history() {
    std::lock_guard<std::mutex> lock(mutex_);
    return history_;
  }
  bool hasJointStates() {
    std::lock_guard<std::mutex> lock(mutex_);
    return !latest_.name.empty();
  }
  double position(const std::string& joint) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < latest_.name.size(); ++i) {
      if (latest_.name[i] == joint) return latest_.position[i];
    }
    return std::nan("");
  }
  double jointStateTime() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_.header.stamp.toSec();
  }
  double clockTime() {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_clock_;
  }
  int clockViolations() {
    std::lock_guard<std::mutex> lock(mutex_);
    return clock_violations_;
  }
  int clockCount() {
    std::lock_guard<std::mutex> lock(mutex_);
    return clock_count_;
  }
  bool objectPose(const std::string& name, geometry_msgs::PoseStamped* pose) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = objects_.find(name);
    if (it == objects_.end()) return false;
    *pose = it->second;
    return true;
  }
  void forgetObjects() {
    std::lock_guard<std::mutex> lock(mutex_);
    objects_.clear();
  }
  // Waits until joint states stamped at or after sim time t arrive.
  bool waitUntilSimTime(double t, double wall_timeout) {
    return waitFor([&] { return jointStateTime() >= t - 1e-9; }, wall_timeout);
  }

 private:
  void onJoints(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = *msg;
    if (recorded_joint_.empty()) return;
    for (size_t i = 0; i < msg->name.size(); ++i) {
      if (msg->name[i] == recorded_joint_)
        history_.push_back({msg->header.stamp.toSec(), msg->position[i]});
    }
  }
  void onClock(const rosgraph_msgs::Clock::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = msg->clock.toSec();
    if (clock_count_ > 0 && !(t > last_clock_)) ++clock_violations_;
    last_clock_ = t;
    ++clock_count_;
  }

  std::mutex mutex_;
  sensor_msgs::JointState latest_;
  std::string recorded_joint_;
  std::vector<Sample> history_;
  double last_clock_ = 0.0;
  int clock_violations_ = 0, clock_count_ = 0;
  std::map<std::string, geometry_msgs::PoseStamped> objects_;
  ros::Subscriber joint_sub_, clock_sub_;
  std::vector<ros::Subscriber> object_subs_;
};

// Publishes one JointState command once the bridge is subscribed.
inline bool sendJointCommand(ros::Publisher& pub, const std::vector<std::string>& names,
                             const std::vector<double>& positions) {
  if (!waitFor([&] { return pub.getNumSubscribers() > 0; }, 10.0)) return false;
  sensor_msgs::JointState cmd;
  cmd.name = names;
  cmd.position = positions;
  pub.publish(cmd);
  return true;
}

// Streams a joint target (as a teleoperator or the executor does) at 20 Hz wall until destroyed.
// ROS does not guarantee delivery of the first messages on a fresh connection; a stream of
// identical targets is immune to that and is idempotent for the bridge.
class TargetStream {
 public:
  TargetStream(ros::Publisher& pub, const std::vector<std::string>& names,
               const std::vector<double>& positions)
      : thread_([this, &pub, names, positions] {
          while (!stop_ && ros::ok()) {
            sendJointCommand(pub, names, positions);
            ros::WallDuration(0.05).sleep();
          }
        }) {}
  ~TargetStream() {
    stop_ = true;
    thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace bridge_test
