// executor_node: reproduces a learned task toward a new goal (paper III, reproduction).
//   service ~execute (lfd_msgs/ExecuteTask)  plan (generalize + roll out + IK-check) then stream
//   service ~cancel  (std_srvs/Trigger)      stops a running execution (the arm holds its target)
//   topic   ~progress (std_msgs/Float64)     fraction of the planned samples streamed
//   topics  /executor/planned_path, /executor/executed_path (nav_msgs/Path, base_link),
//           /executor/segment_markers (visualization_msgs/MarkerArray)
//   out     /joint_command (sensor_msgs/JointState), /gripper/command (lfd_msgs/GripperCommand)
//   in      /joint_states, /gripper/state, /ee_pose
// The logic is lfd_dmp::TaskPlanner (lib/executor.cpp); this file is ROS I/O and sim-time pacing.
// Parameters: config/executor.yaml (loaded by launch/reproduce.launch).
#include "lfd_dmp/executor.hpp"
#include "lfd_core/robot_setup.hpp"
#include "lfd_sim_bridge/pose_msg.hpp"

#include <lfd_msgs/ExecuteTask.h>
#include <lfd_msgs/GripperCommand.h>
#include <lfd_sim_bridge/demo_tasks.hpp>

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

namespace {

double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

// YAML numbers may be ints or doubles; anything else is a configuration error.
double number(XmlRpc::XmlRpcValue& v, const std::string& what) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
  throw std::runtime_error("executor: ~tasks: " + what + " must be a number");
}

std::string text(XmlRpc::XmlRpcValue& v, const std::string& what) {
  if (v.getType() != XmlRpc::XmlRpcValue::TypeString)
    throw std::runtime_error("executor: ~tasks: " + what + " must be a string");
  return static_cast<std::string>(v);
}

bool finitePose(const geometry_msgs::Pose& p) {
  for (double v : {p.position.x, p.position.y, p.position.z, p.orientation.w, p.orientation.x,
                   p.orientation.y, p.orientation.z})
    if (!std::isfinite(v)) return false;
  return true;
}

class Executor {
 public:
  Executor(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
    pnh.param<std::string>("tasks_file", tasks_file_, "");
    pnh.param<std::string>("library_dir", library_dir_, "");
    std::string robot_file;
    pnh.param<std::string>("robot_file", robot_file, "");
    robot_ = lfd::loadRobotSetup(robot_file);
    pnh.param("dt", options_.dt, options_.dt);
    pnh.param("all_segment_goals", options_.all_segment_goals, options_.all_segment_goals);
    pnh.param("gripper/threshold_fraction", options_.gripper_threshold_fraction,
              options_.gripper_threshold_fraction);
    pnh.param("gripper/hysteresis", options_.gripper_hysteresis, options_.gripper_hysteresis);
    pnh.param("gripper/min_range", options_.gripper_min_range, options_.gripper_min_range);
    pnh.param("gripper/open_opening", open_opening_, open_opening_);
    pnh.param("gripper/close_opening", close_opening_, close_opening_);
    pnh.param("gripper/close_effort", close_effort_, close_effort_);
    pnh.param("gripper/joint", gripper_joint_, gripper_joint_);
    pnh.param("generalization/bandwidth", options_.generalization.bandwidth, 0.0);
    pnh.param("generalization/local_linear", options_.generalization.local_linear,
              options_.generalization.local_linear);
    pnh.param("generalization/range_margin", options_.generalization.range_margin,
              options_.generalization.range_margin);
    pnh.param("settle_time", settle_time_, settle_time_);
    pnh.param("clock_timeout", clock_timeout_, clock_timeout_);
    std::vector<double> b;
    if (pnh.getParam("base_link_in_world", b) && b.size() == 3)
      base_in_world_ = Eigen::Vector3d(b[0], b[1], b[2]);
    loadGoalModels(pnh);

    joint_pub_ = nh.advertise<sensor_msgs::JointState>("/joint_command", 10);
    gripper_pub_ = nh.advertise<lfd_msgs::GripperCommand>("/gripper/command", 10);
    progress_pub_ = pnh.advertise<std_msgs::Float64>("progress", 10);
    planned_pub_ = nh.advertise<nav_msgs::Path>("/executor/planned_path", 1, true);
    executed_pub_ = nh.advertise<nav_msgs::Path>("/executor/executed_path", 1, true);
    marker_pub_ =
        nh.advertise<visualization_msgs::MarkerArray>("/executor/segment_markers", 1, true);
    const auto hints = ros::TransportHints().tcpNoDelay();
    joint_sub_ = nh.subscribe("/joint_states", 5, &Executor::onJoints, this, hints);
    gripper_sub_ = nh.subscribe("/gripper/state", 5, &Executor::onGripper, this, hints);
    ee_sub_ = nh.subscribe("/ee_pose", 5, &Executor::onEePose, this, hints);
    execute_srv_ = pnh.advertiseService("execute", &Executor::execute, this);
    cancel_srv_ = pnh.advertiseService("cancel", &Executor::cancel, this);
    ROS_INFO("executor: ready (%zu task goal models, dt %.4f s)", models_.size(), options_.dt);
  }

