#include "lfd_dmp/demo_bag.hpp"
#include "lfd_dmp/demo_scene.hpp"

#include <lfd_core/io/safe_paths.hpp>
#include <lfd_core/io/stamp_order.hpp>
#include <lfd_core/io/user_text.hpp>
#include <lfd_ros/ros_bag_message.hpp>

#include <geometry_msgs/PoseStamped.h>
#include <lfd_msgs/DemoMetadata.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <vector>

namespace lfd_dmp {
namespace {

void addTransforms(const tf2_msgs::TFMessage& msg, StaticTransforms* tf) {
  for (const geometry_msgs::TransformStamped& t : msg.transforms) {
    const auto& r = t.transform.rotation;
    const auto& p = t.transform.translation;
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.translation() = Eigen::Vector3d(p.x, p.y, p.z);
    const Eigen::Quaterniond q(r.w, r.x, r.y, r.z);
    if (q.norm() < 1e-6) continue;  // not a transform; lookups that need it fail by name
    iso.linear() = q.normalized().toRotationMatrix();
    tf->add(t.header.frame_id, t.child_frame_id, iso);
  }
}

// The metadata's scene in the poses' frame (empty if the bag records none).
std::optional<lfd::Scene> sceneOf(const std::string& path, const std::string& extra_json,
                                  const StaticTransforms& tf, const std::string& pose_frame,
                                  const TransformLookup& fallback) {
  const std::optional<SceneRecord> record = sceneFromMetadata(extra_json);
  if (!record) return std::nullopt;
  if (record->frame == pose_frame || pose_frame.empty()) return record->scene;
  std::string why;
  try {
    return transformScene(record->scene, tf.lookup(pose_frame, record->frame));
  } catch (const std::runtime_error& e) {
    why = e.what();
  }
  if (fallback) {
    try {
      return transformScene(record->scene, fallback(pose_frame, record->frame));
    } catch (const std::runtime_error& e) {
      why += "; tf: " + std::string(e.what());
    }
  }
  throw std::runtime_error(path + ": the scene is in '" + record->frame + "', the poses in '" +
                           pose_frame + "': " + why +
                           " (record /tf_static, config/recorder.yaml, or publish the robot's "
                           "tf: learn.launch runs robot_state_publisher)");
}

// Samples of one topic in the shared timestamp policy's order: by stamp, the first of each stamp
// kept (a DMP needs strictly increasing times), whatever was found reported in `warnings`.
template <typename Row>
void orderByStamp(const std::string& topic, std::vector<double>& stamps, std::vector<Row>& rows,
                  std::vector<std::string>* warnings) {
  lfd::StampReport report;
  const std::vector<size_t> order =
      lfd::orderByStamp(stamps, lfd::DuplicateStamps::kKeepFirst, &report);
  std::vector<double> t;
  std::vector<Row> r;
  t.reserve(order.size());
  r.reserve(order.size());
  for (size_t i : order) t.push_back(stamps[i]), r.push_back(rows[i]);
  stamps = std::move(t);
  rows = std::move(r);
  const std::string warning = lfd::stampWarning(topic, report);
  if (!warning.empty()) warnings->push_back(warning);
}

// What a demo bag holds for the learner, as read (before stamp order).
struct BagContents {
  std::vector<double> t;
  std::vector<std::array<double, 7>> poses;
  std::vector<double> grip_t, grip_v;
  std::string frame, extra_json;
  StaticTransforms tf;
};

void readMessages(rosbag::Bag& bag, const std::string& path, const DemoBagTopics& topics,
                  BagContents* c) {
  std::map<std::string, std::size_t> seen;  // messages per topic, for errors
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{
                             topics.pose, topics.gripper, topics.metadata, topics.tf_static}));
  for (const rosbag::MessageInstance& m : view) {
    const std::size_t index = seen[m.getTopic()]++;
    if (m.getTopic() == topics.metadata) {
      if (const auto meta = lfd::instantiateChecked<lfd_msgs::DemoMetadata>(m, index, path))
        c->extra_json = meta->extra_json;
    } else if (m.getTopic() == topics.tf_static) {
      if (const auto msg = lfd::instantiateChecked<tf2_msgs::TFMessage>(m, index, path)) {
        try {
          addTransforms(*msg, &c->tf);
        } catch (const std::runtime_error& e) {
          throw std::runtime_error(path + ": " + topics.tf_static + ": " + e.what());
        }
      }
    } else if (m.getTopic() == topics.pose) {
      const auto msg = lfd::instantiateChecked<geometry_msgs::PoseStamped>(m, index, path);
      if (!msg)
        throw std::runtime_error(path + ": " + topics.pose + " is not geometry_msgs/PoseStamped");
      const double stamp = msg->header.stamp.toSec();
      const auto& p = msg->pose.position;
      const auto& q = msg->pose.orientation;
      const std::array<double, 7> row = {p.x, p.y, p.z, q.w, q.x, q.y, q.z};
      for (double v : row) {
        if (!std::isfinite(v)) {
          throw std::runtime_error(path + ": non-finite pose on " + topics.pose +
                                   " at t = " + std::to_string(stamp));
        }
      }
      if (c->t.empty()) c->frame = msg->header.frame_id;
      c->t.push_back(stamp);
      c->poses.push_back(row);
    } else {
      const auto msg = lfd::instantiateChecked<sensor_msgs::JointState>(m, index, path);
      if (!msg) continue;
      const auto it = topics.gripper_joint.empty()
                          ? msg->name.begin()
                          : std::find(msg->name.begin(), msg->name.end(), topics.gripper_joint);
      if (it == msg->name.end()) continue;
      const size_t i = static_cast<size_t>(it - msg->name.begin());
      if (i >= msg->position.size() || !std::isfinite(msg->position[i])) continue;
      c->grip_t.push_back(msg->header.stamp.toSec());
      c->grip_v.push_back(msg->position[i]);
    }
  }
}

}  // namespace

