// demonstrator_node: the FSM "demonstrator" of the paper (Sec. III) driving the MuJoCo bridge, for
// any task file. It records one dataset (~task, ~mode) or several in turn (~datasets, see
// demo_jobs.hpp), so one simulation serves them all. Per dataset: select the bridge's noise
// profile of its mode (its generator restarts, so the dataset's noise does not depend on the ones
// before it), then for each configuration of the task's file (config/tasks/<task>.yaml): reset the
// robot, place the objects (the others parked), start a bag (/recorder/start with the demo's
// metadata and scene), run the phases (Cartesian minimum-jerk motions -> IK -> /joint_trajectory,
// gripper via /gripper/command, ground truth on /lfd/phase), stop the bag, and log where the
// objects ended. Physical success is judged from the bags by lfd_tools.judge, never here.
// The task logic is ROS-free (lib/task_file.cpp, lib/demo_plan.cpp); this node times and sends it.
//
// Timing: in lockstep mode (default) the node pauses the bridge and advances it with /bridge/step,
// so commands, phase stamps and recorded samples line up exactly in sim time and nothing is
// dropped however loaded the machine is; the sim then runs exactly as fast as the nodes keep up.
// Each phase is planned when it starts, from where the previous one ended: a guarded move that
// stopped at contact changes where the next phase begins.
//
// Private parameters (config/demonstrator.yaml): task, mode, configurations, output_dir or
// datasets, seed, tasks_dir, scene_file, robot_file, speed_min/max, sample_period,
// contact_threshold, lead_in, tail, scene_settle, phase_rate, skip_existing, lockstep,
// lockstep_chunk, lockstep_contact_chunk, physics_dt, tool/*, teleop/*.
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <memory>
#include <mutex>
#include <random>
#include <set>
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

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_core/util/heap_trim.hpp"
#include "lfd_ros/master_watch.hpp"
#include "lfd_sim_bridge/demo_jobs.hpp"
#include "lfd_sim_bridge/demo_metadata.hpp"
#include "lfd_sim_bridge/demo_plan.hpp"
#include "lfd_sim_bridge/pose_msg.hpp"
#include "lfd_sim_bridge/task_file.hpp"
#include "lfd_sim_bridge/wall_profile.hpp"

namespace {

// Wall time a lockstep step may take to deliver a command to the bridge, or this step's sensor
// reading back: far beyond any load seen (1.4 s of lag); beyond it the bridge is gone or hung.
constexpr double kCommandWait = 10.0;

namespace demo = lfd_sim_bridge::demo;
namespace task = lfd_sim_bridge::task;

template <typename T>
T required(const ros::NodeHandle& pnh, const std::string& name) {
  T value;
  if (!pnh.getParam(name, value) || value == T())
    throw std::invalid_argument("~" + name + " is required (demonstrate.launch sets it)");
  return value;
}

demo::TeleopStyle teleopStyle(const ros::NodeHandle& pnh, bool enabled) {
  demo::TeleopStyle t;
  t.enabled = enabled;
  for (auto& [name, value] : std::vector<std::pair<std::string, double*>>{
           {"hesitation_probability", &t.hesitation_probability},
           {"pause_min", &t.pause_min},
           {"pause_max", &t.pause_max},
           {"duration_jitter", &t.duration_jitter},
           {"slowdown_probability", &t.slowdown_probability},
           {"slowdown_factor", &t.slowdown_factor},
           {"reaction_delay", &t.reaction_delay},
           {"timed_close", &t.timed_close},
           {"tremor_rms", &t.tremor_rms},
           {"tremor_low_hz", &t.tremor_low_hz},
           {"tremor_high_hz", &t.tremor_high_hz}})
    pnh.getParam("teleop/" + name, *value);
  return t;
}

demo::Pose fromMsg(const geometry_msgs::Pose& m) {
  demo::Pose p;
  p.position = {m.position.x, m.position.y, m.position.z};
  p.orientation =
      Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z)
          .normalized();
  return p;
}

struct DemoResult {
  int configuration = 0;
  std::string bag;
  bool recorded = false;
  double duration = 0.0;
  std::string final_state;  // where the task's objects and joints ended (logged, never judged)
  std::string error;
  double wall = 0.0;                       // s of wall time the demo took, all included
  lfd_sim_bridge::WallProfile wall_parts;  // the part of it each activity took
};

