#include "lfd_dmp/demo_bag.hpp"

#include <lfd_core/safe_paths.hpp>

#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace lfd_dmp {

DemoRecording readDemoBag(const std::string& path, const DemoBagTopics& topics) {
  rosbag::Bag bag;
  try {
    lfd::checkInputFile(path);  // a FIFO would block bag.open forever
    bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot open bag " + path + ": " + e.what());
  }
  std::vector<double> t;
  std::vector<std::array<double, 7>> poses;
  std::vector<double> grip_t, grip_v;
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{topics.pose, topics.gripper}));
  for (const rosbag::MessageInstance& m : view) {
    if (m.getTopic() == topics.pose) {
      const auto msg = m.instantiate<geometry_msgs::PoseStamped>();
      if (!msg) throw std::runtime_error(path + ": " + topics.pose + " is not geometry_msgs/PoseStamped");
      const double stamp = msg->header.stamp.toSec();
      const auto& p = msg->pose.position;
      const auto& q = msg->pose.orientation;
      const std::array<double, 7> row = {p.x, p.y, p.z, q.w, q.x, q.y, q.z};
      for (double v : row) {
        if (!std::isfinite(v)) {
          throw std::runtime_error(path + ": non-finite pose on " + topics.pose + " at t = " +
                                   std::to_string(stamp));
        }
      }
      if (!t.empty() && stamp <= t.back()) continue;  // duplicate / out-of-order stamp
      t.push_back(stamp);
      poses.push_back(row);
    } else {
      const auto msg = m.instantiate<sensor_msgs::JointState>();
      if (!msg) continue;
      const auto it = std::find(msg->name.begin(), msg->name.end(), topics.gripper_joint);
      if (it == msg->name.end()) continue;
      const size_t i = static_cast<size_t>(it - msg->name.begin());
      if (i >= msg->position.size() || !std::isfinite(msg->position[i])) continue;
      const double stamp = msg->header.stamp.toSec();
      if (!grip_t.empty() && stamp <= grip_t.back()) continue;
      grip_t.push_back(stamp);
      grip_v.push_back(msg->position[i]);
    }
  }
  bag.close();
  if (t.size() < static_cast<size_t>(lfd::kMinDmpSamples)) {
    throw std::runtime_error(path + ": only " + std::to_string(t.size()) + " messages on " +
                             topics.pose);
  }
  DemoRecording rec;
  rec.id = path;
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
