#include "lfd_ros/master_watch.hpp"

#include <ros/master.h>

#include <chrono>

namespace lfd_ros {
namespace {

// A restart is noticed within a second; one XML-RPC call a second costs the master nothing.
constexpr std::chrono::milliseconds kPollPeriod{1000};

// One call to the master that never waits for it (roscpp's own calls wait while it is away).
bool callMaster(const std::string& method, XmlRpc::XmlRpcValue args, XmlRpc::XmlRpcValue* payload) {
  XmlRpc::XmlRpcValue result;
  return ros::master::execute(method, args, result, *payload, false);
}

XmlRpc::XmlRpcValue callerArgs() {
  XmlRpc::XmlRpcValue args;
  args[0] = ros::this_node::getName();
  return args;
}

// false while no master answers.
bool askIdentity(MasterIdentity* out) {
  XmlRpc::XmlRpcValue pid;
  if (!callMaster("getPid", callerArgs(), &pid) || pid.getType() != XmlRpc::XmlRpcValue::TypeInt)
    return false;
  out->pid = static_cast<int>(pid);
  XmlRpc::XmlRpcValue args = callerArgs(), run_id;
  args[1] = "/run_id";
  out->run_id.clear();
  if (callMaster("getParam", args, &run_id) && run_id.getType() == XmlRpc::XmlRpcValue::TypeString)
    out->run_id = static_cast<std::string>(run_id);
  return true;
}

bool hasParam(const std::string& key) {
  XmlRpc::XmlRpcValue args = callerArgs(), payload;
  args[1] = key;
  return callMaster("hasParam", args, &payload) &&
         payload.getType() == XmlRpc::XmlRpcValue::TypeBoolean && static_cast<bool>(payload);
}

bool setParam(const std::string& key, const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue args = callerArgs(), payload;
  args[1] = key;
  args[2] = value;
  return callMaster("setParam", args, &payload);
}

}  // namespace

bool MasterIdentity::differsFrom(const MasterIdentity& before) const {
  if (pid != before.pid) return true;
  return !run_id.empty() && !before.run_id.empty() && run_id != before.run_id;
}

MasterWatch::MasterWatch(std::vector<std::string> global_params) {
  known_ = askIdentity(&identity_);  // the master of the node's start
  global_params.push_back(ros::this_node::getName());
  for (const std::string& key : global_params) {
    XmlRpc::XmlRpcValue value;
    if (ros::param::get(key, value)) params_.emplace_back(key, value);
  }
  thread_ = std::thread(&MasterWatch::run, this);
}

MasterWatch::~MasterWatch() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void MasterWatch::run() {
  const std::string node = ros::this_node::getName();
  bool away = false;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!wake_.wait_for(lock, kPollPeriod, [this] { return stopping_; })) {
    MasterIdentity now;
    if (!askIdentity(&now)) {
      if (!away)
        ROS_ERROR(
            "%s: the ROS master at %s stopped answering: this node is unknown to any master "
            "until one comes back (then it ends, for roslaunch to respawn it)",
            node.c_str(), ros::master::getURI().c_str());
      away = true;
      continue;
    }
    if (!known_) {  // the start's master did not answer at once: this one is it
      identity_ = now;
      known_ = true;
      continue;
    }
    if (!now.differsFrom(identity_)) {
      if (away) ROS_WARN("%s: the same ROS master answers again", node.c_str());
      away = false;
      continue;
    }
    ROS_ERROR(
        "%s: the ROS master restarted (pid %d, now %d): it knows none of this node's topics "
        "and services; ending with status %d so that roslaunch (respawn=\"true\") starts "
        "the node again on the new master",
        node.c_str(), identity_.pid, now.pid, kMasterRestartedExit);
    restoreParameters();
    restarted_ = true;
    ros::requestShutdown();
    return;
  }
}

void MasterWatch::restoreParameters() const {
  for (const auto& [key, value] : params_) {
    if (hasParam(key)) continue;  // set on the new master by whoever started it: theirs holds
    if (!setParam(key, value))
      ROS_ERROR("%s: could not put %s back on the new master", ros::this_node::getName().c_str(),
                key.c_str());
  }
}

}  // namespace lfd_ros