// One dataset being recorded: its job and its task, interpreted for its mode.
struct Dataset {
  lfd_sim_bridge::DemoJob job;
  std::unique_ptr<demo::TaskInterpreter> interpreter;
  demo::TeleopStyle teleop;                         // the operator's (enabled in teleop mode)
  std::vector<task::Configuration> configurations;  // the selected ones, in the file's order
  double contact_threshold = 0.5;                   // N on a pad (the teleop operator's is higher)
};

// How a phase ended: at its planned end, or where a guarded step felt contact.
struct PhaseEnd {
  double elapsed = 0.0;       // s of sim time the phase took
  bool contact = false;       // a guarded step ended it early
  double contact_time = 0.0;  // s from the phase start
  Eigen::VectorXd joints;     // the chain's commanded joints where it ended
};

class Demonstrator {
 public:
  Demonstrator(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
    seed_ = pnh.param("seed", 1);
    const task::Scene scene = task::loadScene(required<std::string>(pnh, "scene_file"));
    robot_ = lfd::loadRobotSetup(required<std::string>(pnh, "robot_file"));
    demo::ToolGeometry tool;
    pnh.getParam("tool/fist_half_width", tool.fist_half_width);
    // Every task file is loaded and checked before anything is recorded: a bad one fails the run
    // at once, as it did when each dataset had a launch of its own.
    std::set<std::string> objects;
    for (const lfd_sim_bridge::DemoJob& job : lfd_sim_bridge::loadDemoJobs(pnh)) {
      Dataset d;
      d.job = job;
      const task::TaskDefinition definition =
          task::loadTask(task::taskFilePath(job.tasks_dir, job.task), scene);
      const std::vector<int>& wanted = job.configurations;
      for (const task::Configuration& c : definition.configurations.at(job.mode))
        if (wanted.empty() || std::find(wanted.begin(), wanted.end(), c.id) != wanted.end())
          d.configurations.push_back(c);
      if (d.configurations.empty())
        throw std::invalid_argument("no configuration of " + job.task + "/" + job.mode +
                                    " selected");
      const bool teleop = job.mode == "teleop";
      d.teleop = teleopStyle(pnh, teleop);
      d.interpreter = std::make_unique<demo::TaskInterpreter>(definition, scene, robot_.gripper,
                                                              tool, d.teleop);
      d.contact_threshold =
          teleop ? pnh.param("teleop/contact_threshold", 4.0) : pnh.param("contact_threshold", 0.5);
      objects.insert(definition.objects.begin(), definition.objects.end());
      datasets_.push_back(std::move(d));
    }

    speed_min_ = pnh.param("speed_min", 0.7);
    speed_max_ = pnh.param("speed_max", 1.3);
    sample_period_ = pnh.param("sample_period", 0.02);
    lead_in_ = pnh.param("lead_in", 0.3);
    tail_ = pnh.param("tail", 0.5);
    settle_before_ = pnh.param("scene_settle", 0.3);
    phase_period_ = 1.0 / pnh.param("phase_rate", 20.0);
    skip_existing_ = pnh.param("skip_existing", true);
    lockstep_ = pnh.param("lockstep", true);
    chunk_ = pnh.param("lockstep_chunk", 0.05);
    contact_chunk_ = pnh.param("lockstep_contact_chunk", 0.01);
    physics_dt_ = pnh.param("physics_dt", 0.001);
    publish_period_ = 1.0 / nh.param("/bridge/publish_rate", 200.0);

    trajectory_pub_ = nh.advertise<trajectory_msgs::JointTrajectory>("joint_trajectory", 10);
    gripper_pub_ = nh.advertise<lfd_msgs::GripperCommand>("gripper/command", 10);
    phase_pub_ = nh.advertise<lfd_msgs::Phase>("lfd/phase", 100);
    const auto hints = ros::TransportHints().tcpNoDelay();
    joint_sub_ = nh.subscribe("joint_states", 5, &Demonstrator::onJoints, this, hints);
    // The pads the grasps and guarded moves feel: the robot file's touch row.
    const lfd::SensorEntry* touch = lfd::findSensorOfType(robot_, "lfd_msgs/Touch");
    if (!touch)
      throw std::runtime_error(
          "the robot file has no lfd_msgs/Touch row in its sensor table; "
          "grasps and guarded moves need one");
    touch_sub_ = nh.subscribe(touch->topic, 5, &Demonstrator::onTouch, this, hints);
    for (const std::string& object : objects)
      object_subs_.push_back(nh.subscribe<geometry_msgs::PoseStamped>(
          "objects/" + object + "/pose", 5,
          [this, object](const geometry_msgs::PoseStamped::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            object_poses_[object] = fromMsg(m->pose);
          },
          ros::VoidConstPtr(), hints));
    reset_client_ = nh.serviceClient<lfd_msgs::ResetSim>("bridge/reset");
    scene_client_ = nh.serviceClient<lfd_msgs::SetScene>("bridge/set_scene");
    start_client_ = nh.serviceClient<lfd_msgs::StartRecording>("recorder/start");
    stop_client_ = nh.serviceClient<lfd_msgs::StopRecording>("recorder/stop");
    pause_client_ = nh.serviceClient<std_srvs::SetBool>("bridge/pause");
    step_client_ = nh.serviceClient<lfd_msgs::StepSim>("bridge/step", true);
  }