 private:
  void loadGoalModels(ros::NodeHandle& pnh) {
    XmlRpc::XmlRpcValue tasks;
    if (!pnh.getParam("tasks", tasks) || tasks.getType() != XmlRpc::XmlRpcValue::TypeStruct)
      throw std::runtime_error("executor: ~tasks (per-task segment goal rules) is missing");
    for (auto& [task, spec] : tasks) {
      lfd_dmp::TaskGoalModel model;
      model.task = task;
      if (spec.getType() != XmlRpc::XmlRpcValue::TypeStruct || !spec.hasMember("segments") ||
          spec["segments"].getType() != XmlRpc::XmlRpcValue::TypeArray)
        throw std::runtime_error("executor: ~tasks/" + task + "/segments must be a list");
      XmlRpc::XmlRpcValue& segs = spec["segments"];
      for (int i = 0; i < segs.size(); ++i) {
        XmlRpc::XmlRpcValue& s = segs[i];
        const std::string where = task + ".segments[" + std::to_string(i) + "]";
        if (s.getType() != XmlRpc::XmlRpcValue::TypeStruct || !s.hasMember("name") ||
            !s.hasMember("reference") || !s.hasMember("orientation"))
          throw std::runtime_error("executor: ~tasks: " + where +
                                   " needs name, reference and orientation");
        lfd_dmp::SegmentGoalRule r;
        r.name = text(s["name"], where + ".name");
        r.reference = lfd_dmp::parseGoalReference(text(s["reference"], where + ".reference"));
        r.orientation =
            lfd_dmp::parseOrientationRule(text(s["orientation"], where + ".orientation"));
        if (s.hasMember("offset")) {
          if (s["offset"].getType() != XmlRpc::XmlRpcValue::TypeArray || s["offset"].size() != 3)
            throw std::runtime_error("executor: ~tasks: " + where + ".offset needs 3 numbers");
          for (int k = 0; k < 3; ++k) r.offset[k] = number(s["offset"][k], where + ".offset");
        }
        if (s.hasMember("along_push")) r.along_push = number(s["along_push"], where);
        if (s.hasMember("frame")) r.frame = text(s["frame"], where + ".frame");
        model.segments.push_back(r);
      }
      for (const auto& r : model.segments) {
        bool known = r.frame.empty();
        for (const auto& other : model.segments) known = known || other.name == r.frame;
        if (!known)
          throw std::runtime_error("executor: ~tasks: " + task + "." + r.name + ".frame '" +
                                   r.frame + "' names no segment of the task");
      }
      models_[task] = model;
    }
  }

  // Lazily: the URDF and tasks.yaml are needed only once the sim is up.
  void ensurePlanner(const std::string& task) {
    if (planners_.count(task)) return;
    std::string urdf;
    if (!nh_.getParam("/robot_description", urdf))
      throw std::runtime_error("/robot_description is not set (launch sim.launch)");
    const lfd_sim_bridge::demo::TaskSetup setup =
        lfd_sim_bridge::demo::loadTaskSetup(tasks_file_, task, "sim");
    planners_[task] =
        std::make_unique<lfd_dmp::TaskPlanner>(lfd::makeCartesianToJoints(urdf, robot_));
    gripper_orientation_[task] = task == "push" ? setup.push_orientation : setup.grasp_orientation;
  }

