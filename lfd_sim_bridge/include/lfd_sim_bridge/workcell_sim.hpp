// ROS-free MuJoCo workcell: loads the MJCF scene, emulates a position-controlled hardware
// interface (PD tracking of joint targets with position, velocity and effort limits, smooth
// trajectories, a parallel gripper), steps physics at the model timestep, reads every sensor the
// pipeline records, and recovers from numerical divergence instead of crashing.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "lfd_sim_bridge/trajectory_interpolator.hpp"

struct mjModel_;
struct mjData_;

namespace lfd_sim {

enum class LogLevel { kInfo, kWarn, kError };
using LogSink = std::function<void(LogLevel, const std::string&)>;

// Gaussian noise (standard deviations, SI units) added to the readings returned by readState().
// All zero = exact readings. Control always uses the exact state.
struct SensorNoise {
  double joint_position = 0.0;  // rad or m
  double joint_velocity = 0.0;
  double joint_effort = 0.0;
  double force = 0.0;            // N
  double torque = 0.0;           // N m
  double touch = 0.0;            // N
  double gyro = 0.0;             // rad/s
  double accel = 0.0;            // m/s^2
  double ee_position = 0.0;      // m
  double ee_orientation = 0.0;   // rad (small random rotation)
  double gripper = 0.0;          // m
  double object_position = 0.0;  // m
};

// Model sensors read together: one row of the robot's sensor table (lfd::SensorEntry), keyed by
// its name (the row's topic). Each sensor's noise follows its kind (force, torque, touch, gyro,
// accelerometer; others exact), and touch sensors respond with touch_time_constant.
struct SensorGroup {
  std::string name;
  std::vector<std::string> sensors;  // MJCF sensor names
};

struct WorkcellConfig {
  // Proportional gain per actuated joint. Joints not listed keep the MJCF position actuator's kp,
  // or default_kp if the actuator has none.
  std::map<std::string, double> kp;
  double default_kp = 200.0;
  // Damping: joint damping is raised to damping_ratio * 2 sqrt(kp * I_eff) (critical at 1) unless
  // given per joint in `kd`. It is applied as implicit joint damping (unconditionally stable) with
  // the target velocity fed forward, so it does not slow trajectory tracking.
  double damping_ratio = 1.0;
  std::map<std::string, double> kd;
  // Velocity limits (rad/s or m/s) of the target motion, and effort limits (N m or N).
  // Effort: per joint here, else URDF (see applyUrdfLimits), else the actuator's forcerange.
  double default_velocity_limit = 2.0;
  std::map<std::string, double> velocity_limits;
  std::map<std::string, double> effort_limits;
  double default_effort_limit = 200.0;  // when neither config, URDF nor MJCF gives one
  // Feed forward gravity and Coriolis torques (within the effort limit), as a humanoid's
  // position controller would; without it the arm sags by g(q)/kp.
  bool gravity_compensation = true;
  // Initial posture used by reset(); joints not listed start at the model's qpos0.
  std::map<std::string, double> initial_posture;
  // Gripper: actuated joint name ("" = none), opening between the fingers = scale * position.
  std::string gripper_joint;
  double gripper_opening_scale = 2.0;
  // The robot's frames (its robot file: the Cartesian frame and the IK tip): the body every
  // end-effector pose is expressed in ("" = the robot's root body) and the end-effector site.
  std::string base_body;
  std::string ee_site;
  // The sensors read into WorkcellState::sensors, one group per sensor table row, in this order
  // (readings and their noise are drawn in it). A name the model lacks is an error naming it.
  std::vector<SensorGroup> sensors;
  // Bodies reported as objects (world poses). Free bodies and mocap bodies (fixed objects such as
  // a cabinet) can be placed by setObjectPose; any other body (a drawer's handle) is reported only.
  std::vector<std::string> objects = {"stick", "box"};
  // Touch pads: first-order response (s) of the reported normal force. A rigid simulated contact
  // pushed by a stiff position controller chatters at the physics rate (impacts of 0-5 N); a real
  // pad's elastomer and readout report their mean. 0 = the raw per-step MuJoCo reading.
  double touch_time_constant = 0.0;
  // Readings noise (teleop-like mode), seeded for reproducible datasets.
  SensorNoise noise;
  uint64_t noise_seed = 1;
  // Divergence: any |qvel| above this (rad/s, m/s) counts as a blow-up and triggers a reset.
  double max_abs_velocity = 200.0;
  // Where objects may be placed (world frame, m): outside it an object falls forever and the
  // divergence check resets the sim on every step.
  std::array<double, 3> workspace_min{-3.0, -3.0, -0.5};
  std::array<double, 3> workspace_max{3.0, 3.0, 3.0};
  // |norm - 1| of a commanded quaternion that is normalized; beyond it the pose is refused.
  double quaternion_tolerance = 0.01;
};

struct Pose {
  std::array<double, 3> position{0, 0, 0};
  std::array<double, 4> orientation{1, 0, 0, 0};  // quaternion w, x, y, z
};

struct JointLimit {
  double lower = -1e300, upper = 1e300;
  bool position_limited = false;
  double velocity = 0.0;  // max |target rate|
  double effort = 0.0;    // max |actuator force|
};

// The readings of one SensorGroup.
struct SensorReading {
  std::string name;                         // the group's
  std::vector<std::string> sensors;         // its sensors
  std::vector<std::vector<double>> values;  // per sensor, its MuJoCo dimension
};

// One snapshot of everything the bridge publishes, at sim time `time`.
struct WorkcellState {
  double time = 0.0;
  std::vector<std::string> joint_names;  // every hinge/slide joint of the model (no free joints)
  std::vector<double> joint_positions, joint_velocities, joint_efforts;
  // Parallel to joint_names: true for a joint of a scene object (a drawer's slide), whose body is
  // not in the robot's tree. The bridge keeps these off the robot's /joint_states.
  std::vector<bool> object_joint;
  // Per WorkcellConfig::sensors group, in its order: each sensor's reading, as MuJoCo gives it
  // (in its site's frame; a quaternion w, x, y, z).
  std::vector<SensorReading> sensors;
  const SensorReading* sensor(const std::string& group) const;
  double gripper_opening = 0.0, gripper_velocity = 0.0, gripper_effort = 0.0;
  Pose ee_pose;                                                       // ee_site in base_body
  std::array<double, 3> ee_linear_velocity{}, ee_angular_velocity{};  // in base_body axes
  std::vector<std::string> object_names;
  std::vector<Pose> object_poses;  // world
};

class WorkcellSim {
 public:
  // Loads the MJCF file; throws std::runtime_error with MuJoCo's message if it fails.
  explicit WorkcellSim(const std::string& mjcf_path, const WorkcellConfig& config = {},
                       LogSink log = nullptr);
  ~WorkcellSim();
  WorkcellSim(const WorkcellSim&) = delete;
  WorkcellSim& operator=(const WorkcellSim&) = delete;

