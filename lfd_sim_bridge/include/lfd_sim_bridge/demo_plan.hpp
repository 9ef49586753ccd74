// The demonstrator's finite-state machine as a plan (ROS-free): the phases of a grasp or push
// demonstration, each a list of Cartesian segments of the gripper TCP (in base_link) with the
// gripper actions attached, timed by the minimum-jerk law and scaled by the demo's speed.
// Teleop-like mode adds what a human operator does: hesitations (a move split into two
// sub-movements with a pause), uneven segment durations, hand tremor and a timed gripper close.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "lfd_sim_bridge/demo_motion.hpp"

namespace lfd_sim_bridge {
namespace demo {

struct GripperAction {
  double opening = 0.0;     // m between the fingers
  double max_effort = 0.0;  // N, <= 0 = the model default
};

struct Segment {
  std::string label;  // e.g. "pregrasp", "descend", "close", "lift"
  Pose target;        // TCP pose (base_link) at the end of the segment (= start pose for a hold)
  double duration = 0.0;                 // s, speed scaling and hesitations included
  bool is_move = true;                   // false: hold the pose (e.g. while the gripper closes)
  std::optional<GripperAction> gripper;  // sent when the segment starts
  // Sim mode: the segment (a hold) ends once both finger pads touch, plus `settle` seconds;
  // `duration` is then the timeout.
  bool until_contact = false;
  double settle = 0.0;
};

struct Phase {
  std::string name;  // "approach", "grasp", "move" | "approach", "push", "return"
  int index = 0;
  std::vector<Segment> segments;
  double duration() const;
};

struct DemoPlan {
  std::string task;  // "grasp" or "push"
  Pose start;        // TCP pose when the demo starts
  std::vector<Phase> phases;
  double duration() const;
};

// One demonstration's situation, in base_link.
struct TaskInstance {
  std::string task;   // "grasp" or "push"
  Pose object_start;  // stick or box pose on the table
  Pose goal;          // grasp: where the stick must end (lifted); push: box target pose
};

// Gripper and task geometry (see config/demonstrator.yaml).
struct Geometry {
  Eigen::Quaterniond grasp_orientation = Eigen::Quaterniond::Identity();  // TCP, stick yaw 0
  Eigen::Quaterniond push_orientation = Eigen::Quaterniond::Identity();   // TCP, push along +x
  double pregrasp_height = 0.10;                                          // m above the grasp pose
  double grasp_height = 0.0;          // TCP height above the stick's centre at the grasp
  double lift_height = 0.15;          // m, lift before carrying (>= 0.10 per the protocol)
  double open_opening = 0.08;         // m
  double grasp_opening = 0.0;         // m commanded to close on the stick (sim)
  double grasp_effort = 20.0;         // N
  double teleop_close_opening = 0.0;  // m, the operator closes fully (overshoot)
  double box_half_length = 0.05;      // m, box half extent along the push direction
  double push_clearance = 0.02;       // m, fingers to box face when lowered behind the box
  double push_contact_depth = 0.0;    // m past the face the approach ends (0 = just touching)
  double tcp_to_face = 0.015;         // m, TCP centre to the gripper's pushing face
  double push_height = 0.0;           // TCP height above the box centre while pushing
  double push_prelift = 0.08;         // m, approach from above before lowering behind the box
  double retreat = 0.06;              // m, back-off after the push
};

// Nominal durations (s) at speed 1.
struct Timing {
  double to_pregrasp = 2.0, descend = 1.2, close = 1.0, settle = 0.3, lift = 1.2, carry = 2.0,
         hold = 0.6;
  double to_prepush = 2.0, lower = 1.0, touch = 0.8, push = 2.5, retreat = 1.0, go_home = 2.0;
  double open = 0.5;  // opening the gripper at the start
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
  double grasp_position_noise = 0.01;  // m, operator's placement error (uniform +-)
};

struct Variation {
  double speed = 1.0;               // time scaling: durations divided by speed
  double grasp_offset_along = 0.0;  // m along the stick axis
  double grasp_yaw = 0.0;           // rad added to the stick's yaw for the gripper
};

// Builds the phases of one demonstration from the start TCP pose. `rng` draws the teleop
// behaviour (ignored in sim mode). Throws std::invalid_argument on an unknown task or speed <= 0.
DemoPlan planDemo(const TaskInstance& instance, const Pose& start, const Geometry& geometry,
                  const Timing& timing, const Variation& variation, const TeleopStyle& teleop,
                  std::mt19937& rng);

// Yaw (rad) of a pose about the base z axis (the stick's axis direction on the table).
double yawOf(const Eigen::Quaterniond& q);

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
