// bridge_node: ROS adapter of the MuJoCo workcell (lfd_sim::WorkcellSim), behaving like a
// position-controlled robot driver on simulated time. Topics and services: DESIGN.md.
//
// One thread owns the simulation: it steps physics, publishes /clock and the sensor topics on
// sim-time schedules, and polls the callback queue (commands and services) between steps, so no
// lock is needed and a service always sees a consistent state.
//
// Private parameters (config/bridge.yaml):
//   model_path            MJCF scene (required; sim.launch passes models/workcell.xml)
//   robot_file            the robot file (required; lfd::loadRobotSetup): the gripper joint, the
//                         end-effector site (ik tip_link) and its frame (the Cartesian frame), and
//                         the sensor table, one topic per row (sensor_publishers.hpp)
//   world_frame           the fixed frame of the object poses and of the base's static transform
//   real_time_factor      <= 0: as fast as possible; else sim seconds per wall second
//   publish_rate          Hz (sim time) of joint states, sensors, ee pose/twist, objects, tf
//   clock_rate            Hz (sim time) of /clock; also how often commands are polled
//   start_paused, headless, use_urdf_limits
//   rtf_report_period     wall seconds between "real-time factor" INFO lines (0 = never)
//   kp, kd, damping_ratio, velocity_limits, default_velocity_limit,
//   effort_limits, default_effort_limit, gravity_compensation,
//   (the ready posture and the gripper's opening scale are the robot file's)
//   objects, max_abs_velocity, touch_time_constant (see WorkcellConfig)
//   noise_profiles        {name: {seed, joint_position, ...}}: readings noise (SensorNoise)
//   noise_profile         the profile at startup; a /bridge/reset request may select another
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/TwistStamped.h>
#include <lfd_msgs/GripperCommand.h>
#include <lfd_msgs/InjectFault.h>
#include <lfd_msgs/ResetSim.h>
#include <lfd_msgs/SetScene.h>
#include <lfd_msgs/StepSim.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/SetBool.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_ros/master_watch.hpp"
#include "lfd_ros/ros_request_strings.hpp"
#include "lfd_sim_bridge/fault_schedule.hpp"
#include "lfd_sim_bridge/sensor_publishers.hpp"
#include "lfd_sim_bridge/sensor_table.hpp"
#include "lfd_sim_bridge/wall_profile.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"

namespace {

// Sensor publisher queues: a recorder that falls behind a fast sim for a moment must
// receive every sample later rather than lose it (the default of 10 dropped samples under load).
constexpr uint32_t kSensorQueue = 2000;

std::map<std::string, double> mapParam(ros::NodeHandle& pnh, const std::string& name) {
  std::map<std::string, double> value;
  if (pnh.hasParam(name) && !pnh.getParam(name, value)) {
    throw std::invalid_argument("~" + name + " must be a map of joint name to number");
  }
  return value;
}

// A named readings noise of ~noise_profiles: the noise and the seed its generator restarts from.
struct NoiseProfile {
  lfd_sim::SensorNoise noise;
  uint64_t seed = 1;
};

double number(XmlRpc::XmlRpcValue& v, const std::string& where) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(v);
  throw std::invalid_argument(where + " must be a number");
}

// ~noise_profiles: {name: {seed: N, joint_position: std, ...}}; a reading not listed is exact.
// Unknown keys are refused: a misspelt one would silently record exact readings.
std::map<std::string, NoiseProfile> loadNoiseProfiles(ros::NodeHandle& pnh) {
  std::map<std::string, NoiseProfile> profiles;
  XmlRpc::XmlRpcValue all;
  if (!pnh.getParam("noise_profiles", all)) return profiles;
  if (all.getType() != XmlRpc::XmlRpcValue::TypeStruct)
    throw std::invalid_argument("~noise_profiles must be a map of name to profile");
  for (auto& [name, entry] : all) {
    const std::string where = "~noise_profiles/" + name;
    if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct)
      throw std::invalid_argument(where + " must be a map");
    NoiseProfile p;
    lfd_sim::SensorNoise& n = p.noise;
    const std::map<std::string, double*> fields = {{"joint_position", &n.joint_position},
                                                   {"joint_velocity", &n.joint_velocity},
                                                   {"joint_effort", &n.joint_effort},
                                                   {"force", &n.force},
                                                   {"torque", &n.torque},
                                                   {"touch", &n.touch},
                                                   {"gyro", &n.gyro},
                                                   {"accel", &n.accel},
                                                   {"ee_position", &n.ee_position},
                                                   {"ee_orientation", &n.ee_orientation},
                                                   {"gripper", &n.gripper},
                                                   {"object_position", &n.object_position}};
    for (auto& [key, value] : entry) {
      if (key == "seed") {
        p.seed = static_cast<uint64_t>(number(value, where + "/seed"));
      } else if (fields.count(key)) {
        *fields.at(key) = number(value, where + "/" + key);
      } else {
        throw std::invalid_argument(where + " has an unknown key '" + key + "'");
      }
    }
    profiles[name] = p;
  }
  return profiles;
}