  // Overrides velocity/effort limits from a URDF string (joint <limit velocity effort>), unless
  // the config names the joint explicitly. Throws std::invalid_argument if the URDF does not parse.
  void applyUrdfLimits(const std::string& urdf_xml);

  // --- commands (all throw std::invalid_argument on bad input and then change nothing) ---
  // Streamed targets; cancels any running trajectory.
  void setJointTargets(const std::vector<std::string>& names, const std::vector<double>& positions);
  // Replaces the current trajectory. It starts at max(start_time, now) (start_time <= 0 = now).
  // A waypoint velocity beyond its joint's velocity limit refuses the whole trajectory (the error
  // names the point, the joint, the value and the limit): a Hermite segment with 1e308 rad/s,
  // even clamped to the limit, overshot both waypoints of a 0.1 rad move by 0.6 rad.
  // A repeat of the running trajectory with the same start_time > 0 is ignored, so senders may
  // resend a stamped trajectory (ROS can drop the first messages of a new connection).
  void setTrajectory(const JointTrajectory& trajectory, double start_time = 0.0);
  // Opening between the fingers (m) and max force (N, <= 0 = the joint's effort limit).
  void setGripper(double opening, double max_effort);

  // --- simulation ---
  void step(int n = 1);
  double time() const;
  double timestep() const;
  // Robot to a posture (empty = configured initial posture; unlisted joints take the initial
  // posture), zero velocities, targets = posture, trajectory cancelled. Every hinge/slide joint is
  // reset this way, the joints of articulated objects (a drawer) included: they return to the
  // model's qpos0 unless `posture` names them. Objects return to their initial poses if
  // reset_objects, else keep their scene poses. Sim time keeps running (never goes backwards).
  void reset(const std::map<std::string, double>& posture = {}, bool reset_objects = false);
  void setObjectPose(const std::string& object, const Pose& pose_in_world);
  // Throws std::invalid_argument (naming the object and the bound) unless `object` exists and the
  // pose is finite, inside the workspace and its quaternion unit within quaternion_tolerance.
  void checkObjectPose(const std::string& object, const Pose& pose_in_world) const;

  // --- faults (sim only: tests and benchmarks of execution monitoring; lib/workcell_faults.cpp).
  // reset() undoes every one. Each throws std::invalid_argument naming a bad target or value.
  // The gripper's force limit becomes `fraction` (in [0, 1]) of the commanded one, from now on.
  void weakenGrip(double fraction);
  // The joint (e.g. the drawer's slide) stuck: under `holding_force` (N or N m, > 0) it creeps at
  // 1 mm/s (1 mrad/s) at most. The model needs the Euler integrator (implicit damping).
  void lockJoint(const std::string& joint, double holding_force);
  // The sensor table row `group` repeats its current reading.
  void freezeSensor(const std::string& group);
  bool hasSensorGroup(const std::string& group) const;

