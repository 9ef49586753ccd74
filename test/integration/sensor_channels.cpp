// The executor's live sensor reader (lfd_dmp/sensor_channels.hpp) against a running master: any
// message type read by field path, and a reader destroyed while messages of several topics arrive
// on a multi-threaded spinner (the executor ends one per goal) never touches what it freed. The
// monitor (execution_monitor.hpp) names a source topic that stops during the motion.
#include <geometry_msgs/WrenchStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/Float64MultiArray.h>
#include <lfd_dmp/execution_monitor.hpp>
#include <lfd_dmp/sensor_channels.hpp>

#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <thread>

namespace {

constexpr double kForceZ = 7.5;
constexpr double kLevel = -2.25;

lfd::SensorySignature twoTopics() {
  lfd::SensorySignature s;
  s.channels = {"/channels_test/ft/wrench/force/z", "/channels_test/level/data/1"};
  s.sources = {"/channels_test/ft", "/channels_test/level"};
  return s;
}

// Publishes both topics at ~2 kHz each until destroyed; the F/T stamped ft_lag s in the past, with
// a noise of 1 mN when ft_noise (else exactly kForceZ), the level at level_value.
class Publishers {
 public:
  std::atomic<bool> level_on{true}, ft_on{true}, ft_noise{false};
  std::atomic<double> ft_lag{0.0}, level_value{kLevel};
  Publishers() {
    ros::NodeHandle nh;
    ft_ = nh.advertise<geometry_msgs::WrenchStamped>("/channels_test/ft", 100);
    level_ = nh.advertise<std_msgs::Float64MultiArray>("/channels_test/level", 100);
    thread_ = std::thread([this] {
      geometry_msgs::WrenchStamped w;
      w.wrench.force.z = kForceZ;
      std_msgs::Float64MultiArray a;
      a.data = {0.0, kLevel, 1.0};
      for (int k = 0; !stop_; ++k) {
        w.header.stamp = ros::Time::now() - ros::Duration(ft_lag);
        w.wrench.force.z = kForceZ + (ft_noise ? 1e-3 * (k % 3) : 0.0);
        a.data[1] = level_value;
        if (ft_on) ft_.publish(w);
        if (level_on) level_.publish(a);
        std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
    });
  }
  ~Publishers() {
    stop_ = true;
    thread_.join();
  }

 private:
  ros::Publisher ft_, level_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Readings {
  std::mutex mutex;
  int count = 0;
  int wrong = 0;
  void add(const Eigen::VectorXd& v) {
    std::lock_guard<std::mutex> lock(mutex);
    ++count;
    if (v.size() != 2 || v[0] != kForceZ || v[1] != kLevel) ++wrong;
  }
};

bool waitFor(const std::function<bool()>& condition, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

TEST(SensorChannels, ReadsEveryChannelOfAnyMessageTypeByItsFieldPath) {
  Publishers publishers;
  Readings readings;
  ros::NodeHandle nh;
  lfd_dmp::SensorChannels channels(
      nh, twoTopics(), [&](const ros::Time&, const Eigen::VectorXd& v) { readings.add(v); });
  ASSERT_TRUE(waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(readings.mutex);
        return readings.count >= 20;
      },
      10.0));
  EXPECT_EQ(readings.wrong, 0);
  EXPECT_EQ(channels.problem(), "");
}

TEST(SensorChannels, DestroyedWhileMessagesArriveOnManyThreadsNeverTouchesWhatItFreed) {
  Publishers publishers;
  Readings readings;
  ros::NodeHandle nh;
  std::atomic<int> after_destruction{0};
  for (int round = 0; round < 150; ++round) {
    std::atomic<bool> destroyed{false};
    {
      lfd_dmp::SensorChannels channels(
          nh, twoTopics(), [&](const ros::Time&, const Eigen::VectorXd& v) {
            if (destroyed) ++after_destruction;
            readings.add(v);
            // a slow callback widens the window in which the other
            // topic's subscription ends
            std::this_thread::sleep_for(std::chrono::microseconds(300));
          });
      std::this_thread::sleep_for(std::chrono::milliseconds(10 + round % 7));
    }
    destroyed = true;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(after_destruction, 0);
  EXPECT_GT(readings.count, 150);  // the rounds did read (each lives >= 10 ms at 2 kHz)
  EXPECT_EQ(readings.wrong, 0);    // a freed buffer read back shows as a wrong value
}

// A signature of one 2 s segment whose levels are what Publishers sends: nothing deviates.
lfd::SensorySignature quietSignature() {
  lfd::SensorySignature s = twoTopics();
  lfd::SegmentSignature segment;
  segment.duration_mean = 2.0;
  for (const double level : {kForceZ, kLevel}) {
    lfd::ChannelSignature c;
    c.mean = Eigen::VectorXd::Constant(50, level);
    c.spread = Eigen::VectorXd::Ones(50);
    c.threshold = 3.0;
    segment.channels.push_back(c);
  }
  s.segments = {segment};
  return s;
}

// A motion of one segment, 'press', lasting `duration` s.
lfd_dmp::ExecutionPlan pressPlan(double duration) {
  lfd_dmp::ExecutionPlan plan;
  plan.segments.resize(1);
  plan.segments[0].name = "press";
  plan.segments[0].duration = duration;
  return plan;
}

TEST(ExecutionMonitor, ATopicThatStopsDuringTheMotionIsNamedOnceSilentForMaxSilence) {
  Publishers publishers;
  ros::NodeHandle nh;
  lfd_dmp::ExecutionMonitor monitor(nh, quietSignature(), 0.3, 0.3, 10.0);
  const lfd_dmp::ExecutionPlan plan = pressPlan(3.0);
  const ros::Time t0 = ros::Time::now();
  monitor.start(plan, t0);
  ros::WallDuration(0.5).sleep();
  EXPECT_FALSE(monitor.silence(ros::Time::now())) << "both topics publish";
  EXPECT_FALSE(monitor.alarm());
  publishers.level_on = false;
  const ros::Time stopped = ros::Time::now();
  std::optional<lfd_dmp::Silence> silent;
  ASSERT_TRUE(
      waitFor([&] { return (silent = monitor.silence(ros::Time::now())).has_value(); }, 2.0));
  EXPECT_EQ(silent->topic, "/channels_test/level");
  EXPECT_LE((ros::Time::now() - stopped).toSec(), 0.4);
  EXPECT_NEAR(silent->allowed, 0.3, 1e-9);  // 10 periods of ~0.5 ms are less than 0.3 s
  const std::string text = lfd_dmp::describeSilence(*silent, plan.segments);
  EXPECT_NE(text.find("'press'"), std::string::npos) << text;
  EXPECT_NE(text.find("/channels_test/level silent"), std::string::npos) << text;
  monitor.stop();
  EXPECT_FALSE(monitor.silence(ros::Time::now())) << "a stopped monitor judges nothing";
}

// A simulation stepped far faster than real time runs its clock ahead of a loaded subscriber's
// callbacks: a topic whose messages keep arriving, stamped long before `now`, is late, not silent;
// once nothing arrives for min_wall_silence, it is.
TEST(ExecutionMonitor, ATopicThatKeepsArrivingLateIsNotSilentUntilItStops) {
  Publishers publishers;
  publishers.ft_lag = 2.0;  // s behind the clock, far beyond max_silence
  ros::NodeHandle nh;
  lfd_dmp::ExecutionMonitor monitor(nh, quietSignature(), 0.3, 0.3, 10.0);
  const lfd_dmp::ExecutionPlan plan = pressPlan(10.0);  // still running when the F/T stops
  monitor.start(plan, ros::Time::now() - ros::Duration(2.5));
  ros::WallDuration(0.5).sleep();
  EXPECT_FALSE(monitor.silence(ros::Time::now())) << "the F/T arrives, 2 s late";
  publishers.ft_on = false;
  const ros::WallTime stopped = ros::WallTime::now();
  std::optional<lfd_dmp::Silence> silent;
  ASSERT_TRUE(
      waitFor([&] { return (silent = monitor.silence(ros::Time::now())).has_value(); }, 2.0));
  EXPECT_EQ(silent->topic, "/channels_test/ft");
  EXPECT_GE((ros::WallTime::now() - stopped).toSec(), 0.3 - 0.05) << "not before min_wall_silence";
  monitor.stop();
}

// A stale driver repeats its last reading: a stream whose values stop changing is frozen after
// max_frozen; a noisy live sensor never repeats, and an idle contact sensor's exact zeros are no
// frozen stream.
TEST(ExecutionMonitor, AStreamThatRepeatsItsReadingsIsFrozenAnIdleOneIsNot) {
  Publishers publishers;
  publishers.ft_noise = true;
  ros::NodeHandle nh;
  lfd_dmp::ExecutionMonitor monitor(nh, quietSignature(), 5.0, 0.3, 0.2);
  const lfd_dmp::ExecutionPlan plan = pressPlan(10.0);
  monitor.start(plan, ros::Time::now());
  std::optional<lfd_dmp::Frozen> frozen;
  ASSERT_TRUE(
      waitFor([&] { return (frozen = monitor.frozen(ros::Time::now())).has_value(); }, 2.0));
  EXPECT_EQ(frozen->topic, "/channels_test/level");  // -2.25 in every message
  EXPECT_GT(frozen->unchanged, 0.2);
  const std::string text = lfd_dmp::describeFrozen(*frozen, plan.segments);
  EXPECT_NE(text.find("/channels_test/level frozen"), std::string::npos) << text;
  publishers.level_value = 0.0;
  ros::WallDuration(0.3).sleep();
  EXPECT_FALSE(monitor.frozen(ros::Time::now())) << "idle zeros and a noisy F/T";
  monitor.stop();
}

TEST(ExecutionMonitor, RefusesANegativeWallSilenceOrNoFrozenTime) {
  ros::NodeHandle nh;
  EXPECT_THROW(lfd_dmp::ExecutionMonitor(nh, quietSignature(), 0.3, -1.0, 0.5),
               std::invalid_argument);
  EXPECT_THROW(lfd_dmp::ExecutionMonitor(nh, quietSignature(), 0.3, 0.3, 0.0),
               std::invalid_argument);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "sensor_channels_test");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(4);  // as the executor: callbacks of different topics in parallel
  spinner.start();
  return RUN_ALL_TESTS();
}