// The robot's part of the workcell comes from its robot file, the rest from ~ parameters.
lfd_sim::WorkcellConfig loadConfig(ros::NodeHandle& pnh, const lfd::RobotSetup& robot,
                                   const std::vector<lfd_sim::SensorBinding>& sensors) {
  lfd_sim::WorkcellConfig c;
  c.gripper_joint = robot.gripper.joint;
  c.base_body = robot.poseFrame();
  c.ee_site = robot.tip_link;
  c.sensors = lfd_sim::sensorGroups(sensors);
  c.initial_posture = robot.initial_posture;
  c.gripper_opening_scale = robot.gripper.opening_scale;
  c.kp = mapParam(pnh, "kp");
  c.kd = mapParam(pnh, "kd");
  c.velocity_limits = mapParam(pnh, "velocity_limits");
  c.effort_limits = mapParam(pnh, "effort_limits");
  c.default_kp = pnh.param("default_kp", c.default_kp);
  c.damping_ratio = pnh.param("damping_ratio", c.damping_ratio);
  c.default_velocity_limit = pnh.param("default_velocity_limit", c.default_velocity_limit);
  c.default_effort_limit = pnh.param("default_effort_limit", c.default_effort_limit);
  c.gravity_compensation = pnh.param("gravity_compensation", c.gravity_compensation);
  c.objects = pnh.param("objects", c.objects);
  c.max_abs_velocity = pnh.param("max_abs_velocity", c.max_abs_velocity);
  c.touch_time_constant = pnh.param("touch_time_constant", c.touch_time_constant);
  c.quaternion_tolerance = pnh.param("quaternion_tolerance", c.quaternion_tolerance);
  for (const auto& [key, bound] : {std::pair{"workspace_min", &c.workspace_min},
                                   std::pair{"workspace_max", &c.workspace_max}}) {
    const std::vector<double> v = pnh.param(key, std::vector<double>(bound->begin(), bound->end()));
    if (v.size() != 3) throw std::invalid_argument(std::string("~") + key + " needs [x, y, z]");
    std::copy(v.begin(), v.end(), bound->begin());
  }
  return c;
}

void toMsg(const lfd_sim::Pose& p, geometry_msgs::Pose* msg) {
  msg->position.x = p.position[0];
  msg->position.y = p.position[1];
  msg->position.z = p.position[2];
  msg->orientation.w = p.orientation[0];
  msg->orientation.x = p.orientation[1];
  msg->orientation.y = p.orientation[2];
  msg->orientation.z = p.orientation[3];
}

void toMsg(const std::array<double, 3>& v, geometry_msgs::Vector3* msg) {
  msg->x = v[0];
  msg->y = v[1];
  msg->z = v[2];
}

geometry_msgs::TransformStamped toTransform(const lfd_sim::Pose& p, const ros::Time& stamp,
                                            const std::string& parent, const std::string& child) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = p.position[0];
  t.transform.translation.y = p.position[1];
  t.transform.translation.z = p.position[2];
  t.transform.rotation.w = p.orientation[0];
  t.transform.rotation.x = p.orientation[1];
  t.transform.rotation.y = p.orientation[2];
  t.transform.rotation.z = p.orientation[3];
  return t;
}

