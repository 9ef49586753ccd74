// rostest: unknown joint names, NaN targets, mismatched vector lengths, empty or non-monotonic
// trajectories and NaN gripper commands are rejected as a whole (the robot does not move), each
// kind is reported with ROS_ERROR, and the bridge keeps running and tracking good commands.
#include <gtest/gtest.h>
#include <lfd_msgs/GripperCommand.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <cmath>
#include <limits>
#include <mutex>

#include "bridge_test_utils.hpp"

namespace {

using bridge_test::BridgeProbe;
using bridge_test::waitFor;

constexpr char kJoint[] = "R_SHOULDER_Y";

class ErrorLog {
 public:
  explicit ErrorLog(ros::NodeHandle& nh)
      : sub_(nh.subscribe("/rosout", 1000, &ErrorLog::onLog, this)) {}
  int count(const std::string& fragment) {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const std::string& m : errors_) n += m.find(fragment) != std::string::npos;
    return n;
  }

 private:
  void onLog(const rosgraph_msgs::Log::ConstPtr& msg) {
    if (msg->level != rosgraph_msgs::Log::ERROR || msg->name != "/bridge") return;
    std::lock_guard<std::mutex> lock(mutex_);
    errors_.push_back(msg->msg);
  }
  std::mutex mutex_;
  std::vector<std::string> errors_;
  ros::Subscriber sub_;
};

TEST(BridgeBadCommands, RejectsThemAndKeepsTracking) {
  ros::NodeHandle nh;
  BridgeProbe probe(nh);
  ErrorLog errors(nh);
  ros::Publisher cmd = nh.advertise<sensor_msgs::JointState>("/joint_command", 10);
  ros::Publisher traj_pub = nh.advertise<trajectory_msgs::JointTrajectory>("/joint_trajectory", 10);
  ros::Publisher grip_pub = nh.advertise<lfd_msgs::GripperCommand>("/gripper/command", 10);
  ASSERT_TRUE(waitFor(
      [&] {
        return probe.hasJointStates() && cmd.getNumSubscribers() > 0 &&
               traj_pub.getNumSubscribers() > 0 && grip_pub.getNumSubscribers() > 0;
      },
      30.0));
  ros::WallDuration(1.0).sleep();  // let /rosout connect so the errors are seen
  const double q0 = probe.position(kJoint);
  const double gripper0 = probe.position("R_GRIPPER");
  const double nan = std::numeric_limits<double>::quiet_NaN();

  // Each bad command also carries a valid entry that would move the joint if applied. Every one
  // is sent three times: ROS may drop the first messages of a new connection.
  trajectory_msgs::JointTrajectory empty;
  empty.joint_names = {kJoint};
  trajectory_msgs::JointTrajectory backwards;
  backwards.joint_names = {kJoint};
  trajectory_msgs::JointTrajectoryPoint p;
  p.positions = {q0 + 0.3};
  p.time_from_start = ros::Duration(1.0);
  backwards.points.push_back(p);
  p.time_from_start = ros::Duration(0.5);
  backwards.points.push_back(p);
  lfd_msgs::GripperCommand grip;
  grip.position = nan;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(bridge_test::sendJointCommand(cmd, {kJoint, "NO_SUCH_JOINT"}, {q0 + 0.3, 0.0}));
    ASSERT_TRUE(bridge_test::sendJointCommand(cmd, {kJoint}, {nan}));
    ASSERT_TRUE(bridge_test::sendJointCommand(cmd, {kJoint, "R_ELBOW_P"}, {q0 + 0.3}));
    ASSERT_TRUE(
        bridge_test::sendJointCommand(cmd, {kJoint}, {std::numeric_limits<double>::infinity()}));
    traj_pub.publish(empty);
    traj_pub.publish(backwards);
    grip_pub.publish(grip);
    ros::WallDuration(0.1).sleep();
  }

  // Nothing moved, and the bridge is alive: time advances.
  const double t = probe.jointStateTime();
  ASSERT_TRUE(probe.waitUntilSimTime(t + 1.0, 20.0)) << "bridge stopped publishing";
  EXPECT_NEAR(probe.position(kJoint), q0, 2e-3);
  EXPECT_NEAR(probe.position("R_GRIPPER"), gripper0, 2e-3);
  EXPECT_TRUE(waitFor([&] { return errors.count("rejected /joint_command") >= 1; }, 10.0));
  EXPECT_TRUE(waitFor([&] { return errors.count("rejected /joint_trajectory") >= 1; }, 10.0));
  EXPECT_TRUE(waitFor([&] { return errors.count("rejected /gripper/command") >= 1; }, 10.0));

  // A good command afterwards is tracked (settled 0.8 s after the motion starts).
  probe.record(kJoint);
  bridge_test::TargetStream stream(cmd, {kJoint}, {q0 - 0.3});
  double t_start = -1.0;
  ASSERT_TRUE(waitFor(
      [&] {
        for (const auto& s : probe.history()) {
          if (std::abs(s.q - q0) > 1e-3) {
            t_start = s.t;
            return true;
          }
        }
        return false;
      },
      30.0))
      << "the good command was not tracked";
  ASSERT_TRUE(probe.waitUntilSimTime(t_start + 1.5, 20.0));
  int checked = 0;
  for (const auto& s : probe.history()) {
    if (s.t < t_start + 0.8) continue;
    ++checked;
    EXPECT_NEAR(s.q, q0 - 0.3, 2e-3) << "t=" << s.t;
  }
  EXPECT_GT(checked, 20);
  EXPECT_EQ(probe.clockViolations(), 0);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "bridge_bad_commands_test");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