  // Runs every selected demonstration of every dataset; returns how many were recorded.
  int run() {
    waitForSystem();
    int recorded = 0;
    for (const Dataset& d : datasets_) {
      if (!ros::ok()) break;
      recorded += runDataset(d);
    }
    if (lockstep_) setPaused(false);  // leave the sim running for whoever comes next
    return recorded;
  }

 private:
  const Dataset& dataset() const { return *dataset_; }
  const std::string& taskName() const { return dataset_->job.task; }
  const std::string& mode() const { return dataset_->job.mode; }
  const task::TaskDefinition& definition() const { return dataset_->interpreter->task(); }
  const task::Scene& scene() const { return dataset_->interpreter->scene(); }

  int runDataset(const Dataset& d) {
    dataset_ = &d;
    noise_selected_ = false;
    // generate_datasets.py splits the launch's output into per-dataset logs at this line.
    ROS_INFO("demonstrator: dataset %s: %zu demos -> %s", d.job.name().c_str(),
             d.configurations.size(), d.job.output_dir.c_str());
    std::vector<DemoResult> results;
    for (const task::Configuration& c : d.configurations) {
      if (!ros::ok()) break;
      results.push_back(runDemo(c));
      lfd::trimHeap();  // the demo's plan and IK solutions go back to the system
    }
    writeSummary(results);
    int recorded = 0;
    for (const DemoResult& r : results) recorded += r.recorded ? 1 : 0;
    ROS_INFO(
        "demonstrator: %s/%s done, %d of %zu demos recorded (judge them from the bags: "
        "check_demo_bag.py)",
        taskName().c_str(), mode().c_str(), recorded, results.size());
    return recorded;
  }

