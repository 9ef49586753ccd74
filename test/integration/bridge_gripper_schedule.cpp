// rostest: stamped gripper commands. A planned motion sends its gripper events ahead of time; the
// bridge must apply each at its stamp on sim time, whatever the wall-clock load (lockstep here).
#include <gtest/gtest.h>
#include <lfd_msgs/GripperCommand.h>
#include <lfd_msgs/ResetSim.h>
#include <lfd_msgs/StepSim.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/SetBool.h>

#include <atomic>
#include <cmath>
#include <mutex>

#include "bridge_test_utils.hpp"

namespace {

using bridge_test::waitFor;

class GripperSchedule : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ros::service::waitForService("/bridge/step", ros::Duration(30.0)));
    std_srvs::SetBool pause;
    pause.request.data = true;
    ASSERT_TRUE(ros::service::call("/bridge/pause", pause));
    state_sub_ = nh_.subscribe("/gripper/state", 100, &GripperSchedule::onState, this);
    ASSERT_TRUE(waitFor([&] { return cmd_.getNumSubscribers() > 0; }, 30.0));
    // The paused bridge publishes at each step, to the subscribers connected by then.
    ASSERT_TRUE(waitFor(
        [&] {
          lfd_msgs::StepSim s;
          s.request.steps = 5;
          ros::service::call("/bridge/step", s);
          ros::WallDuration(0.05).sleep();
          return stamp_ > 0.0;
        },
        20.0))
        << "no /gripper/state";
  }

  // Steps the paused bridge by `seconds` and waits for the state it published at the end.
  double step(double seconds) {
    lfd_msgs::StepSim s;
    s.request.steps = static_cast<uint32_t>(std::lround(seconds * 1000.0));
    EXPECT_TRUE(ros::service::call("/bridge/step", s) && s.response.success);
    const double t = s.response.sim_time;
    EXPECT_TRUE(waitFor([&] { return stamp_ >= t - 1e-9; }, 10.0));
    return t;
  }

  void command(double opening, double effort, double stamp) {
    lfd_msgs::GripperCommand g;
    g.header.stamp = ros::Time(stamp);
    g.position = opening;
    g.max_effort = effort;
    cmd_.publish(g);
    ros::WallDuration(0.2).sleep();  // delivered before the next step (the bridge is paused)
  }

  void onState(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!msg->position.empty()) opening_ = msg->position[0];
    stamp_ = msg->header.stamp.toSec();
  }
  double opening() {
    std::lock_guard<std::mutex> lock(mutex_);
    return opening_;
  }

  ros::NodeHandle nh_;
  ros::Publisher cmd_ = nh_.advertise<lfd_msgs::GripperCommand>("/gripper/command", 10);
  ros::Subscriber state_sub_;
  std::mutex mutex_;
  double opening_ = std::nan("");
  std::atomic<double> stamp_{0.0};
};

TEST_F(GripperSchedule, AStampedCommandTakesEffectAtItsStamp) {
  double t = step(0.0);
  command(0.08, 0.0, 0.0);  // unstamped: at once
  t = step(0.4);
  const double open = opening();
  EXPECT_GT(open, 0.07);
  command(0.0, 20.0, t + 0.5);  // close half a second of sim time from now
  step(0.45);
  EXPECT_NEAR(opening(), open, 1e-3) << "closed before its stamp";
  step(0.25);
  EXPECT_LT(opening(), open - 0.01) << "not closing after its stamp";
}

TEST_F(GripperSchedule, ALaterCommandCancelsThePendingOnesAndAResetClearsThem) {
  double t = step(0.0);
  command(0.08, 0.0, 0.0);
  t = step(0.4);
  const double open = opening();
  command(0.0, 20.0, t + 0.3);  // pending close ...
  command(0.08, 0.0, t);        // ... dropped by a command stamped before it (a stop)
  step(0.6);
  EXPECT_NEAR(opening(), open, 1e-3) << "a cancelled close fired";
  t = step(0.0);
  command(0.0, 20.0, t + 0.3);
  lfd_msgs::ResetSim reset;
  ASSERT_TRUE(ros::service::call("/bridge/reset", reset) && reset.response.success);
  step(0.9);  // the reset posture's half-open gripper (0.06 m), not closed
  EXPECT_GT(opening(), 0.04) << "a close pending before the reset fired";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "bridge_gripper_schedule");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}
