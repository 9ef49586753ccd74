// executor_node: reproduces a learned task in a new scene (paper III, reproduction).
//   action  ~execute (lfd_msgs/ExecuteTaskAction; /executor/execute): plan (learned segment goals,
//           generalization, rollout, IK check of the whole path), then one stamped trajectory
//   out     /joint_trajectory (trajectory_msgs/JointTrajectory, header.stamp = sim time it starts)
//           /gripper/command (lfd_msgs/GripperCommand, header.stamp = sim time it takes effect)
//           /executor/planned_path, /executor/executed_path (nav_msgs/Path, Cartesian frame),
//           /executor/segment_markers (visualization_msgs/MarkerArray)
//   in      /joint_states, /gripper/state, tf (the scene's frames)
// It knows no simulator: any driver of those topics runs it, on its clock (/clock in simulation).
// Every wait is bounded in wall time (a clock that stops fails the goal instead of hanging it), and
// a preemption or cancel is served at any moment (planning, moving, settling).
// The logic is lfd_dmp::TaskPlanner (lib/executor.cpp); this file is ROS I/O and monitoring.
// Parameters: config/executor.yaml (loaded by lfd_launch/reproduce.launch).
#include "lfd_dmp/execution_monitor.hpp"
#include "lfd_dmp/execution_request.hpp"
#include "lfd_dmp/executor.hpp"
#include "lfd_dmp/object_following.hpp"
#include "lfd_dmp/object_symmetry.hpp"
#include "lfd_dmp/plan_messages.hpp"
#include "lfd_dmp/recovery.hpp"

#include <lfd_msgs/ExecuteTaskAction.h>
#include <lfd_core/io/safe_paths.hpp>
#include <lfd_core/kinematics/robot_setup.hpp>
#include <lfd_core/util/heap_trim.hpp>
#include <lfd_ros/master_watch.hpp>
#include <lfd_ros/ros_request_strings.hpp>

#include <actionlib/server/simple_action_server.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using ActionServer = actionlib::SimpleActionServer<lfd_msgs::ExecuteTaskAction>;
using Clock = std::chrono::steady_clock;

class Preempted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

double wallSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Eigen::Vector3d vectorParam(ros::NodeHandle& pnh, const std::string& key,
                            const Eigen::Vector3d& fallback) {
  std::vector<double> v;
  if (!pnh.getParam(key, v)) return fallback;
  if (v.size() != 3) throw std::runtime_error("executor: ~" + key + " needs 3 numbers");
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// Sim time must move while a motion runs; `timeout` wall seconds without progress is a failure
// (a paused or dead clock), never a hang.
class ClockWatch {
 public:
  explicit ClockWatch(double timeout) : timeout_(timeout) {}
  void check(const ros::Time& now) {
    if (now > last_) {
      last_ = now;
      since_ = Clock::now();
    } else if (wallSince(since_) > timeout_) {
      throw std::runtime_error(
          "sim time stopped at t=" + std::to_string(now.toSec()) + " s for " +
          std::to_string(timeout_) +
          " s of wall time (~clock_timeout): the robot driver is paused or gone; a lockstep client "
          "must step the simulation while the goal is active");
    }
  }

 private:
  double timeout_;
  ros::Time last_;
  Clock::time_point since_ = Clock::now();
};

template <class M>
void ignore(const boost::shared_ptr<const M>&) {}

// Handles on the action's topics (the names and types ActionServer uses) while its server is
// replaced: roscpp keeps a topic and its connections as long as one handle on it lives, so the
// clients stay connected to the new server.
// One joint state of the running plan's joints, as it arrived.
struct JointSample {
  ros::Time stamp;
  Eigen::VectorXd q;
};

struct ActionTopics {
  explicit ActionTopics(ros::NodeHandle& pnh)
      : goal(pnh.subscribe("execute/goal", 1, &ignore<lfd_msgs::ExecuteTaskActionGoal>)),
        cancel(pnh.subscribe("execute/cancel", 1, &ignore<actionlib_msgs::GoalID>)),
        status(pnh.advertise<actionlib_msgs::GoalStatusArray>("execute/status", 1, true)),
        feedback(pnh.advertise<lfd_msgs::ExecuteTaskActionFeedback>("execute/feedback", 1)),
        result(pnh.advertise<lfd_msgs::ExecuteTaskActionResult>("execute/result", 1)) {}
  ros::Subscriber goal, cancel;
  ros::Publisher status, feedback, result;
};

class Executor {
 public:
  Executor(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh), tf_listener_(tf_buffer_) {
    loadParameters(pnh);
    trajectory_pub_ = nh.advertise<trajectory_msgs::JointTrajectory>("joint_trajectory", 10);
    gripper_pub_ = nh.advertise<lfd_msgs::GripperCommand>("gripper/command", 10);
    planned_pub_ = nh.advertise<nav_msgs::Path>("executor/planned_path", 1, true);
    executed_pub_ = nh.advertise<nav_msgs::Path>("executor/executed_path", 1, true);
    marker_pub_ =
        nh.advertise<visualization_msgs::MarkerArray>("executor/segment_markers", 1, true);
    const auto hints = ros::TransportHints().tcpNoDelay();
    joint_sub_ = nh.subscribe("joint_states", 5, &Executor::onJoints, this, hints);
    gripper_sub_ = nh.subscribe("gripper/state", 5, &Executor::onGripper, this, hints);
    pnh_ = pnh;
    startServer();
    // A simulator restart takes sim time back to 0: the action server would drop every goal
    // stamped before its last one (RECALLED, no error text) until sim time caught up.
    if (ros::Time::isSimTime())
      // Relative names elsewhere (remappable); /clock is the master-wide sim time.
      clock_sub_ = nh.subscribe("/clock", 10, &Executor::onClock, this, hints);
    ROS_INFO("executor: ready (action %s/execute, dt %.4f s)", pnh.getNamespace().c_str(),
             options_.dt);
  }

 private:
  // ---- the action server and sim time going back -----------------------------------------------
  // The goal thread calls execute() with the server that owns it: while a restart destroys that
  // server (joining its goal thread), server_ already holds nothing.
  void startServer() {
    auto slot = std::make_shared<ActionServer*>(nullptr);
    server_ = std::make_unique<ActionServer>(
        pnh_, "execute",
        [this, slot](const lfd_msgs::ExecuteTaskGoalConstPtr& g) { execute(**slot, *g); }, false);
    *slot = server_.get();
    server_->start();
  }

  void onClock(const rosgraph_msgs::Clock::ConstPtr& msg) {
    const ros::Time before = last_clock_;
    last_clock_ = msg->clock;
    if (msg->clock >= before) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      clock_reset_text_ = "sim time went back from " + std::to_string(before.toSec()) + " to " +
                          std::to_string(msg->clock.toSec()) +
                          " s (the simulator restarted): the goal is aborted, send it again";
    }
    ROS_WARN(
        "executor: sim time went back from %.3f to %.3f s (the simulator restarted): "
        "aborting the active goal and restarting the action server, so that new goals "
        "stamped on the new clock are taken at once",
        before.toSec(), msg->clock.toSec());
    const ActionTopics keep(pnh_);
    clock_reset_ = true;  // the active goal (if any) aborts at its next check
    server_.reset();      // joins the goal thread
    clock_reset_ = false;
    startServer();
  }

  std::string clockResetText() {
    std::lock_guard<std::mutex> lock(mutex_);
    return clock_reset_text_;
  }

  // ---- configuration ---------------------------------------------------------------------------
  void loadParameters(ros::NodeHandle& pnh) {
    library_dir_ = pnh.param<std::string>("library_dir", "");
    robot_ = lfd::loadRobotSetup(pnh.param<std::string>("robot_file", ""));
    options_.dt = pnh.param("dt", options_.dt);
    options_.all_segment_goals = pnh.param("all_segment_goals", options_.all_segment_goals);
    options_.heading_frames = pnh.param("heading_frames", options_.heading_frames);
    options_.frames.min_heading_length =
        pnh.param("min_heading_length", options_.frames.min_heading_length);
    options_.gripper_threshold_fraction =
        pnh.param("gripper/threshold_fraction", options_.gripper_threshold_fraction);
    options_.gripper_hysteresis = pnh.param("gripper/hysteresis", options_.gripper_hysteresis);
    options_.gripper_min_range = pnh.param("gripper/min_range", options_.gripper_min_range);
    auto& gen = options_.generalization;
    gen.bandwidth = pnh.param("generalization/bandwidth", 0.0);
    gen.local_linear = pnh.param("generalization/local_linear", gen.local_linear);
    gen.slope_ridge = pnh.param("generalization/slope_ridge", gen.slope_ridge);
    gen.slope_ridge_candidates =
        pnh.param("generalization/slope_ridge_candidates", gen.slope_ridge_candidates);
    gen.range_margin = pnh.param("generalization/range_margin", gen.range_margin);
    options_.min_range_margin =
        pnh.param("generalization/min_range_margin", options_.min_range_margin);
    options_.min_range_angle =
        pnh.param("generalization/min_range_angle", options_.min_range_angle);
    monitoring_ = pnh.param("monitoring/enabled", monitoring_);
    stop_on_alarm_ = pnh.param("monitoring/stop_on_alarm", stop_on_alarm_);
    max_silence_ = pnh.param("monitoring/max_silence", max_silence_);
    if (!(max_silence_ > 0.0))
      throw std::runtime_error("executor: ~monitoring/max_silence must be > 0");
    min_wall_silence_ = pnh.param("monitoring/min_wall_silence", min_wall_silence_);
    max_frozen_ = pnh.param("monitoring/max_frozen", max_frozen_);
    if (!(max_frozen_ > 0.0))
      throw std::runtime_error("executor: ~monitoring/max_frozen must be > 0");
    if (!(min_wall_silence_ >= 0.0))
      throw std::runtime_error("executor: ~monitoring/min_wall_silence must be >= 0");
    loadFollowOptions(pnh);
    loadRecoveryOptions(pnh);
    loadSymmetries(pnh);
    settle_time_ = pnh.param("settle_time", settle_time_);
    clock_timeout_ = pnh.param("clock_timeout", clock_timeout_);
    motion_lead_ = pnh.param("motion_lead", motion_lead_);
    connect_timeout_ = pnh.param("connect_timeout", connect_timeout_);
    tf_timeout_ = pnh.param("tf_timeout", tf_timeout_);
    trajectory_period_ = pnh.param("trajectory_period", trajectory_period_);
    feedback_period_ = pnh.param("feedback_period", feedback_period_);
    paths_.allowed_roots = pnh.param("allowed_roots", paths_.allowed_roots);
    paths_.require_absolute = true;  // the node's working directory is not the caller's
    strings_.max_bytes = static_cast<std::size_t>(std::max(
        0, pnh.param("limits/max_request_string_bytes", static_cast<int>(strings_.max_bytes))));
    strings_.key = "~limits/max_request_string_bytes";
    limits_.min_duration_scale = pnh.param("limits/min_duration_scale", limits_.min_duration_scale);
    limits_.max_duration_scale = pnh.param("limits/max_duration_scale", limits_.max_duration_scale);
    limits_.max_plan_seconds = pnh.param("limits/max_plan_seconds", limits_.max_plan_seconds);
    limits_.quaternion_tolerance =
        pnh.param("limits/quaternion_tolerance", limits_.quaternion_tolerance);
    limits_.workspace_min = vectorParam(pnh, "limits/workspace_min", limits_.workspace_min);
    limits_.workspace_max = vectorParam(pnh, "limits/workspace_max", limits_.workspace_max);
    limits_.max_objects = pnh.param("limits/max_objects", static_cast<int>(limits_.max_objects));
    limits_.max_name_length =
        pnh.param("limits/max_name_length", static_cast<int>(limits_.max_name_length));
    lfd_dmp::checkLimits(limits_);
    loadLibraryLimits(pnh);
    if (!(options_.dt > 0.0) || !(settle_time_ >= 0.0) || !(clock_timeout_ > 0.0) ||
        !(motion_lead_ >= 0.0) || !(trajectory_period_ > 0.0))
      throw std::runtime_error(
          "executor: dt, clock_timeout, trajectory_period must be > 0 and "
          "settle_time, motion_lead >= 0");
    options_.max_samples = static_cast<size_t>(limits_.max_plan_seconds / options_.dt);
  }

  void loadLibraryLimits(ros::NodeHandle& pnh) {
    lfd_dmp::LibraryLimits& l = library_limits_;
    auto count = [&](const char* key, std::size_t fallback) {
      return static_cast<std::size_t>(
          std::max(0, pnh.param(std::string("library_limits/") + key, static_cast<int>(fallback))));
    };
    l.min_tau = pnh.param("library_limits/min_tau", l.min_tau);
    l.max_tau = pnh.param("library_limits/max_tau", l.max_tau);
    l.max_tau_ratio = pnh.param("library_limits/max_tau_ratio", l.max_tau_ratio);
    l.max_segments = count("max_segments", l.max_segments);
    l.max_demos = count("max_demos", l.max_demos);
    l.max_num_basis = static_cast<int>(count("max_num_basis", l.max_num_basis));
    l.max_list_length = count("max_list_length", l.max_list_length);
    l.max_string_length = count("max_string_length", l.max_string_length);
    l.max_file_bytes = count("max_file_megabytes", l.max_file_bytes >> 20) << 20;
    lfd_dmp::checkLibraryLimits(l);
  }

  // The IK chain on the robot model, built once (the URDF is on the parameter server).
  lfd_dmp::TaskPlanner& planner() {
    if (!planner_) {
      std::string urdf;
      if (!nh_.getParam("/robot_description", urdf))
        throw std::runtime_error("/robot_description is not set (the robot's URDF)");
      planner_ = std::make_unique<lfd_dmp::TaskPlanner>(lfd::makeCartesianToJoints(urdf, robot_));
    }
    return *planner_;
  }

  std::string cartesianFrame() const { return robot_.poseFrame(); }

  // ---- the request -----------------------------------------------------------------------------
  std::string libraryPath(const std::string& s) const {
    lfd_dmp::checkNameLength(s, "library", limits_);
    if (s.empty()) throw std::invalid_argument("library is empty (a path or a name)");
    if (s.find('/') != std::string::npos || (s.size() > 5 && s.substr(s.size() - 5) == ".json")) {
      lfd::checkRequestPath("library", s, paths_);
      return lfd::checkInputFile(s, paths_);
    }
    if (library_dir_.empty() || s == "." || s == "..")
      throw std::invalid_argument("'" + s + "' is not a path and ~library_dir is not set");
    return lfd::checkInputFile(library_dir_ + "/" + s + ".json", paths_);
  }

  // A pose of the request in the Cartesian frame, checked.
  lfd::Pose scenePose(const geometry_msgs::PoseStamped& ps, const std::string& what) {
    const auto& p = ps.pose.position;
    const auto& q = ps.pose.orientation;
    const lfd::Pose raw = lfd_dmp::checkedPose(Eigen::Vector3d(p.x, p.y, p.z),
                                               Eigen::Vector4d(q.w, q.x, q.y, q.z), what, limits_);
    lfd_dmp::checkNameLength(ps.header.frame_id, what + " frame", limits_);
    if (ps.header.frame_id.empty())
      throw std::invalid_argument(what + " has no header.frame_id (e.g. world)");
    const lfd::Pose out =
        lfd::toPose(transform(cartesianFrame(), ps.header.frame_id) * lfd::toIsometry(raw));
    lfd_dmp::checkInWorkspace(out, what, limits_);
    return out;
  }

  // The pose of `source` in `target` from tf, waited for at most ~tf_timeout of WALL time (tf's
  // own timeouts run on sim time, which a paused simulation never advances).
  Eigen::Isometry3d transform(const std::string& target, const std::string& source) {
    std::string why;
    const auto t0 = Clock::now();
    while (why.clear(), !tf_buffer_.canTransform(target, source, ros::Time(0), &why)) {
      if (wallSince(t0) > tf_timeout_ || !ros::ok())
        throw std::invalid_argument("no transform from '" + source + "' to '" + target +
                                    "' on tf: " + why);
      ros::WallDuration(0.01).sleep();
    }
    const geometry_msgs::Transform t =
        tf_buffer_.lookupTransform(target, source, ros::Time(0)).transform;
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
    iso.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z)
                       .normalized()
                       .toRotationMatrix();
    return iso;
  }

  lfd::Scene scene(const lfd_msgs::ExecuteTaskGoal& goal) {
    lfd_dmp::checkObjectNames(goal.object_names, goal.object_poses.size(), limits_);
    lfd::Scene s;
    for (size_t i = 0; i < goal.object_names.size(); ++i)
      s.objects[goal.object_names[i]] =
          scenePose(goal.object_poses[i], "object '" + goal.object_names[i] + "'");
    s.goal = scenePose(goal.goal, "goal");
    return s;
  }

  // The chain's joints now (and the gripper opening, when reported), waited for at most
  // ~connect_timeout of wall time.
  Eigen::VectorXd currentJoints(std::optional<double>* gripper) {
    const auto& names = planner().chain().jointNames();
    Eigen::VectorXd q(names.size());
    const auto t0 = Clock::now();
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        size_t found = 0;
        for (size_t i = 0; i < names.size(); ++i) {
          const auto it = joints_.find(names[i]);
          if (it == joints_.end()) break;
          q[static_cast<Eigen::Index>(i)] = it->second;
          ++found;
        }
        *gripper = gripper_;
        if (found == names.size()) return q;
      }
      if (wallSince(t0) > connect_timeout_)
        throw std::runtime_error("no /joint_states for the IK chain's joints (" + names.front() +
                                 ", ...) within ~connect_timeout");
      ros::WallDuration(0.01).sleep();
    }
  }

  void loadFollowOptions(ros::NodeHandle& pnh) {
    lfd_dmp::FollowOptions& f = follow_options_;
    f.enabled = pnh.param("follow_objects/enabled", f.enabled);
    f.check_period = pnh.param("follow_objects/check_period", f.check_period);
    f.min_shift = pnh.param("follow_objects/min_shift", f.min_shift);
    f.min_turn = pnh.param("follow_objects/min_turn", f.min_turn);
    f.lead = pnh.param("follow_objects/lead", f.lead);
    f.until_fraction = pnh.param("follow_objects/until_fraction", f.until_fraction);
    f.max_replans = static_cast<size_t>(
        std::max(0, pnh.param("follow_objects/max_replans", static_cast<int>(f.max_replans))));
    options_.goal_filter = pnh.param("follow_objects/goal_filter", options_.goal_filter);
    try {
      lfd_dmp::checkFollowOptions(f);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("executor: ~") + e.what());
    }
    if (!(options_.goal_filter > 0.0))
      throw std::runtime_error("executor: ~follow_objects/goal_filter must be > 0");
  }

  // ~object_symmetry: {<object>: {x: <order>, y: <order>, z: <order>}} (orders absent = 1).
  void loadSymmetries(ros::NodeHandle& pnh) {
    XmlRpc::XmlRpcValue all;
    if (!pnh.getParam("object_symmetry", all)) return;
    if (all.getType() != XmlRpc::XmlRpcValue::TypeStruct)
      throw std::runtime_error("executor: ~object_symmetry must map object names to {x, y, z}");
    for (auto& [name, orders] : all) {
      const auto order = [&, &name = name, &orders = orders](const char* axis) {
        if (orders.getType() != XmlRpc::XmlRpcValue::TypeStruct || !orders.hasMember(axis))
          return 1;
        if (orders[axis].getType() != XmlRpc::XmlRpcValue::TypeInt)
          throw std::runtime_error("executor: ~object_symmetry/" + name + "/" + axis +
                                   " must be an integer");
        return static_cast<int>(orders[axis]);
      };
      try {
        symmetries_[name] = lfd_dmp::symmetryOfOrders(order("x"), order("y"), order("z"));
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error("executor: ~object_symmetry/" + name + ": " + e.what());
      }
    }
  }

  void loadRecoveryOptions(ros::NodeHandle& pnh) {
    lfd_dmp::RecoveryOptions& r = recovery_;
    r.enabled = pnh.param("recovery/enabled", r.enabled);
    r.max_attempts = static_cast<size_t>(
        std::max(0, pnh.param("recovery/max_attempts", static_cast<int>(r.max_attempts))));
    r.retreat_speed_fraction =
        pnh.param("recovery/retreat_speed_fraction", r.retreat_speed_fraction);
    r.min_retreat_duration = pnh.param("recovery/min_retreat_duration", r.min_retreat_duration);
    r.release_time = pnh.param("recovery/release_time", r.release_time);
    r.settle_time = pnh.param("recovery/settle_time", r.settle_time);
    r.min_hold_time = pnh.param("recovery/min_hold_time", r.min_hold_time);
    r.min_held_opening = pnh.param("recovery/min_held_opening", r.min_held_opening);
    try {
      lfd_dmp::checkRecoveryOptions(r);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("executor: ~") + e.what());
    }
  }

  // ---- the action ------------------------------------------------------------------------------
  void execute(ActionServer& server, const lfd_msgs::ExecuteTaskGoal& goal) {
    const lfd::TrimHeapOnExit trim;  // the goal's library and plan go back to the system
    goal_server_ = &server;
    const auto wall0 = Clock::now();
    lfd_msgs::ExecuteTaskResult result;
    try {
      lfd::checkRequestStrings(goal, strings_);  // before any work: no 10 MB string echoed
      feedback_ = lfd_msgs::ExecuteTaskFeedback();
      feedback_.state = lfd_msgs::ExecuteTaskFeedback::PLANNING;
      goal_server_->publishFeedback(feedback_);
      lfd_dmp::ExecutorOptions opt = options_;
      opt.duration_scale = lfd_dmp::checkedDurationScale(goal.duration_scale, limits_);
      opt.allow_extrapolation = goal.allow_extrapolation;
      const std::string path = libraryPath(goal.library);
      const lfd_dmp::SkillLibrary library = lfd_dmp::loadSkillLibrary(path, library_limits_);
      if (library.cartesian_frame != cartesianFrame())
        throw std::invalid_argument("the library's poses are in '" + library.cartesian_frame +
                                    "', the robot's Cartesian frame is '" + cartesianFrame() + "'");
      const lfd::Scene s = lfd_dmp::canonicalScene(library, scene(goal), symmetries_);
      std::optional<double> gripper;
      const Eigen::VectorXd q = currentJoints(&gripper);
      std::vector<std::string> warnings;
      const auto targets =
          lfd_dmp::segmentTargets(library, s, planner().forward(q), opt, &warnings);
      for (const auto& t : targets) {
        result.extrapolation_distance = std::max(result.extrapolation_distance, t.range.distance);
        result.extrapolation_angle = std::max(result.extrapolation_angle, t.range.angle);
      }
      lfd_dmp::ExecutionPlan plan = planner().plan(library, targets, q, gripper, opt, [this] {
        return goal_server_->isPreemptRequested() || !ros::ok() || clock_reset_;
      });
      plan.warnings.insert(plan.warnings.begin(), warnings.begin(), warnings.end());
      // What the driver would refuse is refused here, with the reason in the result.
      lfd_dmp::checkTrajectoryVelocities(
          lfd_dmp::toJointTrajectory(plan, ros::Time(0), trajectory_period_),
          planner().chain().jointNames(), planner().chain().velocityLimits());
      describePlan(plan, wall0, &result);
      startMonitor(library, &result);
      ROS_INFO("executor: planned %s: %zu segments, %.2f s, IK residual %.2f mm, %.2f s wall",
               library.task.c_str(), plan.segments.size(), plan.duration(),
               plan.max_ik_position_error * 1e3, result.planning_time);
      if (!goal.dry_run) {
        context_ = GoalContext{&library, targets, s, planner().forward(q), q, gripper, opt, goal};
        startFollowing(plan);
        run(std::move(plan), &result);
      }
      result.success = true;
      goal_server_->setSucceeded(result);
    } catch (const lfd_dmp::PlanningCancelled& e) {
      finish(&result, clock_reset_ ? clockResetText() : e.what(), !clock_reset_);
    } catch (const Preempted& e) {
      finish(&result, e.what(), true);
    } catch (const lfd_dmp::OutsideDemoRange& e) {
      result.extrapolation_distance = e.distance;
      result.extrapolation_angle = e.angle;
      result.outside_demo_range = true;
      finish(&result, e.what(), false);
    } catch (const std::exception& e) {
      finish(&result, e.what(), false);
    }
    releaseGoalState();
  }

  // What the goal built up and nobody reads once it ended (its executed path, published; its
  // feedback): freed before the heap is trimmed, so an idle executor holds no goal's data.
  void releaseGoalState() {
    executed_ = nav_msgs::Path();
    feedback_ = lfd_msgs::ExecuteTaskFeedback();
    tracked_stamp_ = ros::Time();
    trackJoints({});
    following_.reset();
    context_.reset();
    untrusted_sensors_ = false;
    monitor_.reset();  // its subscriptions end with the goal
  }

  // From now on, each joint state of `names` is kept for track() (none: no longer kept).
  void trackJoints(const std::vector<std::string>& names) {
    std::lock_guard<std::mutex> lock(mutex_);
    tracked_joints_ = names;
    unread_joint_states_.clear();
  }

  void finish(lfd_msgs::ExecuteTaskResult* result, const std::string& error, bool preempted) {
    result->success = false;
    result->error = error;
    if (preempted) {
      ROS_WARN("executor: %s", error.c_str());
      goal_server_->setPreempted(*result, error);
    } else {
      ROS_ERROR("executor: %s", error.c_str());
      goal_server_->setAborted(*result, error);
    }
  }

  void describePlan(const lfd_dmp::ExecutionPlan& plan, Clock::time_point wall0,
                    lfd_msgs::ExecuteTaskResult* result) {
    result->planning_time = wallSince(wall0);
    result->planned_duration = plan.duration();
    result->warnings = plan.warnings;
    result->extrapolation_distance = plan.extrapolation_distance;
    result->extrapolation_angle = plan.extrapolation_angle;
    result->outside_demo_range = plan.outside_demo_range;
    for (const auto& w : plan.warnings) ROS_WARN("executor: %s", w.c_str());
    for (const auto& s : plan.segments) {
      result->segment_names.push_back(s.name);
      result->segment_frames.push_back(s.frames);
      result->segment_slope_ridges.push_back(s.slope_ridge);
      result->segment_durations.push_back(s.duration);
    }
    const ros::Time now = ros::Time::now();
    planned_pub_.publish(lfd_dmp::plannedPath(plan, cartesianFrame(), now));
    marker_pub_.publish(lfd_dmp::segmentMarkers(plan, cartesianFrame(), now));
  }

  // ---- the motion ------------------------------------------------------------------------------
  void waitForDriver(const ros::Publisher& pub) {
    const auto t0 = Clock::now();
    while (pub.getNumSubscribers() == 0) {
      if (wallSince(t0) > connect_timeout_ || !ros::ok())
        throw std::runtime_error("nobody subscribes to " + pub.getTopic() +
                                 " (is the robot driver running?)");
      ros::WallDuration(0.01).sleep();
    }
  }

  // A grasp the monitor found lost (recover() retries it).
  struct LostGrasp {
    lfd::Deviation alarm;
    ros::Time t0, now;  // the motion's start, and when the alarm was seen
  };

  void run(lfd_dmp::ExecutionPlan plan, lfd_msgs::ExecuteTaskResult* result) {
    waitForDriver(trajectory_pub_);
    if (!plan.gripper_events.empty()) waitForDriver(gripper_pub_);
    waitForSensors(result);
    while (std::optional<LostGrasp> lost = runMotion(plan, result))
      plan = recover(*lost, plan, result);
  }

  // One motion: the plan sent and followed to its end (and settled); or, when the monitor finds
  // the grasp lost and a retry is left, the arm held and what recover() needs.
  std::optional<LostGrasp> runMotion(lfd_dmp::ExecutionPlan& plan,
                                     lfd_msgs::ExecuteTaskResult* result) {
    // The whole motion is sent ahead, stamped on the driver's clock: it runs at sim time whatever
    // the load, and a lockstep client only has to step.
    const ros::Time t0 = ros::Time::now() + ros::Duration(motion_lead_);
    trajectory_pub_.publish(lfd_dmp::toJointTrajectory(plan, t0, trajectory_period_));
    for (const lfd_dmp::GripperEvent& e : plan.gripper_events)
      gripper_pub_.publish(lfd_dmp::gripperCommand(e.close, robot_.gripper,
                                                   t0 + ros::Duration(plan.times[e.sample])));
    if (result->motion_start.isZero()) result->motion_start = t0;
    if (monitor_) monitor_->start(plan, t0);
    feedback_.monitor_alarm.clear();  // this motion's first alarm (the result keeps the goal's)
    trackJoints(plan.joint_names);
    executed_ = nav_msgs::Path();
    feedback_.motion_start = t0;
    feedback_.planned_duration = plan.duration();
    setState(lfd_msgs::ExecuteTaskFeedback::MOVING, plan);
    ros::Time t_end = t0 + ros::Duration(plan.duration());
    ClockWatch watch(clock_timeout_);
    ros::Time reached, settled;
    for (;;) {
      const ros::Time now = ros::Time::now();
      checkRunning(plan, t0, now, &watch);
      const ros::Time measured = track(plan, t0, t_end, &reached);
      if (const auto lost = checkMonitor(plan, t0, now, measured, result))
        return LostGrasp{*lost, t0, now};
      if (following_ && now < t_end && now >= following_->next_look &&
          followObjects(t0, now, &plan, result))
        t_end = t0 + ros::Duration(plan.duration());
      if (now >= t_end) {
        if (feedback_.state != lfd_msgs::ExecuteTaskFeedback::SETTLING)
          setState(lfd_msgs::ExecuteTaskFeedback::SETTLING, plan);
        if (now >= t_end + ros::Duration(settle_time_)) {
          // The final state as measured: SETTLING went out when the plan's time was over, with
          // the progress of the last joint sample then, which lags on a loaded machine (a fresh
          // root: 0.75 s behind the clock, progress 0.97). The joint states up to the plan's end
          // were published before the clock passed it: they are waited for, 1 wall s at most.
          // The TCP counts as arrived only within the settle (a lockstep client may go on
          // stepping meanwhile).
          const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(1.0);
          while (track(plan, t0, t_end, &reached) < t_end && ros::WallTime::now() < deadline)
            ros::WallDuration(0.001).sleep();
          if (reached > now) reached = ros::Time();
          settled = now;
          publishFeedback();
          break;
        }
      }
      ros::WallDuration(0.001).sleep();
    }
    if (reached.isZero()) {
      reached = settled;  // the settle's end
      result->warnings.push_back(
          "the TCP did not come within the IK tolerance of its final pose "
          "in ~settle_time");
    }
    endMonitor(result);
    result->execution_time = (reached - result->motion_start).toSec();
    result->final_position_error = feedback_.tcp_position_error;
    result->final_orientation_error = feedback_.tcp_orientation_error;
    executed_pub_.publish(executed_);
    ROS_INFO("executor: done in %.2f s sim (planned %.2f s), final TCP error %.1f mm / %.3f rad",
             result->execution_time, plan.duration(), result->final_position_error * 1e3,
             result->final_orientation_error);
    return std::nullopt;
  }

  // What every cycle of a motion checks: the simulator restarted, a cancel (the arm holds where
  // `plan` started at t0 is now), sim time standing still.
  void checkRunning(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0, const ros::Time& now,
                    ClockWatch* watch) {
    if (clock_reset_) throw std::runtime_error(clockResetText());
    if (goal_server_->isPreemptRequested() || !ros::ok()) stop(plan, t0, now);
    watch->check(now);
  }

  // Holds the arm where the plan is now and keeps the gripper as the plan has it now (a later
  // stamped command would still fire otherwise), then ends the goal as preempted.
  [[noreturn]] void stop(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0,
                         const ros::Time& now) {
    const size_t k = hold(plan, t0, now);
    throw Preempted("preempted at t=" + std::to_string((now - t0).toSec()) +
                    " s of the motion, in segment '" + segmentAt(plan, k).name +
                    "'; the arm holds there");
  }

  // ---- goals that follow a moving object (lfd_dmp/object_following.hpp) -----------------------
  // What a replan or a retry needs: the goal's library and the targets of the running plan, the
  // scene as it has it, where the task started, where this plan started, and the goal itself (an
  // object pose in a frame that moves with the object is looked up on tf again: followed).
  struct GoalContext {
    const lfd_dmp::SkillLibrary* library = nullptr;
    std::vector<lfd_dmp::SegmentTarget> targets;
    lfd::Scene scene;
    lfd_dmp::TcpPose start;
    Eigen::VectorXd q_start;
    std::optional<double> gripper_start;
    lfd_dmp::ExecutorOptions options;
    lfd_msgs::ExecuteTaskGoal goal;
  };
  struct Following {
    std::vector<lfd_dmp::TargetUpdate> updates;
    std::map<std::string, double> windows;  // s into the plan each object is followed until
    ros::Time next_look;
  };

  void startFollowing(const lfd_dmp::ExecutionPlan& plan) {
    following_.reset();
    if (!follow_options_.enabled) return;
    auto windows = lfd_dmp::followWindows(*context_->library, plan, follow_options_);
    if (windows.empty()) return;
    following_ = Following{{}, std::move(windows), ros::Time()};
  }

  // Looks at the followed objects; when one moved, plans the rest of the motion toward it from
  // ~follow_objects/lead ahead, sends it (it replaces the running trajectory from then on) and
  // returns true. A moved goal that cannot be planned (out of reach, outside the demonstrated
  // range) holds the arm and fails the goal.
  bool followObjects(const ros::Time& t0, const ros::Time& now, lfd_dmp::ExecutionPlan* plan,
                     lfd_msgs::ExecuteTaskResult* result) {
    Following& f = *following_;
    f.next_look = now + ros::Duration(follow_options_.check_period);
    const double elapsed = (now - t0).toSec();
    const std::map<std::string, lfd::Pose> seen = objectsNow(f);
    const auto moves =
        lfd_dmp::movedObjects(context_->scene, seen, f.windows, elapsed, follow_options_);
    if (moves.empty()) return false;
    const double at = elapsed + follow_options_.lead;
    if (f.updates.size() >= follow_options_.max_replans || at >= plan->duration()) {
      result->warnings.push_back(
          "not followed (" + std::to_string(f.updates.size()) +
          " replans already, ~follow_objects/max_replans): " + lfd_dmp::describeMoves(moves));
      following_.reset();
      return false;
    }
    setState(lfd_msgs::ExecuteTaskFeedback::REPLANNING, *plan);
    lfd::Scene scene = context_->scene;
    // Only the moved ones: an object the robot holds or pushes by now keeps its planned pose.
    for (const lfd_dmp::ObjectMove& m : moves) scene.objects[m.object] = seen.at(m.object);
    lfd_dmp::ExecutionPlan next;
    try {
      std::vector<std::string> warnings;
      f.updates.push_back({at, lfd_dmp::segmentTargets(*context_->library, scene, context_->start,
                                                       context_->options, &warnings)});
      next = planner().replan(*context_->library, context_->targets, f.updates, *plan,
                              context_->q_start, context_->gripper_start, context_->options);
    } catch (const std::exception& e) {
      hold(*plan, t0, ros::Time::now());
      throw std::runtime_error("the goal moved (" + lfd_dmp::describeMoves(moves) +
                               ") and cannot be followed: " + e.what() + "; the arm holds there");
    }
    if (ros::Time::now() + ros::Duration(0.5 * follow_options_.check_period) >
        t0 + ros::Duration(at)) {  // planned too slowly: the next look plans again, further ahead
      f.updates.pop_back();
      setState(lfd_msgs::ExecuteTaskFeedback::MOVING, *plan);
      return false;
    }
    // Sent from ~motion_lead ahead, carrying the unchanged plan up to `at`. The bridge replaces
    // the running trajectory when the new one arrives (holding its first point until its stamp),
    // and one arriving after its stamp starts late, the whole rest shifted: stamped at "now", a
    // lockstep client's next step (50 ms) served before the message left the arm 2.5 cm behind
    // its plan in one fresh-root run. The lead absorbs that; its cost is a target 0.1 s ahead.
    sendFrom(next, t0, std::min(at, (ros::Time::now() - t0).toSec() + motion_lead_));
    context_->scene = scene;
    *plan = std::move(next);
    if (monitor_) monitor_->retime(*plan);
    std::ostringstream line;
    line.precision(3);
    line << "at " << elapsed << " s into the motion: " << lfd_dmp::describeMoves(moves)
         << "; the motion follows it from " << at << " s";
    result->replans.push_back(line.str());
    ROS_INFO("executor: %s", result->replans.back().c_str());
    feedback_.planned_duration = plan->duration();
    setState(lfd_msgs::ExecuteTaskFeedback::MOVING, *plan);
    return true;
  }

  // Where the followed objects are now, each looked up on tf without waiting (an object not seen
  // now is not moved).
  std::map<std::string, lfd::Pose> objectsNow(const Following& f) {
    std::map<std::string, lfd::Pose> out;
    const std::vector<std::string>& names = context_->goal.object_names;
    for (size_t i = 0; i < names.size(); ++i) {
      const geometry_msgs::PoseStamped& ps = context_->goal.object_poses[i];
      if (!f.windows.count(names[i]) || ps.header.frame_id == cartesianFrame() ||
          !tf_buffer_.canTransform(cartesianFrame(), ps.header.frame_id, ros::Time(0)))
        continue;
      try {
        out[names[i]] = scenePose(ps, "object '" + names[i] + "'");
        const auto symmetric = symmetries_.find(names[i]);
        if (symmetric != symmetries_.end())
          out[names[i]] = lfd_dmp::canonicalPose(*context_->library, names[i], out[names[i]],
                                                 symmetric->second);
      } catch (const std::exception&) {  // gone from tf between the two calls: not seen
      }
    }
    return out;
  }

  // The plan from `from` s on replaces what the driver runs, gripper included: a command stamped
  // then drops the later ones pending (bridge and driver), then the plan's later events.
  void sendFrom(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0, double from) {
    size_t k = 0;
    while (k + 1 < plan.times.size() && plan.times[k] < from) ++k;
    trajectory_pub_.publish(lfd_dmp::toJointTrajectory(plan, t0, trajectory_period_, k));
    const lfd_dmp::GripperEvent* last = nullptr;
    for (const lfd_dmp::GripperEvent& e : plan.gripper_events)
      if (e.sample <= k) last = &e;
    if (last)
      gripper_pub_.publish(
          lfd_dmp::gripperCommand(last->close, robot_.gripper, t0 + ros::Duration(plan.times[k])));
    for (const lfd_dmp::GripperEvent& e : plan.gripper_events)
      if (e.sample > k)
        gripper_pub_.publish(lfd_dmp::gripperCommand(e.close, robot_.gripper,
                                                     t0 + ros::Duration(plan.times[e.sample])));
  }

  // ---- execution monitoring (lfd_dmp/execution_monitor.hpp) -----------------------------------
  // A library with a sensory signature is monitored when ~monitoring/enabled; a signature whose
  // sensors cannot be subscribed is a warning, not a failure (the motion runs unmonitored).
  void startMonitor(const lfd_dmp::SkillLibrary& library, lfd_msgs::ExecuteTaskResult* result) {
    monitor_.reset();
    if (!monitoring_ || !library.sensory_signature) return;
    try {
      monitor_ = std::make_unique<lfd_dmp::ExecutionMonitor>(
          nh_, *library.sensory_signature, max_silence_, min_wall_silence_, max_frozen_);
      result->monitored = true;
    } catch (const std::invalid_argument& e) {
      result->warnings.push_back(std::string("not monitored: ") + e.what());
    }
  }

  // `measured`: the latest joint state's stamp, the time the sensors' stamps are compared with.
  // The monitor's topics connected before the motion starts (a lockstep client steps at once):
  // else their first messages are lost and the sensor looks silent. A topic that no publisher
  // serves within ~connect_timeout leaves the motion unmonitored, with a warning.
  void waitForSensors(lfd_msgs::ExecuteTaskResult* result) {
    const auto t0 = Clock::now();
    while (monitor_ && !monitor_->unconnected().empty()) {
      if (wallSince(t0) > connect_timeout_ || !ros::ok()) {
        result->warnings.push_back("not monitored: no publisher of " +
                                   monitor_->unconnected().front() + " within ~connect_timeout");
        ROS_WARN("executor: %s", result->warnings.back().c_str());
        monitor_.reset();
        result->monitored = false;
        return;
      }
      ros::WallDuration(0.01).sleep();
    }
  }

  // Returns the lost grasp that recover() retries (~recovery/*: enabled, an attempt left); a lost
  // grasp is looked for even after an earlier alarm (a yank) was reported. A lost grasp with no
  // attempt left fails the goal; any other alarm is reported, or stops the motion
  // (~monitoring/stop_on_alarm).
  std::optional<lfd::Deviation> checkMonitor(const lfd_dmp::ExecutionPlan& plan,
                                             const ros::Time& t0, const ros::Time& now,
                                             const ros::Time& measured,
                                             lfd_msgs::ExecuteTaskResult* result) {
    if (!monitor_) return std::nullopt;
    feedback_.anomaly_score = std::max(feedback_.anomaly_score, monitor_->worst().score);
    std::optional<lfd::Deviation> lost = monitor_->takeLatestAlarm();
    const std::optional<lfd_dmp::Frozen> frozen = monitor_->frozen(measured);
    // A sensor that froze once is not trusted again during the goal (it may freeze again; a retry
    // restarts the monitor's clock, and its last readings before the end are no longer judged).
    untrusted_sensors_ = untrusted_sensors_ || frozen.has_value();
    if (!recovery_.enabled || untrusted_sensors_ ||
        (lost && !lfd_dmp::lostGrasp(*lost, plan, recovery_, robot_.gripper.close_opening)))
      lost.reset();
    if (!lost && !feedback_.monitor_alarm.empty()) return std::nullopt;
    std::string text;
    if (lost) {
      text = lfd_dmp::describeAlarm(*lost, plan.segments);
    } else if (const std::optional<lfd::Deviation> alarm = monitor_->alarm()) {
      text = lfd_dmp::describeAlarm(*alarm, plan.segments);
    } else if (const std::optional<lfd_dmp::Silence> silent = monitor_->silence(measured)) {
      text = lfd_dmp::describeSilence(*silent, plan.segments);
      feedback_.anomaly_score = std::max(feedback_.anomaly_score, silent->gap / silent->allowed);
    } else if (frozen) {
      text = lfd_dmp::describeFrozen(*frozen, plan.segments);
      feedback_.anomaly_score =
          std::max(feedback_.anomaly_score, frozen->unchanged / frozen->allowed);
    } else {
      return std::nullopt;
    }
    feedback_.monitor_alarm = text;
    if (result->monitor_alarm.empty()) result->monitor_alarm = text;  // the goal's first
    result->max_anomaly_score = feedback_.anomaly_score;
    publishFeedback();
    if (lost && result->recoveries.size() < recovery_.max_attempts) return lost;
    if (!lost && !stop_on_alarm_) {
      ROS_WARN("executor: monitor: %s", text.c_str());
      return std::nullopt;
    }
    hold(plan, t0, now);
    monitor_->stop();
    if (lost)
      throw std::runtime_error(
          "the grasp was lost after " + std::to_string(result->recoveries.size()) +
          " recoveries (~recovery/max_attempts): " + text + "; the arm holds there");
    throw std::runtime_error("stopped by the execution monitor: " + text + "; the arm holds there");
  }

  // ---- recovery after a lost grasp (lfd_dmp/recovery.hpp) -------------------------------------
  // Holds the arm and opens the gripper, goes back to the last boundary that held, looks at the
  // objects again (a pose given in a frame that moves with its object is looked up on tf) and
  // plans the task from there. Returns that plan; throws, the arm holding, when it cannot be
  // planned (the object out of reach or outside the demonstrated range now).
  lfd_dmp::ExecutionPlan recover(const LostGrasp& lost, const lfd_dmp::ExecutionPlan& plan,
                                 lfd_msgs::ExecuteTaskResult* result) {
    setState(lfd_msgs::ExecuteTaskFeedback::RECOVERING, plan);
    const size_t k = hold(plan, lost.t0, lost.now);
    gripper_pub_.publish(lfd_dmp::gripperCommand(false, robot_.gripper, lost.now));
    monitor_->stop();
    following_.reset();
    const size_t retry = lfd_dmp::retrySegment(*context_->library, plan, k);
    const std::string boundary = "the start of segment '" + plan.segments[retry].name + "'";
    retreat(plan.joints[plan.segments[retry].begin]);
    lfd_dmp::ExecutorOptions opt = context_->options;
    opt.first_segment = retry;
    std::optional<double> gripper;
    const Eigen::VectorXd q = currentJoints(&gripper);
    lfd_dmp::ExecutionPlan next;
    try {
      const lfd::Scene seen =
          lfd_dmp::canonicalScene(*context_->library, scene(context_->goal), symmetries_);
      std::vector<std::string> warnings;
      auto targets =
          lfd_dmp::segmentTargets(*context_->library, seen, context_->start, opt, &warnings);
      next = planner().plan(*context_->library, targets, q, gripper, opt, [this] {
        return goal_server_->isPreemptRequested() || !ros::ok() || clock_reset_;
      });
      lfd_dmp::checkTrajectoryVelocities(
          lfd_dmp::toJointTrajectory(next, ros::Time(0), trajectory_period_),
          planner().chain().jointNames(), planner().chain().velocityLimits());
      *context_ =
          GoalContext{context_->library, std::move(targets), seen, context_->start, q, gripper, opt,
                      context_->goal};
    } catch (const lfd_dmp::PlanningCancelled&) {
      throw;
    } catch (const std::exception& e) {
      throw std::runtime_error("the grasp was lost (" + feedback_.monitor_alarm +
                               ") and the retry cannot be planned: " + e.what() +
                               "; the arm holds at " + boundary);
    }
    // A gripper that does not open (broken, or holding on to something) would reach for the object
    // closed: no retry.
    if (!next.gripper_events.empty() && next.gripper_events.front().close &&
        !lfd_dmp::gripperClosedAt(plan, plan.segments[retry].begin)) {
      std::ostringstream m;
      m << "the grasp was lost (" << feedback_.monitor_alarm << ") and the gripper does not open "
        << "(it reads " << gripper.value_or(NAN) << " after ~recovery/release_time): no retry; "
        << "the arm holds at " << boundary;
      throw std::runtime_error(m.str());
    }
    std::ostringstream line;
    line.precision(3);
    line << "at " << lost.alarm.time << " s into the motion the grasp was lost ("
         << lost.alarm.channel_name << " measured " << lost.alarm.measured
         << ", the demonstrations showed " << lost.alarm.expected << "): the gripper opened, the "
         << "arm went back to " << boundary << " and the task was planned again from there "
         << "(attempt " << result->recoveries.size() + 1 << " of " << recovery_.max_attempts << ")";
    result->recoveries.push_back(line.str());
    ROS_WARN("executor: %s", result->recoveries.back().c_str());
    const ros::Time now = ros::Time::now();
    planned_pub_.publish(lfd_dmp::plannedPath(next, cartesianFrame(), now));
    marker_pub_.publish(lfd_dmp::segmentMarkers(next, cartesianFrame(), now));
    startFollowing(next);
    feedback_.planned_duration = next.duration();
    return next;
  }

  // A slow joint-space move to `q_back` once the gripper had ~recovery/release_time to open;
  // returns when the arm has had ~recovery/settle_time of sim time there.
  void retreat(const Eigen::VectorXd& q_back) {
    std::optional<double> gripper;
    const lfd_dmp::ExecutionPlan back =
        lfd_dmp::retreatPlan(planner(), currentJoints(&gripper), q_back, options_.dt, recovery_);
    const ros::Time start =
        ros::Time::now() + ros::Duration(std::max(motion_lead_, recovery_.release_time));
    trajectory_pub_.publish(lfd_dmp::toJointTrajectory(back, start, trajectory_period_));
    trackJoints(back.joint_names);
    const ros::Time arrived = start + ros::Duration(back.duration());
    ClockWatch watch(clock_timeout_);
    ros::Time reached;
    for (;;) {
      const ros::Time now = ros::Time::now();
      checkRunning(back, start, now, &watch);
      track(back, start, arrived, &reached);
      if (now >= arrived + ros::Duration(recovery_.settle_time)) return;
      ros::WallDuration(0.001).sleep();
    }
  }

  void endMonitor(lfd_msgs::ExecuteTaskResult* result) {
    if (!monitor_) return;
    monitor_->stop();
    result->max_anomaly_score = std::max(feedback_.anomaly_score, monitor_->worst().score);
    if (!monitor_->problem().empty())
      result->warnings.push_back("monitor: sensor data not read: " + monitor_->problem());
    ROS_INFO("executor: monitored, worst anomaly score %.2f", result->max_anomaly_score);
  }

  // Holds the arm where the plan is at `now`, and the gripper as the plan has it then; returns the
  // plan's sample there.
  size_t hold(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0, const ros::Time& now) {
    const size_t k = sampleAt(plan, t0, now);
    trajectory_pub_.publish(lfd_dmp::holdTrajectory(plan.joint_names, plan.joints[k], now));
    const lfd_dmp::GripperEvent* last = nullptr;
    for (const lfd_dmp::GripperEvent& e : plan.gripper_events)
      if (!last || e.sample <= k) last = &e;
    if (last) gripper_pub_.publish(lfd_dmp::gripperCommand(last->close, robot_.gripper, now));
    executed_pub_.publish(executed_);
    return k;
  }

  static size_t sampleAt(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0,
                         const ros::Time& t) {
    const double elapsed = (t - t0).toSec();
    if (!(elapsed > 0.0)) return 0;
    return std::min(plan.times.size() - 1, static_cast<size_t>(elapsed / plan.dt));
  }

  static const lfd_dmp::PlannedSegment& segmentAt(const lfd_dmp::ExecutionPlan& plan, size_t k) {
    for (const auto& s : plan.segments)
      if (k < s.end) return s;
    return plan.segments.back();
  }

  // Every joint state that arrived since the last call, in order, against the plan (into feedback_,
  // published every ~feedback_period and at each new segment); returns the latest one's stamp.
  // `reached` gets the stamp of the first state at or after `t_end` within the IK tolerance: taken
  // from the states themselves, not from whichever is latest when this loop next runs, so a stall
  // of this thread (while a lockstep client steps the clock on) does not lengthen the measurement.
  ros::Time track(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0, const ros::Time& t_end,
                  ros::Time* reached) {
    std::deque<JointSample> arrived;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      arrived.swap(unread_joint_states_);
    }
    for (const JointSample& sample : arrived) {
      if (sample.stamp == tracked_stamp_) continue;
      tracked_stamp_ = sample.stamp;
      compareWithPlan(plan, t0, sample);
      if (reached->isZero() && sample.stamp >= t_end &&
          feedback_.tcp_position_error <= robot_.ik_tolerance.position &&
          feedback_.tcp_orientation_error <= robot_.ik_tolerance.orientation)
        *reached = sample.stamp;
    }
    // Also while nothing changes (a paused clock): a client that missed one still learns the state.
    if (wallSince(last_feedback_) > feedback_period_) publishFeedback();
    return tracked_stamp_;
  }

  void compareWithPlan(const lfd_dmp::ExecutionPlan& plan, const ros::Time& t0,
                       const JointSample& sample) {
    const size_t k = sampleAt(plan, t0, sample.stamp);
    const lfd::Pose tcp = planner().forward(sample.q);
    feedback_.tcp_position_error = (tcp.position - plan.poses[k].position).norm();
    feedback_.tcp_orientation_error = tcp.orientation.angularDistance(plan.poses[k].orientation);
    feedback_.progress =
        plan.duration() > 0 ? std::min(1.0, (sample.stamp - t0).toSec() / plan.duration()) : 1.0;
    feedback_.progress = std::max(0.0, feedback_.progress);
    const auto& seg = segmentAt(plan, k);
    feedback_.segment_index = static_cast<uint32_t>(&seg - plan.segments.data());
    recordExecuted(tcp, sample.stamp);
    if (feedback_.segment != seg.name) {
      feedback_.segment = seg.name;
      publishFeedback();
    }
  }

  void setState(uint8_t state, const lfd_dmp::ExecutionPlan& plan) {
    feedback_.state = state;
    if (feedback_.segment.empty()) feedback_.segment = plan.segments.front().name;
    publishFeedback();
  }

  void publishFeedback() {
    goal_server_->publishFeedback(feedback_);
    last_feedback_ = Clock::now();
  }

  void recordExecuted(const lfd::Pose& tcp, const ros::Time& stamp) {
    if (!executed_.poses.empty() && (stamp - executed_.poses.back().header.stamp).toSec() < 0.02)
      return;
    geometry_msgs::PoseStamped ps;
    ps.header.frame_id = executed_.header.frame_id = cartesianFrame();
    ps.header.stamp = executed_.header.stamp = stamp;
    ps.pose = lfd_dmp::toPoseMsg(tcp);
    executed_.poses.push_back(ps);
    if (executed_.poses.size() % 25 == 0) executed_pub_.publish(executed_);
  }

  // ---- robot state -----------------------------------------------------------------------------
  void onJoints(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < msg->name.size() && i < msg->position.size(); ++i)
      if (std::isfinite(msg->position[i])) joints_[msg->name[i]] = msg->position[i];
    if (tracked_joints_.empty()) return;
    JointSample sample{msg->header.stamp, Eigen::VectorXd(tracked_joints_.size())};
    for (size_t i = 0; i < tracked_joints_.size(); ++i) {
      const auto it = joints_.find(tracked_joints_[i]);
      if (it == joints_.end()) return;
      sample.q[static_cast<Eigen::Index>(i)] = it->second;
    }
    unread_joint_states_.push_back(std::move(sample));
    // Bounded: a goal thread that stopped reading (it is planning) keeps the newest states only.
    if (unread_joint_states_.size() > kMaxUnreadJointStates) unread_joint_states_.pop_front();
  }

  void onGripper(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < msg->name.size() && i < msg->position.size(); ++i)
      if (msg->name[i] == robot_.gripper.joint && std::isfinite(msg->position[i]))
        gripper_ = msg->position[i];
  }

  ros::NodeHandle nh_;
  std::string library_dir_;
  lfd::RobotSetup robot_;
  lfd::PathPolicy paths_;
  lfd::StringBudget strings_;  // ~limits/max_request_string_bytes of every goal string
  lfd_dmp::ExecutorOptions options_;
  lfd_dmp::RequestLimits limits_;
  lfd_dmp::LibraryLimits library_limits_;
  double settle_time_ = 0.5, clock_timeout_ = 5.0, motion_lead_ = 0.1, connect_timeout_ = 5.0;
  double tf_timeout_ = 1.0;
  double trajectory_period_ = 0.01, feedback_period_ = 0.05;
  std::unique_ptr<lfd_dmp::TaskPlanner> planner_;
  bool monitoring_ = true, stop_on_alarm_ = false;
  double max_silence_ = 2.0;        // s (executor.yaml monitoring/max_silence)
  double min_wall_silence_ = 0.5;   // wall s (executor.yaml monitoring/min_wall_silence)
  double max_frozen_ = 0.5;         // s (executor.yaml monitoring/max_frozen)
  bool untrusted_sensors_ = false;  // the current goal's: a monitored sensor froze
  std::unique_ptr<lfd_dmp::ExecutionMonitor> monitor_;         // the current goal's
  lfd_dmp::FollowOptions follow_options_;                      // executor.yaml follow_objects/*
  std::optional<GoalContext> context_;                         // the current goal's
  std::optional<Following> following_;                         // the current goal's
  lfd_dmp::RecoveryOptions recovery_;                          // executor.yaml recovery/*
  std::map<std::string, lfd_dmp::ObjectSymmetry> symmetries_;  // executor.yaml object_symmetry
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Publisher trajectory_pub_, gripper_pub_, planned_pub_, executed_pub_, marker_pub_;
  ros::Subscriber joint_sub_, gripper_sub_;
  ros::NodeHandle pnh_;
  std::unique_ptr<ActionServer> server_;
  ActionServer* goal_server_ = nullptr;  // the server whose goal thread runs execute()
  ros::Subscriber clock_sub_;
  ros::Time last_clock_;  // the newest /clock (its callbacks never overlap)
  std::atomic<bool> clock_reset_{false};
  std::string clock_reset_text_;
  lfd_msgs::ExecuteTaskFeedback feedback_;
  Clock::time_point last_feedback_;
  ros::Time tracked_stamp_;
  nav_msgs::Path executed_;
  std::mutex mutex_;
  std::map<std::string, double> joints_;
  std::vector<std::string> tracked_joints_;      // the running plan's joints (none: not tracked)
  std::deque<JointSample> unread_joint_states_;  // of tracked_joints_, not yet read by track()
  static constexpr size_t kMaxUnreadJointStates = 4096;
  std::optional<double> gripper_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "executor");
  ros::NodeHandle nh, pnh("~");
  // A restarted master: the node ends, to be respawned (with the robot model and the clock choice
  // its launch file had set).
  const lfd_ros::MasterWatch master_watch({"/use_sim_time", "/robot_description"});
  try {
    Executor executor(nh, pnh);
    // Several threads: the action's goal thread plans and monitors while state callbacks and
    // cancel requests keep arriving.
    ros::AsyncSpinner spinner(4);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("executor: %s", e.what());
    return 1;
  }
  return master_watch.exitCode();
}