  void waitForSystem() {
    ROS_INFO("demonstrator: waiting for the bridge, the recorder and sim time");
    while (ros::ok() && ros::Time::now().isZero()) ros::WallDuration(0.01).sleep();
    for (ros::ServiceClient* c : {&reset_client_, &scene_client_, &start_client_, &stop_client_})
      if (!c->waitForExistence(ros::Duration(60.0)))
        throw std::runtime_error("service " + c->getService() + " is not available");
    std::string urdf;
    if (!nh_.getParam("/robot_description", urdf))
      throw std::runtime_error("/robot_description is not set (launch sim.launch)");
    // The IK of the robot file (chain, costs, posture) for poses in its pose frame; that frame's
    // pose in the world comes from /tf_static.
    converter_ = std::make_unique<lfd::CartesianToJoints>(lfd::makeCartesianToJoints(urdf, robot_));
    // A listener only for this lookup: kept, it would take in every /tf message of every demo.
    tf2_ros::Buffer tf_buffer;
    const tf2_ros::TransformListener tf_listener(tf_buffer);
    // Waited for in wall time: tf's own timeout counts sim time, and 30 s of a simulation running
    // free at ~12x was 2.5 s, too short on a loaded machine for the listener to connect ("world
    // does not exist": a fresh root's recorder_topics test).
    const ros::WallTime tf_deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    std::string why;
    while (!tf_buffer.canTransform("world", robot_.poseFrame(), ros::Time(0), &why)) {
      if (ros::WallTime::now() > tf_deadline || !ros::ok())
        throw std::runtime_error("no transform from '" + robot_.poseFrame() +
                                 "' to 'world' on tf in 30 s of wall time: " + why);
      ros::WallDuration(0.01).sleep();
    }
    const geometry_msgs::TransformStamped w =
        tf_buffer.lookupTransform("world", robot_.poseFrame(), ros::Time(0));
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
    // A message published before its subscriber's connection is up is lost: the first demo's
    // approach trajectory once never reached the bridge (the arm stood still, then jumped).
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    for (const ros::Publisher* pub : {&trajectory_pub_, &gripper_pub_, &phase_pub_})
      while (ros::ok() && pub->getNumSubscribers() == 0) {
        if (ros::WallTime::now() > deadline)
          throw std::runtime_error("nobody subscribes to " + pub->getTopic() +
                                   " (the bridge and the recorder must run)");
        ros::WallDuration(0.01).sleep();
      }
    if (lockstep_) {
      if (!pause_client_.waitForExistence(ros::Duration(30.0)) ||
          !step_client_.waitForExistence(ros::Duration(30.0)))
        throw std::runtime_error("lockstep needs /bridge/pause and /bridge/step");
      step_client_ = nh_.serviceClient<lfd_msgs::StepSim>("bridge/step", true);
      setPaused(true);
      lfd_msgs::StepSim step;  // zero steps: read the paused sim time
      if (!step_client_.call(step) || !step.response.success)
        throw std::runtime_error("/bridge/step failed: " + step.response.message);
      now_ = ros::Time(step.response.sim_time);
      advanceTo(alignedToGrid(now_));
      ROS_INFO("demonstrator: lockstep with the bridge from t=%.3f", now_.toSec());
    }
  }

  DemoResult runDemo(const task::Configuration& c) {
    DemoResult result;
    result.configuration = c.id;
    std::ostringstream name;
    name << dataset().job.output_dir << "/" << taskName() << "_" << mode() << "_" << std::setw(2)
         << std::setfill('0') << c.id << ".bag";
    result.bag = name.str();
    if (skip_existing_ && std::ifstream(result.bag).good()) {
      ROS_INFO("demonstrator: %s exists, skipped", result.bag.c_str());
      result.error = "skipped (exists)";
      return result;
    }
    using Clock = lfd_sim_bridge::WallProfile::Clock;
    const Clock::time_point wall_start = Clock::now();
    profile_ = &result.wall_parts;
    try {
      execute(c, &result);
    } catch (const std::exception& e) {
      result.error = e.what();
      ROS_ERROR("demonstrator: %s/%s configuration %d failed: %s", taskName().c_str(),
                mode().c_str(), c.id, e.what());
      stopRecordingIfActive();
    }
    profile_ = nullptr;
    result.wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    return result;
  }

  // The robot in its ready posture (the gripper closed if the task starts with a fist), the
  // articulated joints at their start, the task's objects at their start and the others parked.
  void placeScene(const task::Configuration& c) {
    lfd_msgs::ResetSim reset;
    if (definition().gripper_closed_at_start) {
      // Closed before recording starts: a closing transient at the start would only mislead the
      // feature selection.
      reset.request.joint_names.push_back(robot_.gripper.joint);
      reset.request.positions.push_back(robot_.gripper.close_opening /
                                        robot_.gripper.opening_scale);
    }
    for (const std::string& joint : definition().joints(scene())) {
      const auto q = c.joints.find(joint);
      reset.request.joint_names.push_back(joint);
      reset.request.positions.push_back(q == c.joints.end() ? 0.0 : q->second);
    }
    // The dataset's first reset selects its mode's noise on the bridge (config/bridge.yaml
    // noise_profiles), restarting the noise generator: one launch or several, same noise.
    if (!noise_selected_) reset.request.noise_profile = mode();
    {
      const auto scope = measure("scene_calls");
      call(reset_client_, reset);
    }
    noise_selected_ = true;
    lfd_msgs::SetScene set;
    for (const task::SceneObject& o : scene().objects) {
      const auto used = c.objects.find(o.name);
      set.request.object_names.push_back(o.name);
      set.request.poses.push_back(
          lfd_sim_bridge::toPoseMsg(used == c.objects.end() ? o.park : used->second));
    }
    {
      const auto scope = measure("scene_calls");
      call(scene_client_, set);
    }
    advanceTo(now() + ros::Duration(settle_before_));
  }