// Errors caused by other nodes' messages: logged at most once per second (wall) per kind, so a
// misbehaving publisher cannot flood the log, with a count of what was suppressed.
class ThrottledErrors {
 public:
  void report(const std::string& kind, const std::string& text) {
    Entry& e = entries_[kind];
    const ros::WallTime now = ros::WallTime::now();
    if (e.last.isZero() || (now - e.last).toSec() >= 1.0) {
      if (e.suppressed > 0) {
        ROS_ERROR("%s (and %d more %s errors in the last second)", text.c_str(), e.suppressed,
                  kind.c_str());
      } else {
        ROS_ERROR("%s", text.c_str());
      }
      e.last = now;
      e.suppressed = 0;
    } else {
      ++e.suppressed;
    }
  }

 private:
  struct Entry {
    ros::WallTime last;
    int suppressed = 0;
  };
  std::map<std::string, Entry> entries_;
};

class BridgeNode {
 public:
  BridgeNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
    const std::string model_path = pnh.param<std::string>("model_path", "");
    if (model_path.empty()) throw std::runtime_error("~model_path is not set");
    noise_profiles_ = loadNoiseProfiles(pnh);
    const lfd::RobotSetup robot = lfd::loadRobotSetup(pnh.param<std::string>("robot_file", ""));
    const std::vector<lfd_sim::SensorBinding> sensors = lfd_sim::bindSensorTable(robot.sensors);
    lfd_sim::WorkcellConfig config = loadConfig(pnh, robot, sensors);
    gripper_joint_ = config.gripper_joint;
    base_frame_ = config.base_body;
    world_frame_ = pnh.param<std::string>("world_frame", "");
    if (world_frame_.empty()) throw std::runtime_error("~world_frame is not set");
    const NoiseProfile& start = noiseProfile(pnh.param<std::string>("noise_profile", ""));
    config.noise = start.noise;
    config.noise_seed = start.seed;
    sim_ = std::make_unique<lfd_sim::WorkcellSim>(model_path, config, rosLogSink);
    lfd_sim::checkSensorDimensions(
        sensors, [this](const std::string& name) { return sim_->sensorDimension(name); });
    if (pnh.param("use_urdf_limits", true)) {
      std::string urdf;
      if (nh.getParam("robot_description", urdf)) {
        sim_->applyUrdfLimits(urdf);
      } else {
        ROS_WARN("use_urdf_limits is set but /robot_description is missing; MJCF/config limits");
      }
    }
    real_time_factor_ = pnh.param("real_time_factor", 0.0);
    const double publish_rate = pnh.param("publish_rate", 200.0);
    const double clock_rate = pnh.param("clock_rate", 200.0);
    if (!(publish_rate > 0) || !(clock_rate > 0)) {
      throw std::invalid_argument("~publish_rate and ~clock_rate must be positive");
    }
    const double dt = sim_->timestep();
    publish_every_ = std::max<long>(1, std::lround(1.0 / (publish_rate * dt)));
    clock_every_ = std::max<long>(1, std::lround(1.0 / (clock_rate * dt)));
    paused_ = pnh.param("start_paused", false);
    max_steps_per_call_ = pnh.param("max_steps_per_call", max_steps_per_call_);
    strings_.max_bytes = static_cast<std::size_t>(std::max(
        0, pnh.param("limits/max_request_string_bytes", static_cast<int>(strings_.max_bytes))));
    strings_.key = "~limits/max_request_string_bytes";
    rtf_report_period_ = pnh.param("rtf_report_period", 30.0);
    if (!pnh.param("headless", true)) {
      ROS_WARN(
          "headless:=false requested, but the bridge has no MuJoCo viewer; use rviz "
          "(robot, tf and object poses are all published)");
    }

    advertiseTopics(nh, sensors);
    serveCommands(nh);