DemoRecording readDemoBag(const std::string& path, const DemoBagTopics& topics,
                          const TransformLookup& fallback) {
  rosbag::Bag bag;
  try {
    // Opened once through the file-access layer: a link swapped to a FIFO cannot hang open().
    const lfd::InputFile file = lfd::openInputFile(path);
    bag.open(file.readPath(), rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot open bag " + path + ": " + e.what());
  }
  BagContents c;
  try {
    readMessages(bag, path, topics, &c);
  } catch (const lfd::MismatchedMessage&) {
    throw;
  } catch (const ros::Exception& e) {  // rosbag: a chunk or record that cannot be read
    throw std::runtime_error("cannot read bag " + lfd::quoted(path) +
                             " (truncated or corrupt?): " + e.what());
  }
  bag.close();
  DemoRecording rec;
  orderByStamp(topics.pose, c.t, c.poses, &rec.warnings);
  orderByStamp(topics.gripper, c.grip_t, c.grip_v, &rec.warnings);
  for (std::string& w : rec.warnings) w = path + ": " + w;
  if (c.t.size() < static_cast<size_t>(lfd::kMinDmpSamples)) {
    throw std::runtime_error(path + ": only " + std::to_string(c.t.size()) + " messages on " +
                             topics.pose);
  }
  rec.id = path;
  rec.frame = c.frame;
  if (!c.extra_json.empty()) {
    try {
      rec.scene = sceneOf(path, c.extra_json, c.tf, c.frame, fallback);
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      throw std::runtime_error(what.rfind(path, 0) == 0 ? what : path + ": " + what);
    }
  }
  const Eigen::Index m = static_cast<Eigen::Index>(c.t.size());
  rec.times = Eigen::Map<Eigen::VectorXd>(c.t.data(), m);
  rec.positions.resize(m, 3);
  rec.quaternions.resize(m, 4);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& r = c.poses[static_cast<size_t>(i)];
    rec.positions.row(i) << r[0], r[1], r[2];
    rec.quaternions.row(i) << r[3], r[4], r[5], r[6];
  }
  if (!c.grip_t.empty()) {
    // Linear interpolation onto the pose stamps, held constant outside the gripper's range.
    rec.gripper.resize(m);
    size_t j = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double ti = rec.times[i];
      while (j + 1 < c.grip_t.size() && c.grip_t[j + 1] <= ti) ++j;
      if (ti <= c.grip_t.front()) {
        rec.gripper[i] = c.grip_v.front();
      } else if (j + 1 >= c.grip_t.size()) {
        rec.gripper[i] = c.grip_v.back();
      } else {
        const double a = (ti - c.grip_t[j]) / (c.grip_t[j + 1] - c.grip_t[j]);
        rec.gripper[i] = (1 - a) * c.grip_v[j] + a * c.grip_v[j + 1];
      }
    }
  }
  return rec;
}

}  // namespace lfd_dmp
