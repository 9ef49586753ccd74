// recorder_node: one bag per demonstration. Subscribes generically (ShapeShifter) to the topics of
// config/recorder.yaml and to the robot's sensor topics (the rows of ~robot_file's sensor table,
// at ~sensor_rate) from startup, so no subscription latency is paid when a demo starts, and
// writes them while a recording is active, stamped with their header time (sim time).
//   /recorder/start (lfd_msgs/StartRecording): open <bag_path>.active (inside ~allowed_roots, no
//                   ".."), write metadata first, answer once every topic is linked to each of
//                   its publishers
//   /recorder/stop  (lfd_msgs/StopRecording):  wait for in-flight messages, close, rename
// SIGINT/SIGTERM close the open bag cleanly before the node exits.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <lfd_msgs/StartRecording.h>
#include <lfd_msgs/StopRecording.h>
#include <ros/callback_queue.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <topic_tools/shape_shifter.h>

#include <lfd_core/io/safe_paths.hpp>
#include <lfd_core/kinematics/robot_setup.hpp>
#include <lfd_core/util/heap_trim.hpp>
#include <lfd_ros/ros_request_strings.hpp>

#include "lfd_ros/master_watch.hpp"
#include "lfd_sim_bridge/bag_recorder.hpp"
#include "lfd_sim_bridge/topic_connections.hpp"