  std::string resolveLibrary(const std::string& s) const {
    if (s.find('/') != std::string::npos || s.size() > 5 && s.substr(s.size() - 5) == ".json")
      return s;
    if (library_dir_.empty())
      throw std::invalid_argument("'" + s + "' is not a path and ~library_dir is not set");
    return library_dir_ + "/" + s + ".json";
  }

  bool execute(lfd_msgs::ExecuteTask::Request& req, lfd_msgs::ExecuteTask::Response& res) {
    bool expected = false;
    if (!busy_.compare_exchange_strong(expected, true)) {
      res.success = false;
      res.error = "busy: another execution is running (call ~cancel first)";
      ROS_WARN("executor: %s", res.error.c_str());
      return true;
    }
    cancel_ = false;
    try {
      run(req, res);
    } catch (const std::exception& e) {
      res.success = false;
      res.error = e.what();
      ROS_ERROR("executor: %s", e.what());
    }
    busy_ = false;
    return true;  // failures are in the response
  }

  void run(lfd_msgs::ExecuteTask::Request& req, lfd_msgs::ExecuteTask::Response& res) {
    const auto wall0 = std::chrono::steady_clock::now();
    if (req.library.empty()) throw std::invalid_argument("library is empty");
    if (!finitePose(req.object_pose) || !finitePose(req.goal))
      throw std::invalid_argument("object_pose / goal contain NaN or infinity");
    const lfd_dmp::SkillLibrary library = lfd_dmp::loadSkillLibrary(resolveLibrary(req.library));
    const auto model = models_.find(library.task);
    if (model == models_.end())
      throw std::invalid_argument("no segment goal rules for task '" + library.task +
                                  "' in ~tasks (config/executor.yaml)");
    ensurePlanner(library.task);
    lfd_dmp::TaskPlanner& planner = *planners_.at(library.task);

    // Current state of the chain's joints.
    Eigen::VectorXd q(planner.chain().dof());
    std::optional<double> grip;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (int i = 0; i < q.size(); ++i) {
        const auto it = joints_.find(planner.chain().jointNames()[i]);
        if (it == joints_.end())
          throw std::runtime_error("no /joint_states yet for joint " +
                                   planner.chain().jointNames()[i]);
        q[i] = it->second;
      }
      grip = gripper_;
    }
    const lfd_dmp::TcpPose start = planner.forward(q);
    lfd_dmp::TaskSituation situation;
    situation.object_position =
        Eigen::Vector3d(req.object_pose.position.x, req.object_pose.position.y,
                        req.object_pose.position.z) -
        base_in_world_;
    situation.object_yaw = yawOf(req.object_pose.orientation);
    situation.goal_position =
        Eigen::Vector3d(req.goal.position.x, req.goal.position.y, req.goal.position.z) -
        base_in_world_;
    situation.goal_yaw = yawOf(req.goal.orientation);
    const std::vector<lfd_dmp::SegmentTarget> targets = lfd_dmp::segmentTargets(
        model->second, situation, start, gripper_orientation_.at(library.task));