  // Plans every phase (guarded moves running their course) and solves its IK before anything is
  // recorded: an unreachable pose fails here, naming the task file and the phase.
  double checkReachable(const demo::DemoState& state, const demo::Pose& start,
                        const Eigen::VectorXd& q0) {
    const demo::DemoPlan plan = dataset().interpreter->planAll(state);
    demo::Pose from = start;
    Eigen::VectorXd seed = q0;
    for (size_t i = 0; i < plan.phases.size(); ++i) {
      const demo::Phase& phase = plan.phases[i];
      try {
        seed = converter_->convert(demo::samplePhase(from, phase, sample_period_, 0.0), seed)
                   .positions.back();
      } catch (const std::exception& e) {
        throw std::runtime_error("task file '" + definition().path + "': phases[" +
                                 std::to_string(i) + "] (" + phase.name +
                                 ") is out of the robot's reach in configuration: " + e.what());
      }
      from = phase.segments.back().target;
    }
    return plan.duration();
  }

  std::string metadata(const task::Configuration& c, const demo::DemoState& state, double speed,
                       double tremor_rms, double planned) const {
    demo::DemoMetadata m;
    m.task = &definition();
    m.scene = &scene();
    m.configuration = &c;
    m.seed = seed_;
    m.speed = speed;
    m.tremor_rms = tremor_rms;
    m.planned_duration = planned;
    for (const std::string& object : definition().objects) {
      const demo::Frame& aim = state.frames.at(object);
      const demo::Frame& truth = state.true_starts.at(object);
      m.aim_offsets[object] = {world_from_base_.linear() * (aim.position - truth.position),
                               aim.yaw - truth.yaw};
    }
    return demo::metadataJson(m);
  }

  void execute(const task::Configuration& c, DemoResult* result) {
    std::mt19937 rng(static_cast<uint32_t>(seed_ * 1000 + c.id * 7 + (mode() == "teleop")));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double speed = speed_min_ + (speed_max_ - speed_min_) * unit(rng);
    placeScene(c);

    if (lockstep_) waitForFreshSensors();  // the joints after the scene's settling, not before
    const Eigen::VectorXd q0 = currentChainPositions();
    const demo::Pose start = converter_->forward(q0);
    demo::DemoState state = dataset().interpreter->begin(c, world_from_base_, start, speed, rng);
    const demo::TeleopStyle& teleop = dataset().teleop;
    const demo::Tremor tremor =
        teleop.enabled
            ? demo::Tremor(teleop.tremor_rms, teleop.tremor_low_hz, teleop.tremor_high_hz, rng())
            : demo::Tremor();
    double planned = 0.0;
    {
      const auto scope = measure("planning");
      planned = checkReachable(state, start, q0);
    }

    lfd_msgs::StartRecording start_rec;
    start_rec.request.bag_path = result->bag;
    lfd_msgs::DemoMetadata& meta = start_rec.request.metadata;
    meta.header.stamp = now();
    meta.header.frame_id = "world";
    meta.task = taskName();
    meta.configuration = c.id;
    meta.mode = mode();
    meta.speed = speed;
    meta.extra_json = metadata(c, state, speed, tremor.rms(), planned);
    {
      const auto scope = measure("recorder_calls");
      call(start_client_, start_rec);
    }
    recording_ = true;
    const ros::Time demo_start = meta.header.stamp;
    ROS_INFO("demonstrator: %s/%s configuration %d, speed %.2f, planned %.1f s -> %s",
             taskName().c_str(), mode().c_str(), c.id, speed, planned, result->bag.c_str());
    publishPhase(definition().phases.front().name, 0, demo_start);  // at rest during lead-in
    advanceTo(demo_start + ros::Duration(lead_in_));

    demo::Pose from = start;
    Eigen::VectorXd seed = q0;
    double t0 = 0.0;
    for (size_t i = 0; i < definition().phases.size(); ++i) {
      const demo::Phase phase = dataset().interpreter->planPhase(state, i, from);
      lfd::JointPath path;
      {
        const auto scope = measure("planning");
        path =
            converter_->convert(demo::samplePhase(from, phase, sample_period_, t0, &tremor), seed);
      }
      const PhaseEnd end = runPhase(phase, path);
      from = end.contact ? demo::phasePoseAt(from, phase, end.contact_time)
                         : phase.segments.back().target;
      seed = end.joints;
      t0 += end.elapsed;
    }

    advanceTo(now() + ros::Duration(tail_));
    lfd_msgs::StopRecording stop;
    {
      const auto scope = measure("recorder_calls");
      // The recorder stops at its newest /clock: let the last one (paused sim) reach it.
      ros::WallDuration(0.02).sleep();
      call(stop_client_, stop);
    }
    recording_ = false;
    {
      std::lock_guard<std::mutex> lock(phase_mutex_);
      phase_active_ = false;
    }
    result->recorded = true;
    result->duration = (now() - demo_start).toSec();
    result->final_state = finalState();
    ROS_INFO("demonstrator: configuration %d recorded, %.1f s, %lu messages; ends with %s", c.id,
             result->duration, static_cast<unsigned long>(stop.response.messages_written),
             result->final_state.c_str());
  }

