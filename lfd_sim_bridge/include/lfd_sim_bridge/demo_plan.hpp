// The demonstrator's one interpreter of task files (ROS-free): the phases of a demonstration, each
// a list of Cartesian segments of the gripper TCP (in base_link) with the gripper actions
// attached, timed by the minimum-jerk law and scaled by the demo's speed, built from the task
// file's primitives (move to a pose relative to a named frame, carry, push, open or close the
// gripper, close until contact, move until contact, hold, release, retreat).
// Teleop-like mode adds what a human operator does: hesitations (a move split into two
// sub-movements with a pause), uneven segment durations, a misjudged object position (the task
// file's teleop_placement), hand tremor and a timed gripper close without force feedback.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/demo_motion.hpp"
#include "lfd_sim_bridge/task_file.hpp"

namespace lfd_sim_bridge {
namespace demo {

using task::Contact;

struct GripperAction {
  double opening = 0.0;     // m between the fingers
  double max_effort = 0.0;  // N, <= 0 = the model default
};

struct Segment {
  std::string label;  // the step's label, e.g. "pregrasp", "close", "lift"
  Pose target;        // TCP pose (base_link) at the end of the segment (= start pose for a hold)
  double duration = 0.0;                 // s, speed scaling and hesitations included
  bool is_move = true;                   // false: hold the pose (e.g. while the gripper closes)
  std::optional<GripperAction> gripper;  // sent when the segment starts
  // The phase ends once the pads touch (any or both), plus `settle` seconds; a guarded move stops
  // where it is. Without contact the segment runs its course (`duration` is the timeout).
  Contact until_contact = Contact::kNone;
  double settle = 0.0;
};

struct Phase {
  std::string name;  // from the task file
  int index = 0;
  bool window = false;  // a transition window between two skills
  std::vector<Segment> segments;
  double duration() const;
};

struct DemoPlan {
  std::string task;
  Pose start;  // TCP pose when the demo starts
  std::vector<Phase> phases;
  double duration() const;
};

// Human-operator behaviour of the teleop-like mode.
struct TeleopStyle {
  bool enabled = false;
  double hesitation_probability = 0.4;      // per move: split into two sub-movements
  double pause_min = 0.2, pause_max = 0.7;  // s between the sub-movements
  double duration_jitter = 0.25;            // per-move duration factor in [1-j, 1+j]
  double slowdown_probability = 0.25;       // per move: extra slow-down by slowdown_factor
  double slowdown_factor = 1.6;
  double reaction_delay = 0.25;  // s, operator's delay before closing the gripper
  double timed_close = 0.9;      // s the operator waits after commanding the close
  double tremor_rms = 0.002;     // m per axis
  double tremor_low_hz = 8.0, tremor_high_hz = 12.0;
};

// The closed fingers form a square block: TCP to any of its faces (m), for touch frames.
struct ToolGeometry {
  double fist_half_width = 0.012;
};

// A horizontal frame in base_link: a position and a yaw; TCP poses (tcp, start) also keep their
// orientation, which targets relative to them inherit.
struct Frame {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  std::optional<Eigen::Quaterniond> orientation;
};

// The operator's timing of one step, drawn when the demo starts, so that a phase planned again
// after an early contact keeps it.
struct StepTiming {
  double duration = 0.0;  // s
  bool hesitate = false;
  double split = 0.5, pause = 0.0;
};

// One demonstration being planned.
struct DemoState {
  std::map<std::string, Frame> frames;       // every named frame, as the demonstrator aims at it
  std::map<std::string, Frame> true_starts;  // objects and object frames where they really start
  std::vector<std::vector<StepTiming>> timings;  // per phase, per step
  Pose start;                                    // TCP at the demo's start
  Pose grasp_tcp;  // TCP when the gripper last closed: the hand's hold on what it carries
};

class TaskInterpreter {
 public:
  TaskInterpreter(task::TaskDefinition task, task::Scene scene, lfd::GripperSetup gripper,
                  ToolGeometry tool, TeleopStyle teleop);

  // A demonstration of configuration `c` (world poses) with base_link at `world_from_base` and
  // the TCP at `start` (base_link), at `speed` (durations divided by it): draws the demo's
  // variation and the operator's timing from `rng`. Throws std::invalid_argument (naming the task
  // file and the frame) when a frame is degenerate (a heading toward its own origin) or speed <= 0.
  DemoState begin(const task::Configuration& c, const Eigen::Isometry3d& world_from_base,
                  const Pose& start, double speed, std::mt19937& rng) const;

  // Phase `i`, with the TCP at `tcp` (base_link) where the previous phase ended (or where its
  // guarded move stopped). Updates the state's hold on a carried object.
  Phase planPhase(DemoState& state, size_t i, const Pose& tcp) const;

  // Every phase, each guarded move running its course: the plan checked before recording.
  DemoPlan planAll(DemoState state) const;

  const task::TaskDefinition& task() const { return task_; }
  const task::Scene& scene() const { return scene_; }

 private:
  Frame resolveFrame(const DemoState& s, const task::FrameSpec& f) const;
  Pose target(const DemoState& s, const task::PoseSpec& spec) const;
  Frame targetFrame(const DemoState& s, const task::PoseSpec& spec) const;
  const Frame& frame(const DemoState& s, const std::string& name) const;
  void addStep(DemoState& s, const task::Step& step, const StepTiming& timing, Pose* tcp,
               std::vector<Segment>* out) const;
  StepTiming drawTiming(const task::Step& step, double speed, std::mt19937& rng) const;

  task::TaskDefinition task_;
  task::Scene scene_;
  lfd::GripperSetup gripper_;
  ToolGeometry tool_;
  TeleopStyle teleop_;
};

// Yaw (rad) of an orientation about z (the axis of a stick on the table).
double yawOf(const Eigen::Quaterniond& q);

// How far behind the centre of a box (horizontal half sizes `half`, turned by `yaw`) a flat
// pusher of half width `pusher_half` first touches it, moving along the horizontal unit `dir`
// through the centre. Off the box's axes the contact is an edge or a corner, farther than a face.
double contactDistance(const Eigen::Vector3d& dir, const Eigen::Vector2d& half, double yaw,
                       double pusher_half);

using TimedPose = lfd::TimedPose;

// Samples the segments of one phase every `dt` from `start` (the phase's start pose) at times
// t0 + k*dt; the last sample lands exactly at the phase end. Moves follow the minimum-jerk law;
// `tremor` (evaluated at the absolute demo time t0 + t) is added to every position.
std::vector<TimedPose> samplePhase(const Pose& start, const Phase& phase, double dt, double t0,
                                   const Tremor* tremor = nullptr);

// TCP pose at time t (s from the phase start) without tremor.
Pose phasePoseAt(const Pose& start, const Phase& phase, double t);

}  // namespace demo
}  // namespace lfd_sim_bridge