    ROS_INFO(
        "bridge: %zu actuated joints, dt %.4f s, /clock every %ld steps, sensors every %ld "
        "steps, real_time_factor %.2f%s",
        sim_->actuatedJoints().size(), dt, clock_every_, publish_every_, real_time_factor_,
        paused_ ? ", paused" : "");
  }

  void run() {
    publishClock();  // t = 0 first, so sim-time nodes start
    publishState();
    ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
    ros::WallTime anchor_wall = ros::WallTime::now();
    double anchor_sim = sim_->time();
    bool was_paused = paused_;
    while (ros::ok()) {
      if (paused_) {
        queue->callAvailable(ros::WallDuration(0.01));
        was_paused = true;
        report_wall_ = ros::WallTime();
        continue;
      }
      if (was_paused) {  // pacing restarts from here, no catch-up burst after a pause
        anchor_wall = ros::WallTime::now();
        anchor_sim = sim_->time();
        was_paused = false;
      }
      stepOnce();
      if (step_count_ % clock_every_ == 0) {
        queue->callAvailable();
        if (real_time_factor_ > 0) pace(&anchor_wall, &anchor_sim);
        reportRealTimeFactor();
      }
    }
  }

 private:
  // The state, sensor and object topics, /clock, /tf and the base's static transform.
  void advertiseTopics(ros::NodeHandle& nh, const std::vector<lfd_sim::SensorBinding>& sensors) {
    // Names are relative (the node's namespace, remappable), except the master-wide /clock, which
    // every sim-time node reads by that name, and the tf tree /tf.
    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    joint_state_pub_ = nh.advertise<sensor_msgs::JointState>("joint_states", kSensorQueue);
    object_joint_pub_ = nh.advertise<sensor_msgs::JointState>("objects/joint_states", kSensorQueue);
    gripper_state_pub_ = nh.advertise<sensor_msgs::JointState>("gripper/state", kSensorQueue);
    sensor_pubs_ = lfd_sim_bridge::makeSensorPublishers(nh, sensors, kSensorQueue);
    ee_pose_pub_ = nh.advertise<geometry_msgs::PoseStamped>("ee_pose", kSensorQueue);
    ee_twist_pub_ = nh.advertise<geometry_msgs::TwistStamped>("ee_twist", kSensorQueue);
    tf_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
    sim_->readState(&state_);
    for (const std::string& name : state_.object_names) {
      object_pubs_.push_back(
          nh.advertise<geometry_msgs::PoseStamped>("objects/" + name + "/pose", kSensorQueue));
    }
    static_tf_.sendTransform(
        toTransform(sim_->basePoseInWorld(), ros::Time(0), world_frame_, base_frame_));
  }

  // The command topics (joints, trajectories, gripper) and the bridge/ services.
  void serveCommands(ros::NodeHandle& nh) {
    ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    joint_command_sub_ =
        nh.subscribe("joint_command", 10, &BridgeNode::onJointCommand, this, hints);
    trajectory_sub_ = nh.subscribe("joint_trajectory", 10, &BridgeNode::onTrajectory, this, hints);
    gripper_sub_ = nh.subscribe("gripper/command", 10, &BridgeNode::onGripper, this, hints);
    reset_srv_ = nh.advertiseService("bridge/reset", &BridgeNode::onReset, this);
    scene_srv_ = nh.advertiseService("bridge/set_scene", &BridgeNode::onSetScene, this);
    pause_srv_ = nh.advertiseService("bridge/pause", &BridgeNode::onPause, this);
    step_srv_ = nh.advertiseService("bridge/step", &BridgeNode::onStep, this);
    fault_srv_ = nh.advertiseService("bridge/inject_fault", &BridgeNode::onInjectFault, this);
  }

  static void rosLogSink(lfd_sim::LogLevel level, const std::string& text) {
    switch (level) {
      case lfd_sim::LogLevel::kInfo:
        ROS_INFO("%s", text.c_str());
        break;
      case lfd_sim::LogLevel::kWarn:
        ROS_WARN("%s", text.c_str());
        break;
      case lfd_sim::LogLevel::kError:
        ROS_ERROR("%s", text.c_str());
        break;
    }
  }

  void stepOnce() {
    applyDueGripperCommands();
    {
      const auto scope = wall_.measure("physics");
      sim_->step();
    }
    applyDueFaults();
    ++step_count_;
    const auto scope = wall_.measure("publishing");
    if (step_count_ % clock_every_ == 0) publishClock();
    if (step_count_ % publish_every_ == 0) publishState();
  }

  // Achieved speed, measured over the last report period of running (not paused) wall time.
  void reportRealTimeFactor() {
    if (rtf_report_period_ <= 0) return;
    const ros::WallTime now = ros::WallTime::now();
    if (report_wall_.isZero()) {
      report_wall_ = now;
      report_sim_ = sim_->time();
      return;
    }
    const double wall = (now - report_wall_).toSec();
    if (wall < rtf_report_period_) return;
    ROS_INFO("bridge: t=%.1f s, real-time factor %.2f over the last %.0f s (%d divergences)",
             sim_->time(), (sim_->time() - report_sim_) / wall, wall, sim_->divergenceCount());
    report_wall_ = now;
    report_sim_ = sim_->time();
  }

  void pace(ros::WallTime* anchor_wall, double* anchor_sim) {
    const double sim_elapsed = sim_->time() - *anchor_sim;
    const ros::WallTime due = *anchor_wall + ros::WallDuration(sim_elapsed / real_time_factor_);
    const ros::WallTime now = ros::WallTime::now();
    if (due > now) {
      (due - now).sleep();
    } else if ((now - due).toSec() > 0.1) {  // too slow: re-anchor instead of bursting
      *anchor_wall = now;
      *anchor_sim = sim_->time();
    }
  }

  void publishClock() {
    const ros::Time now(sim_->time());
    if (now <= last_clock_) return;  // /clock never repeats nor goes backwards
    rosgraph_msgs::Clock msg;
    msg.clock = now;
    clock_pub_.publish(msg);
    last_clock_ = now;
  }

  void publishState() {
    sim_->readState(&state_);
    const ros::Time stamp(state_.time);
    // The robot's joints on /joint_states (what a robot's driver publishes, and all that
    // robot_state_publisher knows from the URDF); a scene object's (the drawer's slide) apart.
    for (const bool objects : {false, true}) {
      const ros::Publisher& pub = objects ? object_joint_pub_ : joint_state_pub_;
      if (pub.getNumSubscribers() == 0) continue;
      sensor_msgs::JointState js;
      js.header.stamp = stamp;
      for (size_t i = 0; i < state_.joint_names.size(); ++i) {
        if (state_.object_joint[i] != objects) continue;
        js.name.push_back(state_.joint_names[i]);
        js.position.push_back(state_.joint_positions[i]);
        js.velocity.push_back(state_.joint_velocities[i]);
        js.effort.push_back(state_.joint_efforts[i]);
      }
      if (!js.name.empty()) pub.publish(js);
    }
    if (gripper_state_pub_.getNumSubscribers() > 0) {
      sensor_msgs::JointState gs;
      gs.header.stamp = stamp;
      gs.name = {gripper_joint_};
      gs.position = {state_.gripper_opening};
      gs.velocity = {state_.gripper_velocity};
      gs.effort = {state_.gripper_effort};
      gripper_state_pub_.publish(gs);
    }
    for (size_t i = 0; i < sensor_pubs_.size(); ++i)
      if (!silenced_.count(state_.sensors[i].name))
        sensor_pubs_[i]->publish(state_.sensors[i], stamp);
    if (ee_pose_pub_.getNumSubscribers() > 0) {
      geometry_msgs::PoseStamped p;
      p.header.stamp = stamp;
      p.header.frame_id = base_frame_;
      toMsg(state_.ee_pose, &p.pose);
      ee_pose_pub_.publish(p);
    }
    if (ee_twist_pub_.getNumSubscribers() > 0) {
      geometry_msgs::TwistStamped tw;
      tw.header.stamp = stamp;
      tw.header.frame_id = base_frame_;
      toMsg(state_.ee_linear_velocity, &tw.twist.linear);
      toMsg(state_.ee_angular_velocity, &tw.twist.angular);
      ee_twist_pub_.publish(tw);
    }
    tf2_msgs::TFMessage tf;
    for (size_t i = 0; i < state_.object_names.size(); ++i) {
      if (object_pubs_[i].getNumSubscribers() > 0) {
        geometry_msgs::PoseStamped p;
        p.header.stamp = stamp;
        p.header.frame_id = world_frame_;
        toMsg(state_.object_poses[i], &p.pose);
        object_pubs_[i].publish(p);
      }
      tf.transforms.push_back(
          toTransform(state_.object_poses[i], stamp, world_frame_, state_.object_names[i]));
    }
    if (tf_pub_.getNumSubscribers() > 0 && stamp > last_tf_) {
      tf_pub_.publish(tf);
      last_tf_ = stamp;
    }
  }

  void onJointCommand(const sensor_msgs::JointState::ConstPtr& msg) {
    try {
      sim_->setJointTargets(msg->name, msg->position);
    } catch (const std::exception& e) {
      errors_.report("joint_command", std::string("rejected /joint_command: ") + e.what());
    }
  }

  // Validated on receipt, whole (WorkcellSim::setTrajectory: sizes, finite values, times, each
  // velocity within its joint's limit); a refused trajectory is logged and nothing moves.
  void onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
    last_trajectory_stamp_ = msg->header.stamp.toSec();
    lfd_sim::JointTrajectory traj;
    traj.joint_names = msg->joint_names;
    traj.points.reserve(msg->points.size());
    for (const trajectory_msgs::JointTrajectoryPoint& p : msg->points) {
      traj.points.push_back({p.time_from_start.toSec(), p.positions, p.velocities});
    }
    try {
      checkAccelerations(*msg);
      sim_->setTrajectory(traj, msg->header.stamp.toSec());
    } catch (const std::exception& e) {
      errors_.report("joint_trajectory", std::string("rejected /joint_trajectory: ") + e.what());
    }
  }

  // The interpolation does not use accelerations, but a trajectory that carries wrong ones is a
  // wrong trajectory: refused like a bad position or velocity.
  static void checkAccelerations(const trajectory_msgs::JointTrajectory& msg) {
    for (size_t k = 0; k < msg.points.size(); ++k) {
      const std::vector<double>& a = msg.points[k].accelerations;
      if (!a.empty() && a.size() != msg.joint_names.size())
        throw std::invalid_argument("trajectory point " + std::to_string(k) + " has " +
                                    std::to_string(a.size()) + " accelerations for " +
                                    std::to_string(msg.joint_names.size()) + " joints");
      for (double x : a)
        if (!std::isfinite(x))
          throw std::invalid_argument("trajectory point " + std::to_string(k) +
                                      " has a NaN or infinite acceleration");
    }
  }

  // A command stamped ahead of sim time takes effect at its stamp, to the physics step (a planned
  // motion sends its gripper events in advance, so they happen on time whatever the load); a zero
  // or past stamp, at once. A command drops the pending ones stamped after it (a stop cancels).
  void onGripper(const lfd_msgs::GripperCommand::ConstPtr& msg) {
    last_gripper_stamp_ = msg->header.stamp.toSec();
    while (!pending_gripper_.empty() && pending_gripper_.back().header.stamp > msg->header.stamp)
      pending_gripper_.pop_back();
    if (msg->header.stamp.toSec() <= sim_->time() + 0.5 * sim_->timestep())
      applyGripper(*msg);
    else if (pending_gripper_.size() >= kMaxPendingGripper)
      errors_.report("gripper_command", "rejected /gripper/command: over " +
                                            std::to_string(kMaxPendingGripper) + " pending");
    else
      pending_gripper_.push_back(*msg);  // stays sorted: every later one was dropped above
  }

  void applyDueGripperCommands() {
    while (!pending_gripper_.empty() &&
           pending_gripper_.front().header.stamp.toSec() <= sim_->time() + 0.5 * sim_->timestep()) {
      applyGripper(pending_gripper_.front());
      pending_gripper_.pop_front();
    }
  }

  void applyGripper(const lfd_msgs::GripperCommand& msg) {
    try {
      sim_->setGripper(msg.position, msg.max_effort);
    } catch (const std::exception& e) {
      errors_.report("gripper_command", std::string("rejected /gripper/command: ") + e.what());
    }
  }

  bool onReset(lfd_msgs::ResetSim::Request& req, lfd_msgs::ResetSim::Response& res) {
    try {
      lfd::checkRequestStrings(req, strings_);  // before any work: no 10 MB name echoed
      if (req.joint_names.size() != req.positions.size()) {
        throw std::invalid_argument("joint_names and positions differ in length");
      }
      std::map<std::string, double> posture;
      for (size_t i = 0; i < req.joint_names.size(); ++i) {
        posture[req.joint_names[i]] = req.positions[i];
      }
      // Looked up first: an unknown profile fails the request before anything changes.
      const NoiseProfile* noise =
          req.noise_profile.empty() ? nullptr : &noiseProfile(req.noise_profile);
      // Per demonstration (a demonstrator resets before each): where the bridge's time went.
      ROS_INFO("bridge: wall time since the last reset, %ld steps: %s",
               step_count_ - steps_at_reset_, wall_.flowMap().c_str());
      wall_.clear();
      steps_at_reset_ = step_count_;
      sim_->reset(posture, req.reset_objects);
      if (noise) sim_->setNoise(noise->noise, noise->seed);
      pending_gripper_.clear();  // a reset robot has no plan left
      faults_.clear();           // and no fault (the workcell undid those in force)
      silenced_.clear();
      publishState();
      res.success = true;
      res.message = "reset at t=" + std::to_string(sim_->time()) +
                    (noise ? ", noise profile " + req.noise_profile : "");
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      ROS_ERROR("/bridge/reset failed: %s", e.what());
    }
    return true;
  }

  // "" = exact readings (no profile configured), else a name of ~noise_profiles.
  const NoiseProfile& noiseProfile(const std::string& name) const {
    static const NoiseProfile kExact;
    if (name.empty()) return kExact;
    const auto it = noise_profiles_.find(name);
    if (it == noise_profiles_.end()) {
      std::string known;
      for (const auto& [n, p] : noise_profiles_) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("no noise profile '" + name + "' in ~noise_profiles (" + known +
                                  ")");
    }
    return it->second;
  }

  bool onSetScene(lfd_msgs::SetScene::Request& req, lfd_msgs::SetScene::Response& res) {
    try {
      lfd::checkRequestStrings(req, strings_);  // before any work: no 10 MB name echoed
      if (req.object_names.size() != req.poses.size()) {
        throw std::invalid_argument("object_names and poses differ in length");
      }
      // Check every entry before moving anything, so a bad request changes nothing.
      std::vector<lfd_sim::Pose> poses(req.poses.size());
      for (size_t i = 0; i < req.poses.size(); ++i) {
        const geometry_msgs::Pose& p = req.poses[i];
        poses[i].position = {p.position.x, p.position.y, p.position.z};
        poses[i].orientation = {p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z};
        sim_->checkObjectPose(req.object_names[i], poses[i]);
      }
      for (size_t i = 0; i < poses.size(); ++i) sim_->setObjectPose(req.object_names[i], poses[i]);
      publishState();
      res.success = true;
      res.message = "placed " + std::to_string(poses.size()) + " object(s)";
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      ROS_ERROR("/bridge/set_scene failed: %s", e.what());
    }
    return true;
  }

  // ---- fault injection (sim only; lfd_sim_bridge/fault_schedule.hpp) -------------------------
  bool onInjectFault(lfd_msgs::InjectFault::Request& req, lfd_msgs::InjectFault::Response& res) {
    try {
      lfd::checkRequestStrings(req, strings_);
      lfd_sim::Fault f;
      f.kind = lfd_sim::faultKind(req.kind);
      f.target = req.target;
      f.at = req.at_time;
      f.pose.position = {req.pose.position.x, req.pose.position.y, req.pose.position.z};
      f.pose.orientation = {req.pose.orientation.w, req.pose.orientation.x, req.pose.orientation.y,
                            req.pose.orientation.z};
      f.value = req.value;
      faults_.add(f, *sim_);
      res.success = true;
      res.message = "scheduled: " + lfd_sim::describeFault(f);
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      ROS_ERROR("/bridge/inject_fault failed: %s", e.what());
    }
    return true;
  }

  void applyDueFaults() {
    for (const lfd_sim::Fault& f : faults_.takeDue(sim_->time())) {
      try {
        if (f.kind == lfd_sim::Fault::Kind::kSilenceSensor) silenced_.insert(f.target);
        lfd_sim::applyFault(f, sim_.get());
        ROS_WARN("bridge: fault injected at t=%.3f s: %s", sim_->time(),
                 lfd_sim::describeFault(f).c_str());
      } catch (const std::exception& e) {  // checked when scheduled; the scene may have changed
        ROS_ERROR("bridge: fault not injected (%s): %s", lfd_sim::describeFault(f).c_str(),
                  e.what());
      }
    }
  }

  bool onPause(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
    paused_ = req.data;
    res.success = true;
    res.message =
        std::string(paused_ ? "paused" : "running") + " at t=" + std::to_string(sim_->time());
    return true;
  }

  bool onStep(lfd_msgs::StepSim::Request& req, lfd_msgs::StepSim::Response& res) {
    res.sim_time = sim_->time();
    res.last_trajectory_stamp = last_trajectory_stamp_;
    res.last_gripper_stamp = last_gripper_stamp_;
    if (!paused_) {
      res.success = false;
      res.message = "the simulation is running; pause it (/bridge/pause) before stepping";
      return true;
    }
    // One call holds the only thread: a bounded step keeps /bridge/pause and the rest served.
    if (req.steps > static_cast<uint32_t>(std::max(0, max_steps_per_call_))) {
      res.success = false;
      res.message = std::to_string(req.steps) + " steps is over the limit of " +
                    std::to_string(max_steps_per_call_) + " per call (~max_steps_per_call)";
      return true;
    }
    if (req.steps == 0) {  // a query: a republished state would duplicate a recorded stamp
      res.success = true;
      res.message = "stepped 0";
      return true;
    }
    for (uint32_t i = 0; i < req.steps; ++i) stepOnce();
    publishClock();  // the final time is always announced (skipped only if already sent)
    // Only if stepOnce() did not just publish it: a duplicate at the same stamp would
    // distort the recorded topic rates when a demonstrator steps the sim in lockstep.
    if (step_count_ % publish_every_ != 0) publishState();
    res.success = true;
    res.sim_time = sim_->time();
    res.message = "stepped " + std::to_string(req.steps);
    return true;
  }

  ros::NodeHandle nh_;
  std::unique_ptr<lfd_sim::WorkcellSim> sim_;
  lfd_sim::WorkcellState state_;
  double real_time_factor_ = 0.0;
  double rtf_report_period_ = 30.0;
  ros::WallTime report_wall_;
  double report_sim_ = 0.0;
  long publish_every_ = 5, clock_every_ = 5;
  long step_count_ = 0;
  long steps_at_reset_ = 0;
  lfd_sim_bridge::WallProfile wall_;  // physics vs publishing, logged at each reset
  int max_steps_per_call_ = 10000;
  lfd::StringBudget strings_;  // ~limits/max_request_string_bytes of every request string
  bool paused_ = false;
  double last_trajectory_stamp_ = -1.0, last_gripper_stamp_ = -1.0;  // the commands taken in
  ros::Time last_clock_, last_tf_;
  ThrottledErrors errors_;
  static constexpr size_t kMaxPendingGripper = 1000;
  std::deque<lfd_msgs::GripperCommand> pending_gripper_;  // stamped ahead, by stamp
  ros::Publisher clock_pub_, joint_state_pub_, object_joint_pub_, gripper_state_pub_, ee_pose_pub_,
      ee_twist_pub_, tf_pub_;
  std::vector<std::unique_ptr<lfd_sim_bridge::SensorPublisher>> sensor_pubs_;  // per table row
  std::string gripper_joint_, base_frame_, world_frame_;  // robot file, ~world_frame
  std::vector<ros::Publisher> object_pubs_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
  ros::Subscriber joint_command_sub_, trajectory_sub_, gripper_sub_;
  ros::ServiceServer reset_srv_, scene_srv_, pause_srv_, step_srv_, fault_srv_;
  lfd_sim::FaultSchedule faults_;
  std::set<std::string> silenced_;  // sensor table rows whose topic a fault stopped
  std::map<std::string, NoiseProfile> noise_profiles_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "bridge");
  ros::NodeHandle nh, pnh("~");
  // A restarted master: the node ends, to be respawned (with the clock choice of its launch file).
  const lfd_ros::MasterWatch master_watch({"/use_sim_time"});
  try {
    BridgeNode bridge(nh, pnh);
    bridge.run();
  } catch (const std::exception& e) {
    ROS_FATAL("bridge: %s", e.what());
    return 1;
  }
  return master_watch.exitCode();
}
