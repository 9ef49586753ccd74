#include "lfd_dmp/demo_bag.hpp"
#include "lfd_dmp/demo_scene.hpp"

#include <lfd_core/safe_paths.hpp>
#include <lfd_core/stamp_order.hpp>

#include <geometry_msgs/PoseStamped.h>
#include <lfd_msgs/DemoMetadata.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
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
  std::vector<double> t;
  std::vector<std::array<double, 7>> poses;
  std::vector<double> grip_t, grip_v;
  std::string frame, extra_json;
  StaticTransforms tf;
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{
                             topics.pose, topics.gripper, topics.metadata, topics.tf_static}));
  for (const rosbag::MessageInstance& m : view) {
    if (m.getTopic() == topics.metadata) {
      if (const auto meta = m.instantiate<lfd_msgs::DemoMetadata>()) extra_json = meta->extra_json;
    } else if (m.getTopic() == topics.tf_static) {
      if (const auto msg = m.instantiate<tf2_msgs::TFMessage>()) {
        try {
          addTransforms(*msg, &tf);
        } catch (const std::runtime_error& e) {
          throw std::runtime_error(path + ": " + topics.tf_static + ": " + e.what());
        }
      }
    } else if (m.getTopic() == topics.pose) {
      const auto msg = m.instantiate<geometry_msgs::PoseStamped>();
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
      if (t.empty()) frame = msg->header.frame_id;
      t.push_back(stamp);
      poses.push_back(row);
    } else {
      const auto msg = m.instantiate<sensor_msgs::JointState>();
      if (!msg) continue;
      const auto it = std::find(msg->name.begin(), msg->name.end(), topics.gripper_joint);
      if (it == msg->name.end()) continue;
      const size_t i = static_cast<size_t>(it - msg->name.begin());
      if (i >= msg->position.size() || !std::isfinite(msg->position[i])) continue;
      grip_t.push_back(msg->header.stamp.toSec());
      grip_v.push_back(msg->position[i]);
    }
  }
  bag.close();
  DemoRecording rec;
  orderByStamp(topics.pose, t, poses, &rec.warnings);
  orderByStamp(topics.gripper, grip_t, grip_v, &rec.warnings);
  for (std::string& w : rec.warnings) w = path + ": " + w;
  if (t.size() < static_cast<size_t>(lfd::kMinDmpSamples)) {
    throw std::runtime_error(path + ": only " + std::to_string(t.size()) + " messages on " +
                             topics.pose);
  }
  rec.id = path;
  rec.frame = frame;
  if (!extra_json.empty()) {
    try {
      rec.scene = sceneOf(path, extra_json, tf, frame, fallback);
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      throw std::runtime_error(what.rfind(path, 0) == 0 ? what : path + ": " + what);
    }
  }
  const Eigen::Index m = static_cast<Eigen::Index>(t.size());
  rec.times = Eigen::Map<Eigen::VectorXd>(t.data(), m);
  rec.positions.resize(m, 3);
  rec.quaternions.resize(m, 4);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& r = poses[static_cast<size_t>(i)];
    rec.positions.row(i) << r[0], r[1], r[2];
    rec.quaternions.row(i) << r[3], r[4], r[5], r[6];
  }
  if (!grip_t.empty()) {
    // Linear interpolation onto the pose stamps, held constant outside the gripper's range.
    rec.gripper.resize(m);
    size_t j = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double ti = rec.times[i];
      while (j + 1 < grip_t.size() && grip_t[j + 1] <= ti) ++j;
      if (ti <= grip_t.front()) {
        rec.gripper[i] = grip_v.front();
      } else if (j + 1 >= grip_t.size()) {
        rec.gripper[i] = grip_v.back();
      } else {
        const double a = (ti - grip_t[j]) / (grip_t[j + 1] - grip_t[j]);
        rec.gripper[i] = (1 - a) * grip_v[j] + a * grip_v[j + 1];
      }
    }
  }
  return rec;
}

}  // namespace lfd_dmp