  // --- readings ---
  WorkcellState readState();  // noisy if config.noise is non-zero
  // Replaces the readings noise and restarts its generator from `seed`: the noise that follows
  // depends only on (noise, seed) and the readings taken since, not on what ran before (one
  // simulation records datasets of different modes in turn).
  void setNoise(const SensorNoise& noise, uint64_t seed);
  const SensorNoise& sensorNoise() const { return config_.noise; }
  void readState(WorkcellState* state);
  Pose basePoseInWorld() const;

  // --- introspection ---
  const std::vector<std::string>& actuatedJoints() const { return actuated_names_; }
  const std::vector<std::string>& jointNames() const { return joint_names_; }
  // The dimension of a model sensor (3 for a force, 1 for a touch pad); throws naming it if the
  // model has none of that name.
  int sensorDimension(const std::string& sensor) const;
  bool hasJoint(const std::string& name) const;
  JointLimit jointLimit(const std::string& actuated_joint) const;
  double jointPosition(const std::string& name) const;
  double jointTarget(const std::string& actuated_joint) const;  // after clamping & rate limit
  double actuatorForce(const std::string& actuated_joint) const;
  bool trajectoryActive() const;     // true until sim time passes the trajectory's last point
  double trajectoryEndTime() const;  // 0 when none has been set
  int divergenceCount() const { return divergence_count_; }
  const mjModel_* model() const { return m_; }
  mjData_* data() { return d_; }
  // For tests: write NaN into the velocity of the first dof, as a blow-up would.
  void injectNaNForTest();

 private:
  void checkTrajectoryVelocities(const JointTrajectory& trajectory,
                                 const std::vector<int>& index) const;
  struct Actuated;
  void loadModel(const std::string& mjcf_path);  // m_ and d_, or throws with nothing held
  void releaseModel();
  void configureFromModel();
  void configureActuators();
  void configureGains(Actuated& a);   // kp and kd of a's joint
  void configureLimits(Actuated& a);  // a's position, velocity and effort limits
  void findBaseBody();                // base_body_: config's, else the robot's root body
  void recordInitialScene();
  void computeControls();
  bool diverged(std::string* why) const;
  std::array<int, 4> badNumberWarnings() const;
  void recoverFromDivergence(const std::string& why);
  void applyPosture(const std::map<std::string, double>& posture);
  void log(LogLevel level, const std::string& text) const;
  double clampTarget(Actuated& a, double target);
  Pose bodyPose(int body) const;
  int actuatedIndex(const std::string& name) const;
  double noise(double std);

  WorkcellConfig config_;
  LogSink log_;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  std::vector<Actuated> actuated_;
  std::vector<std::string> actuated_names_;
  std::map<std::string, int> actuated_index_;
  std::vector<std::string> joint_names_;
  std::vector<int> joint_ids_;
  std::vector<bool> object_joint_;  // parallel to joint_ids_ (WorkcellState::object_joint)
  std::unique_ptr<TrajectoryInterpolator> trajectory_;
  std::vector<int> trajectory_to_actuated_;
  JointTrajectory last_trajectory_;
  double last_trajectory_stamp_ = 0.0;
  std::vector<double> traj_pos_, traj_vel_;
  int base_body_ = -1, ee_site_ = -1, gripper_ = -1;
  // One read sensor: its sensordata address, dimension and noise; touch_slot indexes
  // touch_filtered_ for a touch sensor (-1 otherwise).
  struct SensorSlot {
    int adr = -1, dim = 0, touch_slot = -1;
    const double SensorNoise::*noise = nullptr;  // the kind's noise; nullptr = exact
  };
  std::vector<std::vector<SensorSlot>> sensor_slots_;  // parallel to config_.sensors
  void checkRobotNames() const;  // throws std::invalid_argument naming the first mismatch
  void configureSensors();
  SensorSlot sensorSlot(const std::string& group, const std::string& sensor);
  std::vector<int> touch_adr_;          // sensordata address of each touch sensor read
  std::vector<double> touch_filtered_;  // the pads' response (touch_time_constant)
  void updateTouch();
  void readSensors(WorkcellState* state);
  std::vector<std::pair<std::string, int>> objects_;  // name, body id
  std::vector<double> initial_qpos_;                  // model qpos0: initial object poses
  std::vector<double> scene_qpos_;   // object poses last set (divergence recovery restores them)
  std::vector<double> scene_mocap_;  // fixed objects' poses last set, 7 per mocap body
  int freeJointOf(int body) const;   // the body's free joint, or -1
  void restoreMocap();
  int divergence_count_ = 0;
  // Faults in force (undone by reset): the grip's fraction, the locked dofs' own damping,
  // the frozen rows' readings (index in config_.sensors).
  double grip_fraction_ = 1.0;
  std::map<int, double> locked_dofs_;
  std::map<std::size_t, std::vector<std::vector<double>>> frozen_readings_;
  void applyGripperEffort();
  void clearFaults();
  std::mt19937_64 rng_;
  bool noisy_ = false;
};

}  // namespace lfd_sim