  // Runs one phase's joint path; a guarded segment ends the phase at contact (the arm holds where
  // its command was).
  PhaseEnd runPhase(const demo::Phase& phase, const lfd::JointPath& path) {
    const ros::Time phase_start = now();
    publishPhase(phase.name, phase.index, phase_start);
    sendTrajectory(path, 0.0);
    double t = 0.0;
    PhaseEnd end;
    end.joints = path.positions.back();
    for (const demo::Segment& segment : phase.segments) {
      const ros::Time segment_start = phase_start + ros::Duration(t);
      advanceTo(segment_start);
      if (segment.gripper) sendGripper(*segment.gripper);
      t += segment.duration;
      if (segment.until_contact == demo::Contact::kNone) continue;
      const ros::Time timeout = phase_start + ros::Duration(t);
      while (ros::ok() && now() < timeout && !inContact(segment.until_contact))
        advanceTo(std::min(timeout, now() + ros::Duration(contact_chunk_)), contact_chunk_, true);
      if (inContact(segment.until_contact)) {
        end.contact = true;
        end.contact_time = (now() - phase_start).toSec();
        end.joints = jointsAt(path, end.contact_time);
        if (segment.is_move) sendTrajectory(path, end.contact_time);  // hold here
        advanceTo(now() + ros::Duration(segment.settle));
        end.elapsed = (now() - phase_start).toSec();
        return end;
      }
      if (&segment == &phase.segments.back()) {
        ROS_WARN("demonstrator: phase %s: no contact after %.2f s", phase.name.c_str(), t);
        advanceTo(phase_start + ros::Duration(t + segment.settle));
        t += segment.settle;
      }
    }
    advanceTo(phase_start + ros::Duration(t));
    end.elapsed = t;
    return end;
  }

  // The path's joints at time t (linear between samples).
  static Eigen::VectorXd jointsAt(const lfd::JointPath& path, double t) {
    const auto& times = path.times;
    if (t <= times.front()) return path.positions.front();
    for (size_t k = 1; k < times.size(); ++k)
      if (t <= times[k]) {
        const double u = (t - times[k - 1]) / (times[k] - times[k - 1]);
        return path.positions[k - 1] + u * (path.positions[k] - path.positions[k - 1]);
      }
    return path.positions.back();
  }

