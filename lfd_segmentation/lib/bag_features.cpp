#include "lfd_segmentation/bag_features.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <lfd_msgs/Touch.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <cmath>

#include <algorithm>
#include <functional>
#include <map>
#include <numeric>
#include <stdexcept>

namespace lfd_segmentation {

namespace {

template <typename Msg>
using FieldMap = std::map<std::string, std::function<double(const Msg&)>>;

#define LFD_FIELD(path, expr)                          \
  {                                                    \
    path, [](const auto& m) { return double(m.expr); } \
  }
// "<vector>/norm" is the magnitude, e.g. the hand's speed, which keeps its shape whatever the
// direction of the motion (pushes toward +x and toward +y look alike).
#define LFD_NORM(path, expr)                                                             \
  {                                                                                      \
    path, [](const auto& m) {                                                            \
      return std::sqrt(m.expr.x * m.expr.x + m.expr.y * m.expr.y + m.expr.z * m.expr.z); \
    }                                                                                    \
  }
#define LFD_XYZ(prefix, expr)                                                                     \
  LFD_FIELD(prefix "/x", expr.x), LFD_FIELD(prefix "/y", expr.y), LFD_FIELD(prefix "/z", expr.z), \
      LFD_NORM(prefix "/norm", expr)

const FieldMap<geometry_msgs::PoseStamped>& pose_fields() {
  static const FieldMap<geometry_msgs::PoseStamped> f{
      LFD_XYZ("pose/position", pose.position), LFD_XYZ("pose/orientation", pose.orientation),
      LFD_FIELD("pose/orientation/w", pose.orientation.w)};
  return f;
}
const FieldMap<geometry_msgs::TwistStamped>& twist_fields() {
  static const FieldMap<geometry_msgs::TwistStamped> f{LFD_XYZ("twist/linear", twist.linear),
                                                       LFD_XYZ("twist/angular", twist.angular)};
  return f;
}
const FieldMap<geometry_msgs::WrenchStamped>& wrench_fields() {
  static const FieldMap<geometry_msgs::WrenchStamped> f{LFD_XYZ("wrench/force", wrench.force),
                                                        LFD_XYZ("wrench/torque", wrench.torque)};
  return f;
}
const FieldMap<sensor_msgs::Imu>& imu_fields() {
  static const FieldMap<sensor_msgs::Imu> f{LFD_XYZ("orientation", orientation),
                                            LFD_FIELD("orientation/w", orientation.w),
                                            LFD_XYZ("angular_velocity", angular_velocity),
                                            LFD_XYZ("linear_acceleration", linear_acceleration)};
  return f;
}
#undef LFD_XYZ
#undef LFD_NORM
#undef LFD_FIELD

template <typename Msg>
double stamp_of(const Msg& msg, const rosbag::MessageInstance& m) {
  return msg.header.stamp.isZero() ? m.getTime().toSec() : msg.header.stamp.toSec();
}

std::string feature_name(const std::string& topic, const std::string& field) {
  return topic + (topic.empty() || topic.back() == '/' ? "" : "/") + field;
}

// Fixed-layout messages: each field is a member path.
template <typename Msg>
void read_fixed(rosbag::View& view, const TopicConfig& cfg, const FieldMap<Msg>& fields,
                std::vector<lfd::Stream>& out) {
  std::vector<const std::function<double(const Msg&)>*> getters;
  for (const std::string& field : cfg.fields) {
    auto it = fields.find(field);
    if (it == fields.end()) {
      std::string known;
      for (const auto& [name, _] : fields) known += " " + name;
      throw std::invalid_argument("topic " + cfg.topic + " has no field '" + field +
                                  "' (fields:" + known + ")");
    }
    getters.push_back(&it->second);
    lfd::Stream s;
    s.name = feature_name(cfg.topic, field);
    s.interpolation = cfg.interpolation;
    out.push_back(std::move(s));
  }
  const std::size_t first = out.size() - getters.size();
  for (const rosbag::MessageInstance& m : view) {
    const auto msg = m.instantiate<Msg>();
    if (!msg) continue;
    const double t = stamp_of(*msg, m);
    for (std::size_t k = 0; k < getters.size(); ++k) {
      out[first + k].time.push_back(t);
      out[first + k].values.push_back((*getters[k])(*msg));
    }
  }
}

// Name-indexed messages (JointState arrays, Touch values): fields "<array>/<name>" or "<array>/*".
struct NamedField {
  std::string array;  // position | velocity | effort | values
  std::string name;
};

std::vector<NamedField> expand_named_fields(const TopicConfig& cfg,
                                            const std::vector<std::string>& arrays,
                                            const std::vector<std::string>& first_names) {
  std::vector<NamedField> fields;
  for (const std::string& field : cfg.fields) {
    const auto slash = field.find('/');
    const std::string array = field.substr(0, slash);
    if (slash == std::string::npos ||
        std::find(arrays.begin(), arrays.end(), array) == arrays.end()) {
      std::string known;
      for (const std::string& a : arrays) known += " " + a + "/<name>";
      throw std::invalid_argument("topic " + cfg.topic + ": bad field '" + field + "' (expected" +
                                  known + ")");
    }
    const std::string name = field.substr(slash + 1);
    if (name == "*") {
      for (const std::string& n : first_names) fields.push_back({array, n});
    } else {
      fields.push_back({array, name});
    }
  }
  return fields;
}

std::vector<lfd::Stream> read_named_topic(rosbag::View& view, const TopicConfig& cfg,
                                          const std::string& datatype) {
  const bool joints = datatype == "sensor_msgs/JointState";
  const std::vector<std::string> arrays =
      joints ? std::vector<std::string>{"position", "velocity", "effort"}
             : std::vector<std::string>{"values"};
  // Names of the first message resolve the "*" fields.
  std::vector<std::string> first_names;
  for (const rosbag::MessageInstance& m : view) {
    if (joints) {
      if (auto msg = m.instantiate<sensor_msgs::JointState>()) {
        first_names = msg->name;
        break;
      }
    } else if (auto msg = m.instantiate<lfd_msgs::Touch>()) {
      first_names = msg->names;
      break;
    }
  }
  const std::vector<NamedField> fields = expand_named_fields(cfg, arrays, first_names);
  std::vector<lfd::Stream> streams(fields.size());
  for (std::size_t k = 0; k < fields.size(); ++k) {
    streams[k].name = feature_name(cfg.topic, fields[k].array + "/" + fields[k].name);
    streams[k].interpolation = cfg.interpolation;
  }
  auto add = [&](double t, const std::vector<std::string>& names,
                 const std::function<const std::vector<double>*(const std::string&)>& array) {
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const auto it = std::find(names.begin(), names.end(), fields[k].name);
      if (it == names.end()) continue;  // this message does not carry the name
      const std::vector<double>* values = array(fields[k].array);
      const std::size_t index = static_cast<std::size_t>(it - names.begin());
      if (values->size() <= index) continue;  // e.g. an empty effort array
      streams[k].time.push_back(t);
      streams[k].values.push_back((*values)[index]);
    }
  };
  for (const rosbag::MessageInstance& m : view) {
    if (joints) {
      const auto msg = m.instantiate<sensor_msgs::JointState>();
      if (!msg) continue;
      add(stamp_of(*msg, m), msg->name, [&](const std::string& a) {
        return a == "position" ? &msg->position : a == "velocity" ? &msg->velocity : &msg->effort;
      });
    } else {
      const auto msg = m.instantiate<lfd_msgs::Touch>();
      if (!msg) continue;
      add(stamp_of(*msg, m), msg->names, [&](const std::string&) { return &msg->values; });
    }
  }
  for (const lfd::Stream& s : streams) {
    if (s.values.empty()) {
      throw std::invalid_argument("topic " + cfg.topic + " has no data for field '" +
                                  s.name.substr(cfg.topic.size() + 1) + "'");
    }
  }
  return streams;
}

// Messages are stored in receive order; sort each stream by stamp so resampling sees a clock.
void sort_by_time(lfd::Stream& s) {
  if (std::is_sorted(s.time.begin(), s.time.end())) return;
  std::vector<std::size_t> order(s.time.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return s.time[a] < s.time[b]; });
  std::vector<double> t, v;
  for (std::size_t k : order) t.push_back(s.time[k]), v.push_back(s.values[k]);
  s.time = std::move(t);
  s.values = std::move(v);
}

}  // namespace

