// demonstrator_node: the FSM "demonstrator" of the paper (Sec. III) driving the MuJoCo bridge.
// For each configuration of config/tasks.yaml: reset the robot, place the objects, start a bag
// (/recorder/start with the demo's metadata), run the phases (Cartesian minimum-jerk motions ->
// IK -> /joint_trajectory, gripper via /gripper/command, ground truth on /lfd/phase), stop the bag,
// and judge physical success from the simulated object pose. Exits when every demo is done.
// The motion logic is ROS-free (lib/demo_*.cpp); this node only times and sends it.
//
// Timing: in lockstep mode (default) the node pauses the bridge and advances it with /bridge/step,
// so commands, phase stamps and recorded samples line up exactly in sim time and nothing is
// dropped however loaded the machine is; the sim then runs exactly as fast as the nodes keep up.
//
// Private parameters (config/demonstrator.yaml): task, mode, configurations, output_dir, seed,
// tasks_file, robot_file, speed_min/max, sample_period, contact_threshold, lead_in, tail, phase_rate,
// skip_existing, lockstep, lockstep_chunk, geometry/*, timing/*, teleop/*.
#include <atomic>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <lfd_msgs/GripperCommand.h>
#include <lfd_msgs/Phase.h>
#include <lfd_msgs/ResetSim.h>
#include <lfd_msgs/SetScene.h>
#include <lfd_msgs/StartRecording.h>
#include <lfd_msgs/StepSim.h>
#include <lfd_msgs/StopRecording.h>
#include <lfd_msgs/Touch.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/SetBool.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <trajectory_msgs/JointTrajectory.h>

#include "lfd_core/robot_setup.hpp"
#include "lfd_sim_bridge/demo_plan.hpp"
#include "lfd_sim_bridge/demo_tasks.hpp"
#include "lfd_sim_bridge/pose_msg.hpp"

namespace {

namespace demo = lfd_sim_bridge::demo;

template <typename T>
T param(const ros::NodeHandle& pnh, const std::string& name, const T& fallback) {
  T value;
  return pnh.getParam(name, value) ? value : fallback;
}

// Physical success criteria of config/evaluation.yaml `reproduction.<task>`, the one place they
// are written (the Python judges read the same file): the launch loads that file into
// ~evaluation. No fallback numbers, so the demonstrator cannot judge by other ones.
demo::SuccessCriteria successCriteria(const ros::NodeHandle& pnh, const std::string& task) {
  const std::string ns = "evaluation/reproduction/" + task + "/";
  // demo::judge measures the grasp in 3-D and the push horizontally: refuse a file that says
  // otherwise rather than judge by another rule than the Python judges.
  const std::string distance = param<std::string>(pnh, ns + "distance", "");
  const std::string judged = task == "push" ? "xy" : "xyz";
  if (distance != judged) {
    throw std::invalid_argument("~" + ns + "distance is '" + distance + "'; the demonstrator judges " +
                                task + " by distance '" + judged + "'");
  }
  demo::SuccessCriteria c;
  if (!pnh.getParam(ns + "tolerance_m", c.tolerance)) {
    throw std::invalid_argument("~" + ns + "tolerance_m is not set: load config/evaluation.yaml "
                                "into the demonstrator's ~evaluation namespace");
  }
  c.min_lift = 0.0;  // a task without min_lift_m (push) has no lift requirement
  pnh.getParam(ns + "min_lift_m", c.min_lift);
  return c;
}

void loadDouble(const ros::NodeHandle& pnh, const std::string& name, double* value) {
  pnh.getParam(name, *value);
}

Eigen::Quaterniond quaternionParam(const ros::NodeHandle& pnh, const std::string& name,
                                   const Eigen::Quaterniond& fallback) {
  std::vector<double> wxyz;
  if (!pnh.getParam(name, wxyz)) return fallback;
  if (wxyz.size() != 4) throw std::invalid_argument("~" + name + " must be [w, x, y, z]");
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
}

demo::Pose fromMsg(const geometry_msgs::Pose& m) {
  demo::Pose p;
  p.position = {m.position.x, m.position.y, m.position.z};
  p.orientation =
      Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z)
          .normalized();
  return p;
}

