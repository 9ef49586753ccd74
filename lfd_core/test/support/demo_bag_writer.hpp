// Writes small synthetic grasp demonstrations as bags with the topics of the DESIGN contract
// (test helper, header-only; also used by test/integration/segmentation_service.cpp).
// Approach phase: the end effector moves with a slow oscillation, gripper open; at the grasp the
// gripper closes, the touch pads and the wrist force step up, and the motion changes texture.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <lfd_msgs/Phase.h>
#include <lfd_msgs/Touch.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "declared_type_bytes.hpp"

namespace lfd_segmentation_test {

struct DemoBagOptions {
  double duration = 8.0;  ///< s
  double grasp_fraction = 0.4;
  double pose_rate = 100.0;   ///< Hz of pose, twist, gripper
  double sensor_rate = 50.0;  ///< Hz of touch and wrist wrench
  unsigned seed = 1;
  double start_time = 100.0;  ///< bag time of the first message (s)
  bool with_touch = true;
  bool nan_in_twist = false;      ///< one NaN sample in /ee_twist
  bool constant_gripper = false;  ///< gripper never moves
  double late_twist_seconds = 0;  ///< > 0: one more /ee_twist stamped this long after the end
  double huge_twist = 0;          ///< != 0: one /ee_twist sample with this (finite) value
  double late_pose_seconds = 0;   ///< > 0: the /ee_pose at a quarter is stamped this late, in place
  bool pose_holds_a_twist = false;  ///< the /ee_pose at half: declared PoseStamped, a twist's bytes
  std::string touch_name = "r_touch_left";
};

/// Grasp time (bag time, s) of a demo written with `o`.
inline double graspTime(const DemoBagOptions& o) {
  return o.start_time + o.grasp_fraction * o.duration;
}

inline void writeDemoBag(const std::string& path, const DemoBagOptions& o = {}) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double grasp = graspTime(o);
  const int samples = static_cast<int>(o.duration * o.pose_rate);
  for (int i = 0; i < samples; ++i) {
    const double t = o.start_time + i / o.pose_rate;
    const ros::Time stamp(t);
    const bool closed = t >= grasp;
    const double u = (t - o.start_time) / o.duration;
    const double phase =
        closed ? (u - o.grasp_fraction) / (1 - o.grasp_fraction) : u / o.grasp_fraction;
    const double speed = std::sin(M_PI * phase) * (closed ? 0.2 : 0.3) +
                         0.05 * std::sin(2 * M_PI * (t - o.start_time) * (closed ? 5.5 : 2.2)) +
                         0.003 * noise(rng);
    geometry_msgs::TwistStamped twist;
    twist.header.stamp = stamp;
    twist.header.frame_id = "base_link";
    twist.twist.linear.x = speed;
    twist.twist.linear.y = 0.5 * speed + 0.01 * noise(rng);
    twist.twist.linear.z = (closed ? 0.1 : 0.0) * std::sin(M_PI * phase) + 0.002 * noise(rng);
    twist.twist.angular.z = 0.01 * noise(rng);
    if (o.nan_in_twist && i == samples / 2)
      twist.twist.linear.x = std::numeric_limits<double>::quiet_NaN();
    if (o.huge_twist != 0 && i == samples / 3) twist.twist.linear.x = o.huge_twist;
    bag.write("/ee_twist", stamp, twist);
    if (o.late_twist_seconds > 0 && i == samples - 1) {
      const ros::Time late(t + o.late_twist_seconds);
      twist.header.stamp = late;
      bag.write("/ee_twist", late, twist);
      twist.header.stamp = stamp;
    }

    geometry_msgs::PoseStamped pose;
    pose.header = twist.header;
    pose.pose.position.x = 0.3 + 0.2 * u + 0.001 * noise(rng);
    pose.pose.position.y = -0.2 + 0.1 * u;
    pose.pose.position.z = 0.8 + (closed ? 0.1 * phase : 0.0);
    pose.pose.orientation.w = 1.0;
    if (o.late_pose_seconds > 0 && i == samples / 4)
      pose.header.stamp = ros::Time(t + o.late_pose_seconds);
    if (o.pose_holds_a_twist && i == samples / 2) {
      lfd_test::writeAsDeclaredType<geometry_msgs::PoseStamped>(bag, "/ee_pose", stamp,
                                                                lfd_test::serializedBytes(twist));
    } else {
      bag.write("/ee_pose", stamp, pose);
    }

    sensor_msgs::JointState gripper;
    gripper.header.stamp = stamp;
    gripper.name = {"R_GRIPPER"};
    const double opening = o.constant_gripper ? 0.08 : (closed ? 0.02 : 0.08);
    gripper.position = {opening + (o.constant_gripper ? 0.0 : 0.0005 * noise(rng))};
    gripper.velocity = {0.0};
    gripper.effort = {closed && !o.constant_gripper ? 5.0 : 0.0};
    bag.write("/gripper/state", stamp, gripper);

    lfd_msgs::Phase truth;  // ground truth: the segmenter must never read it
    truth.header.stamp = stamp;
    truth.task = "grasp";
    truth.name = closed ? "move" : "approach";
    truth.index = closed ? 1 : 0;
    bag.write("/lfd/phase", stamp, truth);
  }
  const int sensor_samples = static_cast<int>(o.duration * o.sensor_rate);
  for (int i = 0; i < sensor_samples; ++i) {
    const double t = o.start_time + i / o.sensor_rate;
    const ros::Time stamp(t);
    const bool closed = t >= grasp;
    geometry_msgs::WrenchStamped wrench;
    wrench.header.stamp = stamp;
    wrench.header.frame_id = "r_wrist_ft";
    wrench.wrench.force.z = (closed ? -3.0 : 0.0) + 0.05 * noise(rng);
    wrench.wrench.torque.x = 0.01 * noise(rng);
    bag.write("/wrist_ft", stamp, wrench);
    if (o.with_touch) {
      lfd_msgs::Touch touch;
      touch.header.stamp = stamp;
      touch.names = {o.touch_name, "r_touch_right"};
      touch.values = {(closed ? 4.0 : 0.0) + 0.02 * noise(rng),
                      (closed ? 3.5 : 0.0) + 0.02 * noise(rng)};
      bag.write("/touch", stamp, touch);
    }
    sensor_msgs::Imu imu;
    imu.header.stamp = stamp;
    imu.orientation.w = 1.0;
    imu.linear_acceleration.z = 9.81 + 0.01 * noise(rng);
    bag.write("/imu", stamp, imu);
  }
  bag.close();
}

}  // namespace lfd_segmentation_test