std::vector<lfd::Stream> read_bag_streams(const std::string& path,
                                          const std::vector<TopicConfig>& topics,
                                          std::vector<FeatureRole>* roles) {
  if (topics.empty()) throw std::invalid_argument("no topics configured for the features");
  std::vector<lfd::Stream> streams;
  if (roles) roles->clear();
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot open bag '" + path + "': " + e.what());
  }
  try {
    for (const TopicConfig& cfg : topics) {
      if (cfg.topic == kGroundTruthTopic) {
        throw std::invalid_argument(std::string(kGroundTruthTopic) +
                                    " is ground truth and is never read by the segmenter");
      }
      rosbag::View view(bag, rosbag::TopicQuery(cfg.topic));
      if (view.size() == 0) {
        std::string available;
        rosbag::View all(bag);
        for (const rosbag::ConnectionInfo* c : all.getConnections()) {
          if (c->topic != kGroundTruthTopic) available += " " + c->topic;
        }
        throw std::invalid_argument("no messages on topic " + cfg.topic +
                                    " (topics in the bag:" + available + ")");
      }
      const std::string datatype = view.getConnections().front()->datatype;
      const std::size_t before = streams.size();
      if (datatype == "geometry_msgs/PoseStamped") {
        read_fixed(view, cfg, pose_fields(), streams);
      } else if (datatype == "geometry_msgs/TwistStamped") {
        read_fixed(view, cfg, twist_fields(), streams);
      } else if (datatype == "geometry_msgs/WrenchStamped") {
        read_fixed(view, cfg, wrench_fields(), streams);
      } else if (datatype == "sensor_msgs/Imu") {
        read_fixed(view, cfg, imu_fields(), streams);
      } else if (datatype == "sensor_msgs/JointState" || datatype == "lfd_msgs/Touch") {
        for (lfd::Stream& s : read_named_topic(view, cfg, datatype))
          streams.push_back(std::move(s));
      } else {
        throw std::invalid_argument("topic " + cfg.topic + " has unsupported type " + datatype);
      }
      if (roles) roles->insert(roles->end(), streams.size() - before, cfg.role);
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("bag '" + path + "': " + e.what());
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read bag '" + path + "' (truncated or corrupt?): " + e.what());
  }
  for (lfd::Stream& s : streams) sort_by_time(s);
  return streams;
}

DemoFeatures read_bag_features(const std::string& path, const std::vector<TopicConfig>& topics,
                               double rate) {
  std::vector<FeatureRole> roles;
  const std::vector<lfd::Stream> streams = read_bag_streams(path, topics, &roles);
  DemoFeatures demo;
  demo.source = path;
  try {
    demo.matrix = lfd::resample(streams, rate);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("bag '" + path + "': " + e.what());
  }
  for (std::size_t k = 0; k < streams.size(); ++k) {
    if (roles[k] == FeatureRole::kSensor) demo.sensor_features.push_back(streams[k].name);
    if (roles[k] == FeatureRole::kState) demo.state_features.push_back(streams[k].name);
    if (roles[k] == FeatureRole::kContext) demo.context_features.push_back(streams[k].name);
  }
  return demo;
}

}  // namespace lfd_segmentation