    lfd_dmp::ExecutorOptions opt = options_;
    opt.duration_scale = req.duration_scale > 0.0 ? req.duration_scale : 1.0;
    const lfd_dmp::ExecutionPlan plan = planner.plan(library, targets, q, grip, opt);
    res.planning_time =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    res.planned_duration = plan.duration();
    res.warnings = plan.warnings;
    for (const auto& w : plan.warnings) ROS_WARN("executor: %s", w.c_str());
    for (const auto& s : plan.segments) res.segment_names.push_back(s.name);
    publishPlan(plan);
    ROS_INFO(
        "executor: planned %s: %zu segments, %.2f s, %zu samples, IK residual %.2f mm, "
        "planning %.2f s wall",
        library.task.c_str(), plan.segments.size(), plan.duration(), plan.times.size(),
        plan.max_ik_position_error * 1e3, res.planning_time);
    if (req.dry_run) {
      res.success = true;
      return;
    }
    stream(plan, res);
    // Final error: measured TCP (FK of the joint states) against the planned end.
    ros::Time settle_end = ros::Time::now() + ros::Duration(settle_time_);
    while (ros::ok() && ros::Time::now() < settle_end) ros::WallDuration(0.001).sleep();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (int i = 0; i < q.size(); ++i) q[i] = joints_.at(planner.chain().jointNames()[i]);
    }
    const lfd_dmp::TcpPose end = planner.forward(q);
    res.final_position_error = (end.position - plan.poses.back().position).norm();
    res.final_orientation_error = end.orientation.angularDistance(plan.poses.back().orientation);
    publishExecuted();
    res.success = true;
    ROS_INFO("executor: done in %.2f s sim (planned %.2f s), final TCP error %.1f mm / %.3f rad",
             res.execution_time, res.planned_duration, res.final_position_error * 1e3,
             res.final_orientation_error);
  }

  void stream(const lfd_dmp::ExecutionPlan& plan, lfd_msgs::ExecuteTask::Response& res) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      executed_.poses.clear();
      recording_ = true;
    }
    sensor_msgs::JointState cmd;
    cmd.name = plan.joint_names;
    const size_t n = plan.times.size();
    size_t next_event = 0, segment = 0, last = 0;
    const ros::Time t0 = ros::Time::now();
    ros::Time last_advance = t0;
    auto last_wall = std::chrono::steady_clock::now();
    ros::Time segment_start = t0;
    ROS_INFO("executor: segment 1/%zu '%s' (%.2f s)", plan.segments.size(),
             plan.segments[0].name.c_str(), plan.segments[0].duration);
    bool first = true;
    while (true) {
      if (!ros::ok()) throw std::runtime_error("shutting down");
      if (cancel_) {
        recording_ = false;
        throw std::runtime_error(
            "cancelled at t=" + std::to_string((ros::Time::now() - t0).toSec()) +
            " s in segment '" + plan.segments[segment].name + "'");
      }
      const ros::Time now = ros::Time::now();
      const double elapsed = (now - t0).toSec();
      size_t k = std::min(n - 1, static_cast<size_t>(std::max(0.0, elapsed / plan.dt)));
      if (first || k > last) {
        first = false;
        cmd.header.stamp = now;
        cmd.position.assign(plan.joints[k].data(), plan.joints[k].data() + plan.joints[k].size());
        joint_pub_.publish(cmd);
        while (next_event < plan.gripper_events.size() &&
               plan.gripper_events[next_event].sample <= k) {
          sendGripper(plan.gripper_events[next_event].close, now);
          ++next_event;
        }
        while (segment + 1 < plan.segments.size() && k >= plan.segments[segment + 1].begin) {
          res.segment_durations.push_back((now - segment_start).toSec());
          segment_start = now;
          ++segment;
          ROS_INFO("executor: segment %zu/%zu '%s' (%.2f s)", segment + 1, plan.segments.size(),
                   plan.segments[segment].name.c_str(), plan.segments[segment].duration);
        }
        std_msgs::Float64 p;
        p.data = n > 1 ? static_cast<double>(k) / (n - 1) : 1.0;
        progress_pub_.publish(p);
        last = k;
        if (k + 1 >= n) break;
      }
      if (now > last_advance) {
        last_advance = now;
        last_wall = std::chrono::steady_clock::now();
      } else if (std::chrono::duration<double>(std::chrono::steady_clock::now() - last_wall)
                     .count() > clock_timeout_) {
        recording_ = false;
        throw std::runtime_error("sim time did not advance for " + std::to_string(clock_timeout_) +
                                 " s of wall time (is the bridge paused?)");
      }
      ros::WallDuration(0.0002).sleep();
    }
    const ros::Time t_end = ros::Time::now();
    res.segment_durations.push_back((t_end - segment_start).toSec());
    res.execution_time = (t_end - t0).toSec();
    recording_ = false;
  }

  void sendGripper(bool close, const ros::Time& stamp) {
    lfd_msgs::GripperCommand g;
    g.header.stamp = stamp;
    g.position = close ? close_opening_ : open_opening_;
    g.max_effort = close ? close_effort_ : 0.0;
    gripper_pub_.publish(g);
    ROS_INFO("executor: gripper %s", close ? "close" : "open");
  }

  bool cancel(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
    res.success = busy_.load();
    res.message = res.success ? "cancelling the running execution" : "nothing is running";
    cancel_ = true;
    return true;
  }

  void publishPlan(const lfd_dmp::ExecutionPlan& plan) {
    nav_msgs::Path path;
    path.header.frame_id = "base_link";
    path.header.stamp = ros::Time::now();
    // Every 10th sample is plenty for rviz.
    for (size_t k = 0; k < plan.poses.size(); k += 10) {
      geometry_msgs::PoseStamped ps;
      ps.header = path.header;
      ps.pose = lfd_sim_bridge::toPoseMsg(plan.poses[k]);
      path.poses.push_back(ps);
    }
    planned_pub_.publish(path);
    visualization_msgs::MarkerArray markers;
    visualization_msgs::Marker clear;
    clear.action = visualization_msgs::Marker::DELETEALL;
    markers.markers.push_back(clear);
    int id = 0;
    for (const auto& s : plan.segments) {
      for (int which = 0; which < 3; ++which) {
        visualization_msgs::Marker m;
        m.header = path.header;
        m.ns = which == 0 ? "segment_goals" : which == 1 ? "segment_labels" : "segment_starts";
        m.id = id++;
        m.type = which == 1 ? visualization_msgs::Marker::TEXT_VIEW_FACING
                            : visualization_msgs::Marker::SPHERE;
        m.pose = which == 2 ? lfd_sim_bridge::toPoseMsg(plan.poses[s.begin])
                            : lfd_sim_bridge::toPoseMsg(s.goal);
        if (which == 1) m.pose.position.z += 0.05;
        m.scale.x = m.scale.y = m.scale.z = which == 1 ? 0.03 : which == 0 ? 0.025 : 0.015;
        m.color.a = 1.0;
        m.color.r = which == 0 ? 1.0 : 0.9;
        m.color.g = which == 2 ? 0.8 : 0.9;
        m.color.b = which == 1 ? 0.9 : 0.1;
        m.text = s.name;
        markers.markers.push_back(m);
      }
    }
    marker_pub_.publish(markers);
  }

  void publishExecuted() {
    std::lock_guard<std::mutex> lock(mutex_);
    executed_.header.frame_id = "base_link";
    executed_.header.stamp = ros::Time::now();
    executed_pub_.publish(executed_);
  }

  void onJoints(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < msg->name.size() && i < msg->position.size(); ++i)
      joints_[msg->name[i]] = msg->position[i];
  }

  void onGripper(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < msg->name.size() && i < msg->position.size(); ++i)
      if (msg->name[i] == gripper_joint_) gripper_ = msg->position[i];
  }

  void onEePose(const geometry_msgs::PoseStamped::ConstPtr& msg) {
    if (!recording_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!executed_.poses.empty() &&
        (msg->header.stamp - executed_.poses.back().header.stamp).toSec() < 0.02)
      return;
    executed_.poses.push_back(*msg);
    if (executed_.poses.size() % 25 == 0) {
      executed_.header.frame_id = "base_link";
      executed_.header.stamp = msg->header.stamp;
      executed_pub_.publish(executed_);
    }
  }

  ros::NodeHandle nh_;
  std::string tasks_file_, library_dir_, gripper_joint_ = "R_GRIPPER";
  lfd_dmp::ExecutorOptions options_;
  lfd::RobotSetup robot_;
  double open_opening_ = 0.08, close_opening_ = 0.0, close_effort_ = 20.0;
  double settle_time_ = 0.5, clock_timeout_ = 5.0;
  Eigen::Vector3d base_in_world_{0.0, 0.0, 0.85};
  std::map<std::string, lfd_dmp::TaskGoalModel> models_;
  std::map<std::string, std::unique_ptr<lfd_dmp::TaskPlanner>> planners_;
  std::map<std::string, Eigen::Quaterniond> gripper_orientation_;
  ros::Publisher joint_pub_, gripper_pub_, progress_pub_, planned_pub_, executed_pub_, marker_pub_;
  ros::Subscriber joint_sub_, gripper_sub_, ee_sub_;
  ros::ServiceServer execute_srv_, cancel_srv_;
  std::mutex mutex_;
  std::map<std::string, double> joints_;
  std::optional<double> gripper_;
  nav_msgs::Path executed_;
  std::atomic<bool> busy_{false}, cancel_{false}, recording_{false};
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "executor");
  ros::NodeHandle nh, pnh("~");
  try {
    Executor executor(nh, pnh);
    // Several threads: state callbacks and ~cancel run while ~execute streams.
    ros::AsyncSpinner spinner(4);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("executor: %s", e.what());
    return 1;
  }
  return 0;
}