  // Sends the path from `from` (s): the whole path at 0, a one-point hold of its pose at `from`.
  void sendTrajectory(const lfd::JointPath& path, double from) {
    trajectory_msgs::JointTrajectory msg;
    msg.header.stamp = lockstep_ ? now() : ros::Time(0);  // lockstep: exactly now; else on receipt
    msg.joint_names = path.joint_names;
    if (from > 0.0) {
      const Eigen::VectorXd q = jointsAt(path, from);
      trajectory_msgs::JointTrajectoryPoint p;
      p.positions.assign(q.data(), q.data() + q.size());
      p.velocities.assign(q.size(), 0.0);
      msg.points.push_back(p);
    } else {
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
    }
    trajectory_pub_.publish(msg);
    waitUntilTaken(msg.header.stamp, &lfd_msgs::StepSim::Response::last_trajectory_stamp);
  }

  void sendGripper(const demo::GripperAction& action) {
    lfd_msgs::GripperCommand g;
    g.header.stamp = now();
    g.position = action.opening;
    g.max_effort = action.max_effort;
    gripper_pub_.publish(g);
    waitUntilTaken(g.header.stamp, &lfd_msgs::StepSim::Response::last_gripper_stamp);
  }

  // --- ground-truth phase: at every transition and on a fixed sim-time grid in between ---
  void publishPhase(const std::string& name, int index, const ros::Time& stamp) {
    publishPhaseGrid(stamp);  // the previous phase up to the transition
    std::lock_guard<std::mutex> lock(phase_mutex_);
    phase_msg_.task = taskName();
    phase_msg_.name = name;
    phase_msg_.index = index;
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
      bool stepped = false;
      {
        const auto scope = measure(fresh_sensors ? "contact_step_calls" : "step_calls");
        stepped = step_client_.call(step);
      }
      if (!stepped || !step.response.success)
        throw std::runtime_error("/bridge/step failed: " + step.response.message);
      now_ = ros::Time(step.response.sim_time);
      publishPhaseGrid(now_);
      if (fresh_sensors) waitForFreshSensors();
    }
  }

  // Lockstep: the sensors of the step just taken (for contact checks) reach this node.
  void waitForFreshSensors() {
    const auto scope = measure("sensor_waits");
    // A bounded wait would let a loaded machine decide a contact on an older reading (the
    // sensor topics lagged /joint_states by up to 1.4 s): wait for this step's reading.
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kCommandWait);
    while (ros::ok()) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        const ros::Time fresh = now_ - ros::Duration(publish_period_ / 2);
        if (touch_.header.stamp >= fresh && joints_.header.stamp >= fresh) return;
      }
      if (ros::WallTime::now() > deadline)
        throw std::runtime_error("no touch and joint reading of sim time " +
                                 std::to_string(now_.toSec()) + " s within " +
                                 std::to_string(kCommandWait) + " s of wall time");
      ros::WallDuration(0.0002).sleep();
    }
  }

  // A command published just before a /bridge/step call must be processed before that step.
  // The command travels on a topic, the next /bridge/step on a service connection: nothing orders
  // the two. Lockstep asks the bridge (0-step calls) until it reports the command's stamp taken in:
  // a fixed sleep (20 ms) let a loaded machine step past a command, and demos differed run to run.
  void waitUntilTaken(const ros::Time& stamp, double lfd_msgs::StepSim::Response::*taken) {
    if (!lockstep_) return;
    const auto scope = measure("settle_sleeps");
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kCommandWait);
    while (ros::ok()) {
      lfd_msgs::StepSim query;  // steps = 0
      if (!step_client_.call(query) || !query.response.success)
        throw std::runtime_error("/bridge/step (query) failed: " + query.response.message);
      if (query.response.*taken >= stamp.toSec() - 1e-9) return;
      if (ros::WallTime::now() > deadline)
        throw std::runtime_error("the bridge did not take in a command stamped " +
                                 std::to_string(stamp.toSec()) + " s within " +
                                 std::to_string(kCommandWait) + " s of wall time");
      ros::WallDuration(0.0005).sleep();
    }
  }

  void setPaused(bool paused) {
    std_srvs::SetBool srv;
    srv.request.data = paused;
    if (!pause_client_.call(srv) || !srv.response.success)
      throw std::runtime_error("/bridge/pause failed: " + srv.response.message);
  }

  // --- helpers ---
  // Counts the scope's wall time for the demo being recorded (nothing between demos).
  lfd_sim_bridge::WallProfile::Scope measure(const char* activity) {
    return lfd_sim_bridge::WallProfile::Scope(profile_, activity);
  }

  template <typename Srv>
  void call(ros::ServiceClient& client, Srv& srv) {
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

  bool inContact(demo::Contact mode) {
    if (lockstep_) waitForFreshSensors();  // this step's pads, not a reading from before it
    std::lock_guard<std::mutex> lock(mutex_);
    if (touch_.values.empty()) return false;
    const auto [lo, hi] = std::minmax_element(touch_.values.begin(), touch_.values.end());
    const double value = mode == demo::Contact::kAny ? *hi : *lo;
    return value >= dataset().contact_threshold &&
           (mode != demo::Contact::kBoth || touch_.values.size() >= 2);
  }

  // Where the task's objects and articulated joints are now (logged; the judge reads the bags).
  std::string finalState() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream s;
    s << std::setprecision(4) << "{";
    bool first = true;
    for (const auto& [name, pose] : object_poses_) {
      const auto& used = definition().objects;  // the other datasets' objects are parked
      if (std::find(used.begin(), used.end(), name) == used.end()) continue;
      s << (first ? "" : ", ") << name << ": [" << pose.position.x() << ", " << pose.position.y()
        << ", " << pose.position.z() << ", " << demo::yawOf(pose.orientation) << "]";
      first = false;
    }
    for (const std::string& joint : definition().joints(scene())) {
      const auto it = std::find(joints_.name.begin(), joints_.name.end(), joint);
      if (it == joints_.name.end()) continue;
      s << (first ? "" : ", ") << joint << ": " << joints_.position[it - joints_.name.begin()];
      first = false;
    }
    return s.str() + "}";
  }

  void onJoints(const sensor_msgs::JointState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    joints_ = *msg;
  }
  void onTouch(const lfd_msgs::Touch::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    touch_ = *msg;
  }

  void writeSummary(const std::vector<DemoResult>& results) const {
    const std::string path =
        dataset().job.output_dir + "/demonstrator_summary_" + taskName() + "_" + mode() + ".yaml";
    std::ofstream out(path);
    out << "task: " << taskName() << "\nmode: " << mode() << "\ndemos:\n";
    for (const DemoResult& r : results) {
      out << "  - {configuration: " << r.configuration << ", bag: " << demo::jsonString(r.bag)
          << ", recorded: " << (r.recorded ? "true" : "false") << ", duration: " << r.duration
          << ", final: " << (r.final_state.empty() ? "{}" : r.final_state)
          << ", error: " << demo::jsonString(r.error) << ", wall: " << r.wall
          << ", wall_parts: " << r.wall_parts.flowMap()
          << ", wall_counts: " << r.wall_parts.countsFlowMap() << "}\n";
    }
  }

  ros::NodeHandle nh_;
  int seed_ = 1;
  std::vector<Dataset> datasets_;
  const Dataset* dataset_ = nullptr;                // the one being recorded
  bool noise_selected_ = false;                     // its noise profile is selected on the bridge
  lfd_sim_bridge::WallProfile* profile_ = nullptr;  // the wall-time breakdown of the current demo
  double speed_min_, speed_max_, sample_period_, lead_in_, tail_, settle_before_, phase_period_;
  bool skip_existing_ = true;
  lfd::RobotSetup robot_;
  std::unique_ptr<lfd::CartesianToJoints> converter_;
  Eigen::Isometry3d world_from_base_ = Eigen::Isometry3d::Identity();

  ros::Publisher trajectory_pub_, gripper_pub_, phase_pub_;
  ros::Subscriber joint_sub_, touch_sub_;
  std::vector<ros::Subscriber> object_subs_;
  ros::ServiceClient reset_client_, scene_client_, start_client_, stop_client_;

  std::mutex mutex_;
  sensor_msgs::JointState joints_;
  lfd_msgs::Touch touch_;
  std::map<std::string, demo::Pose> object_poses_;
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
  // A restarted master: the datasets cannot go on (the simulation and the recorder restart too);
  // the node ends with an error, and with it the launch (required="true").
  const lfd_ros::MasterWatch master_watch({"/use_sim_time"});
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
  return master_watch.exitCode();
}