namespace {

std::atomic<bool> g_signalled{false};
void onSignal(int) {
  g_signalled = true;
}

struct TopicSpec {
  std::string name;
  double rate = 0.0;  // expected rate (Hz, sim time); 0 = event-driven
};

std::vector<TopicSpec> loadTopics(ros::NodeHandle& pnh) {
  XmlRpc::XmlRpcValue list;
  if (!pnh.getParam("topics", list) || list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    throw std::runtime_error("~topics must be a list of {name, rate} (see config/recorder.yaml)");
  std::vector<TopicSpec> topics;
  for (int i = 0; i < list.size(); ++i) {
    XmlRpc::XmlRpcValue& entry = list[i];
    TopicSpec spec;
    if (entry.getType() == XmlRpc::XmlRpcValue::TypeString) {
      spec.name = static_cast<std::string>(entry);
    } else if (entry.getType() == XmlRpc::XmlRpcValue::TypeStruct && entry.hasMember("name")) {
      spec.name = static_cast<std::string>(entry["name"]);
      if (entry.hasMember("rate")) {
        XmlRpc::XmlRpcValue& r = entry["rate"];
        spec.rate = r.getType() == XmlRpc::XmlRpcValue::TypeInt ? static_cast<int>(r)
                                                                : static_cast<double>(r);
      }
    } else {
      throw std::runtime_error("~topics[" + std::to_string(i) + "] needs a 'name'");
    }
    topics.push_back(spec);
  }
  return topics;
}

// The robot's sensor topics, named once, in its robot file (~robot_file; "" = none): each row
// of the sensor table at ~sensor_rate, the rate its driver publishes them at.
void addSensorTopics(ros::NodeHandle& pnh, std::vector<TopicSpec>* topics) {
  const std::string robot_file = pnh.param<std::string>("robot_file", "");
  if (robot_file.empty()) return;
  double rate = 0.0;
  if (!pnh.getParam("sensor_rate", rate) || !(rate >= 0.0))
    throw std::runtime_error("~sensor_rate (Hz of the sensor table's topics, >= 0) is not set");
  for (const lfd::SensorEntry& row : lfd::loadRobotSetup(robot_file).sensors) {
    for (const TopicSpec& spec : *topics)
      if (spec.name == row.topic)
        throw std::runtime_error("~topics lists " + row.topic + ", a row of the sensor table of " +
                                 robot_file + ": name it once");
    topics->push_back({row.topic, rate});
  }
}

class Recorder {
 public:
  Recorder(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
    topics_ = loadTopics(pnh);
    addSensorTopics(pnh, &topics_);
    const int queue_size = pnh.param("queue_size", 100000);
    settle_timeout_ = pnh.param("settle_timeout", 1.0);
    connect_timeout_ = pnh.param("connect_timeout", 5.0);
    max_unflushed_ = pnh.param("max_unflushed_seconds", max_unflushed_);
    paths_.allowed_roots = pnh.param("allowed_roots", paths_.allowed_roots);
    paths_.require_absolute = true;  // the node's working directory is not the caller's
    strings_.max_bytes = static_cast<std::size_t>(std::max(
        0, pnh.param("limits/max_request_string_bytes", static_cast<int>(strings_.max_bytes))));
    strings_.key = "~limits/max_request_string_bytes";
    for (const std::string& folder : pnh.param("recovery_folders", std::vector<std::string>{}))
      reportRecovered(lfd_sim_bridge::recoverCrashedBags(folder));
    for (const TopicSpec& spec : topics_) {
      ros::SubscribeOptions opts;
      // Full callback type: the connection header (latching, callerid) comes with each message.
      opts.initByFullCallbackType<const ros::MessageEvent<const topic_tools::ShapeShifter>&>(
          spec.name, queue_size,
          [this,
           name = spec.name](const ros::MessageEvent<const topic_tools::ShapeShifter>& event) {
            onMessage(name, event);
          });
      opts.transport_hints = ros::TransportHints().tcpNoDelay();
      subscribers_.push_back(nh.subscribe(opts));
    }
    // The services appear only once the subscriptions are connected: clients wait for them.
    waitForConnections(connect_timeout_);
    // Services run on their own thread so /recorder/stop can wait for in-flight messages while the
    // main thread keeps writing them.
    service_nh_.setCallbackQueue(&service_queue_);
    start_srv_ = service_nh_.advertiseService("recorder/start", &Recorder::onStart, this);
    // The newest sim time, read on the service thread: ros::Time::now() is updated on the main
    // queue, behind any backlog of messages, and would stop a bag too early.
    // Relative service names (remappable); /clock is the master-wide sim time.
    clock_sub_ = service_nh_.subscribe("/clock", 10, &Recorder::onClock, this,
                                       ros::TransportHints().tcpNoDelay());
    stop_srv_ = service_nh_.advertiseService("recorder/stop", &Recorder::onStop, this);
    service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
    service_spinner_->start();
    ROS_INFO("recorder: %zu topics, queue %d, services /recorder/start and /recorder/stop",
             topics_.size(), queue_size);
  }

  // Closes the open bag (if any): used on shutdown so that nothing recorded is lost.
  void closeOnShutdown() {
    service_spinner_->stop();
    std::lock_guard<std::mutex> lock(mutex_);
    if (bag_) {
      const std::string path = bag_->path();
      const uint64_t n = bag_->messagesWritten();
      closeLocked();
      ROS_INFO("recorder: shutdown, closed %s (%lu messages)", path.c_str(),
               static_cast<unsigned long>(n));
    }
  }

 private:
  void onMessage(const std::string& topic,
                 const ros::MessageEvent<const topic_tools::ShapeShifter>& event) {
    ros::Time stamp;
    if (!lfd_sim_bridge::headerStampOf(*event.getConstMessage(), &stamp) || stamp.isZero())
      stamp = ros::Time::now();
    const auto& header = event.getConnectionHeader();
    const auto latch = header.find("latching");
    const bool latched = latch != header.end() && latch->second == "1";
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (latched) latched_[topic] = event;
      last_stamp_[topic] = stamp;
      heard_from_[topic].insert(event.getPublisherName());
      if (bag_ && (stop_time_.isZero() || stamp <= stop_time_)) {
        try {
          if (bag_->write(topic, stamp, event)) first_written_.try_emplace(topic, stamp);
        } catch (const std::exception& e) {
          ROS_ERROR_THROTTLE(1.0, "recorder: writing %s failed: %s", topic.c_str(), e.what());
        }
      }
    }
    settled_.notify_all();
  }

  // At start-up, wait (in wall time, bounded) until every topic that the master knows a publisher
  // of has one. Topics nobody publishes yet (e.g. the demonstrator's /lfd/phase when the recorder
  // starts first) are not waited for. A counted publisher may not be sending yet: see
  // waitForPublisherLinks.
  void waitForConnections(double timeout) {
    ros::master::V_TopicInfo advertised;
    if (!ros::master::getTopics(advertised)) return;
    std::set<std::string> published;
    for (const ros::master::TopicInfo& t : advertised) published.insert(t.name);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
    std::vector<std::string> missing;
    do {
      missing.clear();
      for (std::size_t i = 0; i < subscribers_.size(); ++i)
        if (published.count(subscribers_[i].getTopic()) && subscribers_[i].getNumPublishers() == 0)
          missing.push_back(topics_[i].name);
      if (missing.empty()) return;
      ros::WallDuration(0.01).sleep();
    } while (ros::WallTime::now() < deadline && ros::ok());
    ROS_WARN("recorder: no publisher connected after %.1f s on:%s (going on)", timeout,
             joined(missing).c_str());
  }

  // A new bag's periodic topics are each linked to each of their publishers but the node asking
  // for the recording (topic_connections.hpp: roscpp counts a publisher before the publisher has
  // taken the connection, and what it sends in between is lost). Seen on a loaded CI machine:
  // four sensor topics joined a bag 7.5 s of sim time late. A topic is linked once a message came
  // from the publisher, or once the publisher lists the link. Waits at most connect_timeout.
  void waitForPublisherLinks(const std::string& caller) {
    lfd_sim_bridge::PublishersByTopic publishers;
    if (!lfd_sim_bridge::publishersFromMaster(&publishers)) return;
    std::vector<std::string> periodic;
    for (const TopicSpec& spec : topics_)
      if (spec.rate > 0.0) periodic.push_back(spec.name);
    const ros::WallTime wait_start = ros::WallTime::now();
    const ros::WallTime deadline = wait_start + ros::WallDuration(connect_timeout_);
    std::map<std::string, std::set<std::string>> linked;  // topic -> publishers known connected
    std::vector<std::string> awaiting, first_awaiting;
    while (ros::ok()) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const auto& [topic, nodes] : heard_from_)
          linked[topic].insert(nodes.begin(), nodes.end());
      }
      awaiting = lfd_sim_bridge::topicsAwaitingData(periodic, publishers, linked, caller);
      if (awaiting.empty()) {
        if (!first_awaiting.empty())
          ROS_INFO("recorder: waited %.2f s for the links of:%s",
                   (ros::WallTime::now() - wait_start).toSec(), joined(first_awaiting).c_str());
        return;
      }
      if (first_awaiting.empty()) first_awaiting = awaiting;
      const double left = (deadline - ros::WallTime::now()).toSec();
      if (left <= 0.0) break;
      askPublishersForLinks(awaiting, publishers, left, &linked);
      ros::WallDuration(0.01).sleep();
    }
    ROS_WARN("recorder: after %.1f s, still not connected to a publisher of:%s (recording anyway)",
             connect_timeout_, joined(awaiting).c_str());
  }

  static void askPublishersForLinks(const std::vector<std::string>& topics,
                                    const lfd_sim_bridge::PublishersByTopic& publishers,
                                    double timeout,
                                    std::map<std::string, std::set<std::string>>* linked) {
    std::set<std::string> nodes;
    for (const std::string& topic : topics)
      for (const std::string& node : publishers.at(topic)) nodes.insert(node);
    for (const std::string& node : nodes) {
      std::set<std::string> topics_of_node;
      if (!lfd_sim_bridge::topicsLinkedTo(node, ros::this_node::getName(), timeout,
                                          &topics_of_node))
        continue;
      for (const std::string& topic : topics_of_node) (*linked)[topic].insert(node);
    }
  }

  static std::string joined(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names) text += " " + name;
    return text;
  }

  // Logs each recovered crash and returns it as text for the service answer ("" if none).
  static std::string reportRecovered(const std::vector<lfd_sim_bridge::RecoveredBag>& found) {
    std::string text;
    for (const auto& r : found) {
      const std::string line =
          "crashed recording kept as " + r.active +
          (r.recovered.empty() ? " (" + r.error + ")" : ", reindexed into " + r.recovered);
      ROS_WARN("recorder: %s", line.c_str());
      text += "; " + line;
    }
    return text;
  }

  bool onStart(ros::ServiceEvent<lfd_msgs::StartRecording::Request,
                                 lfd_msgs::StartRecording::Response>& event) {
    if (!openBag(event.getRequest(), &event.getResponse())) return true;
    // The bag is open: topics already linked record from its start while the others connect.
    // The caller waits for this answer (a lockstep demonstrator does not step the sim meanwhile).
    waitForPublisherLinks(event.getCallerName());
    return true;
  }

  bool openBag(const lfd_msgs::StartRecording::Request& req,
               lfd_msgs::StartRecording::Response* res) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (bag_) {
      res->success = false;
      res->message = "already recording to " + bag_->path();
      return false;
    }
    const ros::Time start =
        req.metadata.header.stamp.isZero() ? ros::Time::now() : req.metadata.header.stamp;
    std::string recovered;
    try {
      lfd::checkRequestStrings(req, strings_);  // before any work: no 10 MB path echoed
      lfd::checkRequestPath("bag_path", req.bag_path, paths_);
      lfd::checkPathInRoots(req.bag_path, paths_);
      // A crash may have left this very bag's `.active`: keep and reindex it. Only this path, and
      // only when no live recorder holds it (another recorder may be recording next to it).
      if (const auto r = lfd_sim_bridge::recoverCrashedBag(req.bag_path))
        recovered = reportRecovered({*r});
      bag_ = std::make_unique<lfd_sim_bridge::DemoBag>(req.bag_path, req.metadata, start,
                                                       ros::Duration(max_unflushed_));
    } catch (const std::exception& e) {
      res->success = false;
      res->message = e.what() + recovered;
      ROS_ERROR("recorder: %s", e.what());
      return false;
    }
    stop_time_ = ros::Time();
    first_written_.clear();
    // Latched topics (e.g. /tf_static) were sent once, before this demo: repeat them at its start.
    for (const auto& [topic, event] : latched_) bag_->write(topic, start, event);
    res->success = true;
    res->message = "recording " + req.bag_path + recovered;
    ROS_INFO("recorder: start %s at t=%.3f", req.bag_path.c_str(), start.toSec());
    return true;
  }

  bool onStop(lfd_msgs::StopRecording::Request&, lfd_msgs::StopRecording::Response& res) {
    const lfd::TrimHeapOnExit trim;  // the closed bag's buffers go back to the system
    std::unique_lock<std::mutex> lock(mutex_);
    if (!bag_) {
      res.success = false;
      res.message = "not recording";
      return true;
    }
    stop_time_ = std::max(ros::Time::now(), latest_clock_);
    // Messages stamped up to the stop time may still be queued: wait until every topic seen in this
    // bag has delivered past the stop time (or the settle timeout passes, e.g. sim paused).
    if (!settled_.wait_for(lock, std::chrono::duration<double>(settle_timeout_),
                           [this] { return allTopicsPast(stop_time_); }))
      ROS_WARN("recorder: %s", laggingTopics(stop_time_).c_str());
    res.bag_path = bag_->path();
    res.messages_written = bag_->messagesWritten();
    warnAboutRates();
    try {
      closeLocked();
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      return true;
    }
    res.success = true;
    res.message = "closed after " + std::to_string(res.messages_written) + " messages";
    ROS_INFO("recorder: stop %s (%lu messages)", res.bag_path.c_str(),
             static_cast<unsigned long>(res.messages_written));
    return true;
  }

  void onClock(const rosgraph_msgs::Clock::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_clock_ = std::max(latest_clock_, msg->clock);
  }

  // True when no message stamped up to t can still be on its way: each periodic topic has
  // delivered a message less than one period before t (its next one is after t). Event-driven
  // topics (rate 0) give no such guarantee and are not waited for.
  bool allTopicsPast(const ros::Time& t) const {
    for (const TopicSpec& spec : topics_) {
      if (spec.rate <= 0.0 || !bag_->perTopic().count(spec.name)) continue;
      const auto it = last_stamp_.find(spec.name);
      if (it == last_stamp_.end() || it->second + ros::Duration(1.0 / spec.rate) <= t) return false;
    }
    return true;
  }

  std::string laggingTopics(const ros::Time& t) const {
    std::string text = "stopped before every topic reached t=" + std::to_string(t.toSec()) + ":";
    for (const TopicSpec& spec : topics_) {
      if (spec.rate <= 0.0 || !bag_->perTopic().count(spec.name)) continue;
      const auto it = last_stamp_.find(spec.name);
      if (it == last_stamp_.end() || it->second + ros::Duration(1.0 / spec.rate) <= t)
        text += " " + spec.name +
                (it == last_stamp_.end() ? " (none)"
                                         : " (last " + std::to_string(it->second.toSec()) + ")");
    }
    return text;
  }

  void warnAboutRates() const {
    const double duration = (stop_time_ - bag_->start()).toSec();
    if (duration <= 0.5) return;
    for (const TopicSpec& spec : topics_) {
      // A late first message is data lost upstream (e.g. a publisher queue shorter than our lag).
      const auto first = first_written_.find(spec.name);
      if (spec.rate > 0.0 && first != first_written_.end() &&
          (first->second - bag_->start()).toSec() > 2.0 / spec.rate)
        ROS_WARN("recorder: %s began %.3f s after the bag's start: its first messages were lost",
                 spec.name.c_str(), (first->second - bag_->start()).toSec());
      const auto it = bag_->perTopic().find(spec.name);
      const double count = it == bag_->perTopic().end() ? 0.0 : static_cast<double>(it->second);
      if (spec.rate > 0.0 && count < 0.5 * spec.rate * duration)
        ROS_WARN("recorder: %s has %.0f messages over %.2f s, expected ~%.0f", spec.name.c_str(),
                 count, duration, spec.rate * duration);
    }
  }

  void closeLocked() {
    std::unique_ptr<lfd_sim_bridge::DemoBag> bag = std::move(bag_);
    stop_time_ = ros::Time();
    bag->close();
  }

  std::vector<TopicSpec> topics_;
  double settle_timeout_ = 1.0;
  std::vector<ros::Subscriber> subscribers_;
  double connect_timeout_ = 5.0;  // s of wall time: at start-up, and at each start
  double max_unflushed_ = 0.1;    // s of bag time a kill -9 may lose (chunk closed this often)
  lfd::PathPolicy paths_;         // ~allowed_roots of a start's bag_path
  lfd::StringBudget strings_;     // ~limits/max_request_string_bytes of a start's strings
  ros::NodeHandle service_nh_;
  ros::CallbackQueue service_queue_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  ros::ServiceServer start_srv_, stop_srv_;

  std::mutex mutex_;
  std::condition_variable settled_;
  std::unique_ptr<lfd_sim_bridge::DemoBag> bag_;
  ros::Time stop_time_, latest_clock_;
  ros::Subscriber clock_sub_;
  std::map<std::string, ros::Time> last_stamp_;
  std::map<std::string, ros::Time> first_written_;           // per topic, in the open bag
  std::map<std::string, std::set<std::string>> heard_from_;  // topic -> publisher nodes
  std::map<std::string, ros::MessageEvent<const topic_tools::ShapeShifter>> latched_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "recorder", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  ros::NodeHandle nh, pnh("~");
  // A restarted master: the node ends (closing an open bag as on a signal), to be respawned.
  const lfd_ros::MasterWatch master_watch({"/use_sim_time"});
  std::unique_ptr<Recorder> recorder;
  try {
    recorder = std::make_unique<Recorder>(nh, pnh);
  } catch (const std::exception& e) {
    ROS_FATAL("recorder: %s", e.what());
    return 1;
  }
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  while (ros::ok() && !g_signalled) queue->callAvailable(ros::WallDuration(0.05));
  queue->callAvailable();  // messages already received are part of the demonstration: write them
  recorder->closeOnShutdown();
  ros::shutdown();
  return master_watch.exitCode();
}