demo::Pose transformed(const Eigen::Isometry3d& t, const demo::Pose& p) {
  demo::Pose out;
  out.position = t * p.position;
  out.orientation = Eigen::Quaterniond(t.linear()) * p.orientation;
  return out;
}

std::string poseJson(const demo::Pose& p) {
  std::ostringstream s;
  s << std::setprecision(6) << "{\"position\": [" << p.position.x() << ", " << p.position.y()
    << ", " << p.position.z() << "], \"orientation\": [" << p.orientation.w() << ", "
    << p.orientation.x() << ", " << p.orientation.y() << ", " << p.orientation.z() << "]}";
  return s.str();
}

struct DemoResult {
  int configuration = 0;
  std::string bag;
  bool recorded = false;
  demo::Outcome outcome;
  double duration = 0.0;
  std::string error;
};

class Demonstrator {
 public:
  Demonstrator(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh), tf_listener_(tf_buffer_) {
    task_ = param<std::string>(pnh, "task", "grasp");
    mode_ = param<std::string>(pnh, "mode", "sim");
    if (mode_ != "sim" && mode_ != "teleop")
      throw std::invalid_argument("~mode must be sim or teleop, got '" + mode_ + "'");
    output_dir_ = param<std::string>(pnh, "output_dir", "");
    if (output_dir_.empty()) throw std::invalid_argument("~output_dir is required");
    seed_ = param(pnh, "seed", 1);
    setup_ = demo::loadTaskSetup(param<std::string>(pnh, "tasks_file", ""), task_, mode_);
    robot_ = lfd::loadRobotSetup(param<std::string>(pnh, "robot_file", ""));
    std::vector<int> wanted = param(pnh, "configurations", std::vector<int>());
    for (const demo::TaskConfiguration& c : setup_.configurations)
      if (wanted.empty() || std::find(wanted.begin(), wanted.end(), c.index) != wanted.end())
        configurations_.push_back(c);
    if (configurations_.empty())
      throw std::invalid_argument("no configuration of " + task_ + "/" + mode_ + " selected");

    speed_min_ = param(pnh, "speed_min", 0.7);
    speed_max_ = param(pnh, "speed_max", 1.3);
    sample_period_ = param(pnh, "sample_period", 0.02);
    contact_threshold_ = param(pnh, "contact_threshold", 0.5);
    lead_in_ = param(pnh, "lead_in", 0.3);
    tail_ = param(pnh, "tail", 0.5);
    settle_before_ = param(pnh, "scene_settle", 0.3);
    phase_period_ = 1.0 / param(pnh, "phase_rate", 20.0);
    skip_existing_ = param(pnh, "skip_existing", true);
    lockstep_ = param(pnh, "lockstep", true);
    chunk_ = param(pnh, "lockstep_chunk", 0.05);
    contact_chunk_ = param(pnh, "lockstep_contact_chunk", 0.01);
    physics_dt_ = param(pnh, "physics_dt", 0.001);
    publish_period_ = 1.0 / nh.param("/bridge/publish_rate", 200.0);
    gripper_joint_ = nh.param<std::string>("/bridge/gripper_joint", "R_GRIPPER");
    grasp_offset_ = param(pnh, "grasp_offset_range", 0.015);
    grasp_yaw_ = param(pnh, "grasp_yaw_range", 0.08);
    criteria_ = successCriteria(pnh, task_);

    geometry_.grasp_orientation = setup_.grasp_orientation;
    geometry_.push_orientation = setup_.push_orientation;
    geometry_.grasp_orientation =
        quaternionParam(pnh, "geometry/grasp_orientation", geometry_.grasp_orientation);
    geometry_.push_orientation =
        quaternionParam(pnh, "geometry/push_orientation", geometry_.push_orientation);
    for (auto& [name, value] : std::vector<std::pair<std::string, double*>>{
             {"pregrasp_height", &geometry_.pregrasp_height},
             {"grasp_height", &geometry_.grasp_height},
             {"lift_height", &geometry_.lift_height},
             {"open_opening", &geometry_.open_opening},
             {"grasp_opening", &geometry_.grasp_opening},
             {"grasp_effort", &geometry_.grasp_effort},
             {"teleop_close_opening", &geometry_.teleop_close_opening},
             {"box_half_length", &geometry_.box_half_length},
             {"push_clearance", &geometry_.push_clearance},
             {"push_contact_depth", &geometry_.push_contact_depth},
             {"tcp_to_face", &geometry_.tcp_to_face},
             {"push_height", &geometry_.push_height},
             {"push_prelift", &geometry_.push_prelift},
             {"retreat", &geometry_.retreat}})
      loadDouble(pnh, "geometry/" + name, value);
    for (auto& [name, value] :
         std::vector<std::pair<std::string, double*>>{{"to_pregrasp", &timing_.to_pregrasp},
                                                      {"descend", &timing_.descend},
                                                      {"close", &timing_.close},
                                                      {"settle", &timing_.settle},
                                                      {"lift", &timing_.lift},
                                                      {"carry", &timing_.carry},
                                                      {"hold", &timing_.hold},
                                                      {"to_prepush", &timing_.to_prepush},
                                                      {"lower", &timing_.lower},
                                                      {"touch", &timing_.touch},
                                                      {"push", &timing_.push},
                                                      {"retreat", &timing_.retreat},
                                                      {"go_home", &timing_.go_home},
                                                      {"open", &timing_.open}})
      loadDouble(pnh, "timing/" + name, value);
    teleop_.enabled = mode_ == "teleop";
    for (auto& [name, value] : std::vector<std::pair<std::string, double*>>{
             {"hesitation_probability", &teleop_.hesitation_probability},
             {"pause_min", &teleop_.pause_min},
             {"pause_max", &teleop_.pause_max},
             {"duration_jitter", &teleop_.duration_jitter},
             {"slowdown_probability", &teleop_.slowdown_probability},
             {"slowdown_factor", &teleop_.slowdown_factor},
             {"reaction_delay", &teleop_.reaction_delay},
             {"timed_close", &teleop_.timed_close},
             {"tremor_rms", &teleop_.tremor_rms},
             {"tremor_low_hz", &teleop_.tremor_low_hz},
             {"tremor_high_hz", &teleop_.tremor_high_hz},
             {"grasp_position_noise", &teleop_.grasp_position_noise}})
      loadDouble(pnh, "teleop/" + name, value);

    trajectory_pub_ = nh.advertise<trajectory_msgs::JointTrajectory>("/joint_trajectory", 10);
    gripper_pub_ = nh.advertise<lfd_msgs::GripperCommand>("/gripper/command", 10);
    phase_pub_ = nh.advertise<lfd_msgs::Phase>("/lfd/phase", 100);
    const auto hints = ros::TransportHints().tcpNoDelay();
    joint_sub_ = nh.subscribe("/joint_states", 5, &Demonstrator::onJoints, this, hints);
    touch_sub_ = nh.subscribe("/touch", 5, &Demonstrator::onTouch, this, hints);
    object_sub_ = nh.subscribe("/objects/" + setup_.object + "/pose", 5, &Demonstrator::onObject,
                               this, hints);
    reset_client_ = nh.serviceClient<lfd_msgs::ResetSim>("/bridge/reset");
    scene_client_ = nh.serviceClient<lfd_msgs::SetScene>("/bridge/set_scene");
    start_client_ = nh.serviceClient<lfd_msgs::StartRecording>("/recorder/start");
    stop_client_ = nh.serviceClient<lfd_msgs::StopRecording>("/recorder/stop");
    pause_client_ = nh.serviceClient<std_srvs::SetBool>("/bridge/pause");
    step_client_ = nh.serviceClient<lfd_msgs::StepSim>("/bridge/step", true);
  }

