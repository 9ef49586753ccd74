// Live readings of a sensory signature's channels (lfd_core/dmp/sensory_signature.hpp) from topics
// of any message type: one subscription per source topic (topic_tools::ShapeShifter), each
// channel's field read by its path with the publisher's own message definition (lfd_core
// ros_message_reader.hpp), exactly as the learner's bag reader read the demonstrations.
#pragma once

#include <ros/ros.h>
#include <topic_tools/shape_shifter.h>

#include <Eigen/Core>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "lfd_core/dmp/sensory_signature.hpp"
#include "lfd_core/io/ros_message_reader.hpp"

namespace lfd_dmp {

class SensorChannels {
 public:
  /// Called with every channel's latest value (signature order) each time a message arrives, once
  /// every channel has had one; `stamp` is the message's header stamp (its arrival on ros::Time
  /// when it has none).
  using Callback = std::function<void(const ros::Time& stamp, const Eigen::VectorXd& values)>;

  /// Throws std::invalid_argument when a channel has no source topic or its name does not start
  /// with "<source>/".
  SensorChannels(ros::NodeHandle& nh, const lfd::SensorySignature& signature, Callback callback);

  /// Ends every subscription before any member goes: a message of one topic may be in its
  /// callback while another topic's subscription ends (the executor's spinner has 4 threads).
  ~SensorChannels();
  SensorChannels(const SensorChannels&) = delete;
  SensorChannels& operator=(const SensorChannels&) = delete;

  /// The source topics no publisher is connected to yet (roscpp connects in the background: a
  /// motion started before that would lose its first messages).
  std::vector<std::string> unconnected() const;

  /// Each source topic's readable messages: their header stamps (their arrival on ros::Time
  /// when they have none).
  struct Activity {
    std::string topic;
    ros::Time first, last;  ///< zero before the first message
    std::size_t count = 0;
    ros::WallTime arrived;  ///< wall time of the last message's arrival (zero before the first)
    /// The stamp of the last message whose fields differed from the one before it, or were all
    /// zero (an idle contact sensor): a live sensor's noise changes its readings every message, a
    /// frozen driver repeats one.
    ros::Time changed;
  };
  std::vector<Activity> activity() const;

  /// What could not be read so far (a message whose bytes or fields do not fit), "" = nothing.
  std::string problem() const;

 private:
  struct Source {
    std::string topic;
    std::vector<std::string> fields;
    std::vector<std::size_t> channels;  ///< index in the signature of each field
    std::string reader_key;             ///< type + md5 the reader was made for
    std::unique_ptr<lfd::rosmsg::FieldReader> reader;
    std::vector<std::uint8_t> bytes;  ///< the last message, serialized (reused: 200 Hz each)
    ros::Time first, last;            ///< stamps (Activity)
    std::size_t count = 0;
    ros::WallTime arrived;
    std::vector<double> previous;  ///< the last message's fields (Activity::changed)
    ros::Time changed;
    ros::Subscriber subscriber;
  };
  void onMessage(Source* source, const topic_tools::ShapeShifter::ConstPtr& msg);
  void readMessage(Source* source, const topic_tools::ShapeShifter& msg);

  Callback callback_;
  std::vector<std::unique_ptr<Source>> sources_;
  Eigen::VectorXd latest_;
  std::vector<bool> seen_;
  mutable std::mutex mutex_;
  std::string problem_;
};

}  // namespace lfd_dmp