  // Runs every selected demonstration; returns how many succeeded physically.
  int run() {
    waitForSystem();
    std::vector<DemoResult> results;
    for (const demo::TaskConfiguration& c : configurations_) {
      if (!ros::ok()) break;
      results.push_back(runDemo(c));
    }
    if (lockstep_) setPaused(false);  // leave the sim running for whoever comes next
    writeSummary(results);
    int ok = 0;
    for (const DemoResult& r : results) ok += r.outcome.success ? 1 : 0;
    ROS_INFO("demonstrator: %s/%s done, %d of %zu demos succeeded physically", task_.c_str(),
             mode_.c_str(), ok, results.size());
    return ok;
  }

 private:
  void waitForSystem() {
    ROS_INFO("demonstrator: waiting for the bridge, the recorder and sim time");
    while (ros::ok() && ros::Time::now().isZero()) ros::WallDuration(0.01).sleep();
    for (ros::ServiceClient* c : {&reset_client_, &scene_client_, &start_client_, &stop_client_})
      if (!c->waitForExistence(ros::Duration(60.0)))
        throw std::runtime_error("service " + c->getService() + " is not available");
    std::string urdf;
    if (!nh_.getParam("/robot_description", urdf))
      throw std::runtime_error("/robot_description is not set (launch sim.launch)");
    // The IK of config/robot.yaml (chain, costs, posture) for poses in base_link; base_link's
    // pose in the world comes from /tf_static.
    converter_ = std::make_unique<lfd::CartesianToJoints>(lfd::makeCartesianToJoints(urdf, robot_));
    const geometry_msgs::TransformStamped w =
        tf_buffer_.lookupTransform("world", "base_link", ros::Time(0), ros::Duration(30.0));
    world_from_base_ = Eigen::Isometry3d::Identity();
    world_from_base_.translation() = Eigen::Vector3d(
        w.transform.translation.x, w.transform.translation.y, w.transform.translation.z);
    world_from_base_.linear() = Eigen::Quaterniond(w.transform.rotation.w, w.transform.rotation.x,
                                                   w.transform.rotation.y, w.transform.rotation.z)
                                    .toRotationMatrix();
    while (ros::ok()) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!joints_.name.empty()) break;
      }
      ros::WallDuration(0.01).sleep();
    }
    if (lockstep_) {
      if (!pause_client_.waitForExistence(ros::Duration(30.0)) ||
          !step_client_.waitForExistence(ros::Duration(30.0)))
        throw std::runtime_error("lockstep needs /bridge/pause and /bridge/step");
      step_client_ = nh_.serviceClient<lfd_msgs::StepSim>("/bridge/step", true);
      setPaused(true);
      lfd_msgs::StepSim step;  // zero steps: read the paused sim time
      if (!step_client_.call(step) || !step.response.success)
        throw std::runtime_error("/bridge/step failed: " + step.response.message);
      now_ = ros::Time(step.response.sim_time);
      advanceTo(alignedToGrid(now_));
      ROS_INFO("demonstrator: lockstep with the bridge from t=%.3f", now_.toSec());
    }
  }

  DemoResult runDemo(const demo::TaskConfiguration& c) {
    DemoResult result;
    result.configuration = c.index;
    std::ostringstream name;
    name << output_dir_ << "/" << task_ << "_" << mode_ << "_" << std::setw(2) << std::setfill('0')
         << c.index << ".bag";
    result.bag = name.str();
    if (skip_existing_ && std::ifstream(result.bag).good()) {
      ROS_INFO("demonstrator: %s exists, skipped", result.bag.c_str());
      result.error = "skipped (exists)";
      return result;
    }
    try {
      execute(c, &result);
    } catch (const std::exception& e) {
      result.error = e.what();
      ROS_ERROR("demonstrator: %s configuration %d failed: %s", task_.c_str(), c.index, e.what());
      stopRecordingIfActive();
    }
    return result;
  }

  void execute(const demo::TaskConfiguration& c, DemoResult* result) {
    std::mt19937 rng(static_cast<uint32_t>(seed_ * 1000 + c.index * 7 + (mode_ == "teleop")));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    demo::Variation variation;
    variation.speed = speed_min_ + (speed_max_ - speed_min_) * unit(rng);
    variation.grasp_offset_along = grasp_offset_ * (2.0 * unit(rng) - 1.0);
    variation.grasp_yaw = grasp_yaw_ * (2.0 * unit(rng) - 1.0);

    // Scene: the robot in its ready posture, the task's object at its start, the other parked.
    lfd_msgs::ResetSim reset;
    if (task_ == "push") {
      // The pushing fist is closed before recording starts: the gripper carries no information
      // about the push's phases, and a closing transient at the start would only mislead the
      // feature selection.
      reset.request.joint_names.push_back(gripper_joint_);
      reset.request.positions.push_back(0.0);
    }
    call(reset_client_, reset);
    lfd_msgs::SetScene scene;
    scene.request.object_names.push_back(setup_.object);
    scene.request.poses.push_back(lfd_sim_bridge::toPoseMsg(c.object_start));
    for (const auto& [object, pose] : setup_.park) {
      if (object == setup_.object) continue;
      scene.request.object_names.push_back(object);
      scene.request.poses.push_back(lfd_sim_bridge::toPoseMsg(pose));
    }
    call(scene_client_, scene);
    advanceTo(now() + ros::Duration(settle_before_));

    // Plan the whole demo and solve its IK before recording anything.
    const Eigen::VectorXd q0 = currentChainPositions();
    const demo::Pose start = converter_->forward(q0);
    const Eigen::Isometry3d base_from_world = world_from_base_.inverse();
    const demo::TaskInstance instance{task_, transformed(base_from_world, c.object_start),
                                      transformed(base_from_world, c.goal)};
    const demo::DemoPlan plan =
        demo::planDemo(instance, start, geometry_, timing_, variation, teleop_, rng);
    const demo::Tremor tremor =
        teleop_.enabled
            ? demo::Tremor(teleop_.tremor_rms, teleop_.tremor_low_hz, teleop_.tremor_high_hz, rng())
            : demo::Tremor();
    std::vector<lfd::JointPath> paths;
    demo::Pose from = start;
    Eigen::VectorXd seed = q0;
    double t0 = 0.0;
    for (const demo::Phase& phase : plan.phases) {
      paths.push_back(
          converter_->convert(demo::samplePhase(from, phase, sample_period_, t0, &tremor), seed));
      seed = paths.back().positions.back();
      from = phase.segments.back().target;
      t0 += phase.duration();
    }

    // Record.
    lfd_msgs::StartRecording start_rec;
    start_rec.request.bag_path = result->bag;
    lfd_msgs::DemoMetadata& meta = start_rec.request.metadata;
    meta.header.stamp = now();
    meta.header.frame_id = "world";
    meta.task = task_;
    meta.configuration = c.index;
    meta.mode = mode_;
    meta.speed = variation.speed;
    std::ostringstream extra;
    extra << std::setprecision(6) << "{\"object\": \"" << setup_.object
          << "\", \"frame\": \"world\", \"object_start\": " << poseJson(c.object_start)
          << ", \"goal\": " << poseJson(c.goal) << ", \"table_top\": " << setup_.table_top
          << ", \"seed\": " << seed_ << ", \"grasp_offset_along\": " << variation.grasp_offset_along
          << ", \"grasp_yaw\": " << variation.grasp_yaw << ", \"tremor_rms\": " << tremor.rms()
          << ", \"planned_duration\": " << plan.duration() << ", \"phases\": [";
    for (size_t i = 0; i < plan.phases.size(); ++i)
      extra << (i ? ", " : "") << "\"" << plan.phases[i].name << "\"";
    extra << "]}";
    meta.extra_json = extra.str();
    call(start_client_, start_rec);
    recording_ = true;
    const ros::Time demo_start = meta.header.stamp;
    ROS_INFO("demonstrator: %s/%s configuration %d, speed %.2f, planned %.1f s -> %s",
             task_.c_str(), mode_.c_str(), c.index, variation.speed, plan.duration(),
             result->bag.c_str());
    setPhase(plan.phases.front(), demo_start);  // the robot rests in "approach" during lead-in
    advanceTo(demo_start + ros::Duration(lead_in_));

    for (size_t i = 0; i < plan.phases.size(); ++i) runPhase(plan.phases[i], paths[i]);

    advanceTo(now() + ros::Duration(tail_));
    // The recorder stops at its newest /clock: let the last one (paused sim) reach it.
    ros::WallDuration(0.02).sleep();
    lfd_msgs::StopRecording stop;
    call(stop_client_, stop);
    recording_ = false;
    {
      std::lock_guard<std::mutex> lock(phase_mutex_);
      phase_active_ = false;
    }
    result->recorded = true;
    result->duration = (now() - demo_start).toSec();

    demo::Pose object_end;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      object_end = object_pose_;
    }
    result->outcome = demo::judge(task_, object_end, c.goal, setup_.table_top, criteria_);
    ROS_INFO("demonstrator: configuration %d %s (%s), %lu messages", c.index,
             result->outcome.success ? "SUCCEEDED" : "FAILED", result->outcome.reason.c_str(),
             static_cast<unsigned long>(stop.response.messages_written));
  }

  void runPhase(const demo::Phase& phase, const lfd::JointPath& path) {
    const ros::Time phase_start = now();
    setPhase(phase, phase_start);
    sendTrajectory(path);
    double t = 0.0;
    for (const demo::Segment& segment : phase.segments) {
      const ros::Time segment_start = phase_start + ros::Duration(t);
      advanceTo(segment_start);
      if (segment.gripper) {
        lfd_msgs::GripperCommand g;
        g.header.stamp = now();
        g.position = segment.gripper->opening;
        g.max_effort = segment.gripper->max_effort;
        gripper_pub_.publish(g);
        letMessagesArrive();
      }
      if (segment.until_contact) {
        // Close until both pads touch (or time out), settle, then the phase ends early.
        const ros::Time timeout = segment_start + ros::Duration(segment.duration);
        while (ros::ok() && now() < timeout && !inContact())
          advanceTo(std::min(timeout, now() + ros::Duration(contact_chunk_)), contact_chunk_, true);
        if (!inContact())
          ROS_WARN("demonstrator: no contact on both finger pads after %.2f s", segment.duration);
        advanceTo(now() + ros::Duration(segment.settle));
        return;
      }
      t += segment.duration;
    }
    advanceTo(phase_start + ros::Duration(t));
  }

  void sendTrajectory(const lfd::JointPath& path) {
    trajectory_msgs::JointTrajectory msg;
    msg.header.stamp = lockstep_ ? now() : ros::Time(0);  // lockstep: exactly now; else on receipt
    msg.joint_names = path.joint_names;
    const size_t n = path.times.size();
    msg.points.resize(n);
    for (size_t k = 0; k < n; ++k) {
      trajectory_msgs::JointTrajectoryPoint& p = msg.points[k];
      p.positions.assign(path.positions[k].data(),
                         path.positions[k].data() + path.positions[k].size());
      // Central differences (zero at the ends, where the minimum-jerk law stops).
      p.velocities.assign(path.positions[k].size(), 0.0);
      if (k > 0 && k + 1 < n) {
        const Eigen::VectorXd v = (path.positions[k + 1] - path.positions[k - 1]) /
                                  (path.times[k + 1] - path.times[k - 1]);
        p.velocities.assign(v.data(), v.data() + v.size());
      }
      p.time_from_start = ros::Duration(path.times[k]);
    }
    trajectory_pub_.publish(msg);
    letMessagesArrive();
  }

  // --- ground-truth phase: at every transition and on a fixed sim-time grid in between ---
  void setPhase(const demo::Phase& phase, const ros::Time& stamp) {
    publishPhaseGrid(stamp);  // the previous phase up to the transition
    std::lock_guard<std::mutex> lock(phase_mutex_);
    phase_msg_.task = task_;
    phase_msg_.name = phase.name;
    phase_msg_.index = phase.index;
    phase_msg_.header.stamp = stamp;
    phase_pub_.publish(phase_msg_);
    if (!phase_active_) next_phase_time_ = stamp + ros::Duration(phase_period_);
    phase_active_ = true;
  }

  // Publishes the current phase on the sim-time grid up to `t` (between transitions).
  void publishPhaseGrid(const ros::Time& t) {
    std::lock_guard<std::mutex> lock(phase_mutex_);
    while (phase_active_ && t >= next_phase_time_) {
      phase_msg_.header.stamp = next_phase_time_;
      phase_pub_.publish(phase_msg_);
      next_phase_time_ += ros::Duration(phase_period_);
    }
  }

  // --- sim time: lockstep (/bridge/step) or following /clock ---
  ros::Time now() const { return lockstep_ ? now_ : ros::Time::now(); }

  // Sim time rounded up to the bridge's publishing grid, so each /bridge/step call ends on it.
  ros::Time alignedToGrid(const ros::Time& t) const {
    const double grid = publish_period_;
    return ros::Time(std::ceil(t.toSec() / grid - 1e-6) * grid);
  }

  void advanceTo(const ros::Time& t, double chunk = 0.0, bool fresh_sensors = false) {
    if (chunk <= 0.0) chunk = chunk_;
    if (!lockstep_) {
      while (ros::ok() && ros::Time::now() < t) {
        publishPhaseGrid(ros::Time::now());
        ros::WallDuration(0.0005).sleep();
      }
      publishPhaseGrid(ros::Time::now());
      return;
    }
    const ros::Time target = alignedToGrid(t);
    while (ros::ok() && now_ < target - ros::Duration(1e-6)) {
      const double span = std::min(chunk, (target - now_).toSec());
      lfd_msgs::StepSim step;
      step.request.steps = static_cast<uint32_t>(std::lround(span / physics_dt_));
      if (step.request.steps == 0) break;
      if (!step_client_.call(step) || !step.response.success)
        throw std::runtime_error("/bridge/step failed: " + step.response.message);
      now_ = ros::Time(step.response.sim_time);
      publishPhaseGrid(now_);
      if (fresh_sensors) waitForFreshSensors();
    }
  }

  // Lockstep: the sensors of the step just taken (for contact checks) reach this node.
  void waitForFreshSensors() {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(0.2);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (touch_.header.stamp >= now_ - ros::Duration(publish_period_ / 2)) return;
      }
      ros::WallDuration(0.0002).sleep();
    }
  }

  // A command published just before a /bridge/step call must be processed before that step.
  // The trajectory travels on a topic, the next /bridge/step on a service connection: nothing
  // orders the two, so give the topic time to land before the bridge steps (3 ms was not always
  // enough on an idle machine, where a push demo once never moved the box).
  void letMessagesArrive() {
    if (lockstep_) ros::WallDuration(0.02).sleep();
  }

  void setPaused(bool paused) {
    std_srvs::SetBool srv;
    srv.request.data = paused;
    if (!pause_client_.call(srv) || !srv.response.success)
      throw std::runtime_error("/bridge/pause failed: " + srv.response.message);
  }

  // --- helpers ---
  template <typename Srv>
  void call(ros::ServiceClient& client, Srv srv) {
    if (!client.call(srv))
      throw std::runtime_error("service " + client.getService() + " call failed");
    if (!srv.response.success)
      throw std::runtime_error(client.getService() + ": " + srv.response.message);
  }
  void call(ros::ServiceClient& client, lfd_msgs::StopRecording& srv) {
    if (!client.call(srv))
      throw std::runtime_error("service " + client.getService() + " call failed");
    if (!srv.response.success)
      throw std::runtime_error(client.getService() + ": " + srv.response.message);
  }

  void stopRecordingIfActive() {
    {
      std::lock_guard<std::mutex> lock(phase_mutex_);
      phase_active_ = false;
    }
    if (!recording_) return;
    lfd_msgs::StopRecording stop;
    stop_client_.call(stop);
    recording_ = false;
  }

  Eigen::VectorXd currentChainPositions() {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto& names = converter_->chain().jointNames();
    Eigen::VectorXd q(names.size());
    for (size_t i = 0; i < names.size(); ++i) {
      const auto it = std::find(joints_.name.begin(), joints_.name.end(), names[i]);
      if (it == joints_.name.end())
        throw std::runtime_error("/joint_states has no joint " + names[i]);
      q[i] = joints_.position[it - joints_.name.begin()];
    }
    converter_->chain().clampToLimits(q);
    return q;
  }

  bool inContact() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (touch_.values.size() < 2) return false;
    for (double v : touch_.values)
      if (v < contact_threshold_) return false;
    return true;
  }

  void onJoints(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    joints_ = *msg;
  }
  void onTouch(const lfd_msgs::Touch::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    touch_ = *msg;
  }
  void onObject(const geometry_msgs::PoseStamped::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    object_pose_ = fromMsg(msg->pose);
  }

  void writeSummary(const std::vector<DemoResult>& results) const {
    const std::string path = output_dir_ + "/demonstrator_summary_" + task_ + "_" + mode_ + ".yaml";
    std::ofstream out(path);
    out << "task: " << task_ << "\nmode: " << mode_ << "\ndemos:\n";
    for (const DemoResult& r : results) {
      out << "  - {configuration: " << r.configuration << ", bag: \"" << r.bag
          << "\", recorded: " << (r.recorded ? "true" : "false")
          << ", success: " << (r.outcome.success ? "true" : "false")
          << ", distance: " << r.outcome.distance << ", height: " << r.outcome.height
          << ", duration: " << r.duration << ", error: \"" << r.error << "\"}\n";
    }
  }

  ros::NodeHandle nh_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  std::string task_, mode_, output_dir_;
  int seed_ = 1;
  demo::TaskSetup setup_;
  std::vector<demo::TaskConfiguration> configurations_;
  double speed_min_, speed_max_, sample_period_, contact_threshold_, lead_in_, tail_,
      settle_before_, phase_period_, grasp_offset_, grasp_yaw_;
  bool skip_existing_ = true;
  demo::SuccessCriteria criteria_;
  demo::Geometry geometry_;
  demo::Timing timing_;
  demo::TeleopStyle teleop_;
  lfd::RobotSetup robot_;
  std::unique_ptr<lfd::CartesianToJoints> converter_;
  Eigen::Isometry3d world_from_base_ = Eigen::Isometry3d::Identity();

  ros::Publisher trajectory_pub_, gripper_pub_, phase_pub_;
  ros::Subscriber joint_sub_, touch_sub_, object_sub_;
  ros::ServiceClient reset_client_, scene_client_, start_client_, stop_client_;
  std::string gripper_joint_;

  std::mutex mutex_;
  sensor_msgs::JointState joints_;
  lfd_msgs::Touch touch_;
  demo::Pose object_pose_;
  bool recording_ = false;

  std::mutex phase_mutex_;
  lfd_msgs::Phase phase_msg_;
  bool phase_active_ = false;
  ros::Time next_phase_time_;
  bool lockstep_ = true;
  double chunk_ = 0.05, contact_chunk_ = 0.01, physics_dt_ = 0.001, publish_period_ = 0.005;
  ros::Time now_;
  ros::ServiceClient pause_client_, step_client_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "demonstrator");
  ros::NodeHandle nh, pnh("~");
  try {
    Demonstrator demonstrator(nh, pnh);
    // Declared after the demonstrator so it is destroyed (its threads joined) first: callbacks
    // write the demonstrator's members, which must not be freed under a running callback. Once
    // run() unpauses the sim, /joint_states arrives at full simulation rate, and a spinner that
    // outlived the demonstrator crashed the node at exit (free(): invalid pointer, SIGSEGV).
    ros::AsyncSpinner spinner(2);
    spinner.start();
    demonstrator.run();
  } catch (const std::exception& e) {
    ROS_FATAL("demonstrator: %s", e.what());
    ros::shutdown();
    return 1;
  }
  ros::shutdown();
  return 0;
}
