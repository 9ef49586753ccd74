#include "lfd_sim_bridge/workcell_sim.hpp"

#include <mujoco/mujoco.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace lfd_sim {

// Per actuated joint: addresses, gains, limits and the target pipeline
// desired (command, clamped to the position limits) -> command (rate limited) -> ctrl.
struct WorkcellSim::Actuated {
  std::string name;
  int joint = -1, qpos_adr = -1, dof_adr = -1, actuator = -1;
  double kp = 0.0, kd = 0.0;
  JointLimit limit;
  double effort_cap = 0.0;  // current force limit (gripper max_effort may lower it)
  double desired = 0.0;     // target after position clamping
  double command = 0.0;     // target after velocity limiting, what the PD tracks
  double command_velocity = 0.0;
  bool warned_out_of_range = false;
  bool effort_from_config = false, velocity_from_config = false;
};

namespace {

// MuJoCo reports warnings through one global hook; route them to the sim being stepped.
thread_local const WorkcellSim* g_active_sim = nullptr;
thread_local LogSink* g_active_sink = nullptr;

void mujocoWarning(const char* msg) {
  if (g_active_sink && *g_active_sink) {
    (*g_active_sink)(LogLevel::kWarn, std::string("MuJoCo: ") + msg);
  } else {
    std::fprintf(stderr, "MuJoCo warning: %s\n", msg);
  }
}

void mujocoError(const char* msg) {
  // MuJoCo's default handler exits the process; a C++ exception at least names the problem.
  throw std::runtime_error(std::string("MuJoCo error: ") + msg);
}

struct ActiveSimGuard {
  ActiveSimGuard(const WorkcellSim* sim, LogSink* sink) {
    g_active_sim = sim;
    g_active_sink = sink;
  }
  ~ActiveSimGuard() {
    g_active_sim = nullptr;
    g_active_sink = nullptr;
  }
};

bool allFinite(const mjtNum* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// The readings noise of a sensor's kind; nullptr = read exactly (a frame orientation, ...).
const double SensorNoise::*noiseOfKind(int type) {
  switch (type) {
    case mjSENS_FORCE:
      return &SensorNoise::force;
    case mjSENS_TORQUE:
      return &SensorNoise::torque;
    case mjSENS_TOUCH:
      return &SensorNoise::touch;
    case mjSENS_GYRO:
      return &SensorNoise::gyro;
    case mjSENS_ACCELEROMETER:
      return &SensorNoise::accel;
    default:
      return nullptr;
  }
}

std::string sensorNames(const mjModel* m) {
  std::string names;
  for (int i = 0; i < m->nsensor; ++i) {
    const char* name = mj_id2name(m, mjOBJ_SENSOR, i);
    names += (names.empty() ? "" : ", ") + std::string(name ? name : "(unnamed)");
  }
  return names.empty() ? "none" : names;
}

std::string jointName(const mjModel* m, int joint) {
  const char* name = mj_id2name(m, mjOBJ_JOINT, joint);
  return name ? name : "joint" + std::to_string(joint);
}

// Small random rotation (rotation vector with the given std per axis) applied to q (w,x,y,z).
void perturbQuaternion(std::array<double, 4>* q, const std::array<double, 3>& rotvec) {
  mjtNum dq[4], rv[3] = {rotvec[0], rotvec[1], rotvec[2]}, res[4];
  const mjtNum angle = mju_normalize3(rv);
  mju_axisAngle2Quat(dq, rv, angle);
  mjtNum src[4] = {(*q)[0], (*q)[1], (*q)[2], (*q)[3]};
  mju_mulQuat(res, src, dq);
  mju_normalize4(res);
  for (int i = 0; i < 4; ++i) (*q)[i] = res[i];
}

// Makes actuator u a pure P term: force = kp * (ctrl - q). Damping, gravity and velocity
// feed-forward are handled in computeControls() and by implicit joint damping.
void makeProportionalActuator(mjModel* m, int u, double kp) {
  m->actuator_dyntype[u] = mjDYN_NONE;
  m->actuator_gaintype[u] = mjGAIN_FIXED;
  m->actuator_biastype[u] = mjBIAS_AFFINE;
  mju_zero(m->actuator_gainprm + mjNGAIN * u, mjNGAIN);
  mju_zero(m->actuator_biasprm + mjNBIAS * u, mjNBIAS);
  m->actuator_gainprm[mjNGAIN * u] = kp;
  m->actuator_biasprm[mjNBIAS * u + 1] = -kp;
  m->actuator_ctrllimited[u] = 0;  // targets are clamped to joint limits before ctrl
}

}  // namespace

WorkcellSim::WorkcellSim(const std::string& mjcf_path, const WorkcellConfig& config, LogSink log)
    : config_(config), log_(std::move(log)), rng_(config.noise_seed) {
  mju_user_warning = mujocoWarning;
  mju_user_error = mujocoError;
  loadModel(mjcf_path);
  try {
    configureFromModel();
  } catch (...) {  // the destructor does not run for a constructor that throws
    releaseModel();
    throw;
  }
}

void WorkcellSim::loadModel(const std::string& mjcf_path) {
  char error[1024] = "";
  m_ = mj_loadXML(mjcf_path.c_str(), nullptr, error, sizeof(error));
  if (!m_) {
    throw std::runtime_error("cannot load MJCF '" + mjcf_path +
                             "': " + (error[0] ? error : "unknown MuJoCo error"));
  }
  if (error[0]) log(LogLevel::kWarn, std::string("MJCF load warning: ") + error);
  d_ = mj_makeData(m_);
  if (!d_) {
    releaseModel();
    throw std::runtime_error("MuJoCo could not allocate data for '" + mjcf_path + "'");
  }
  if (m_->opt.integrator == mjINT_RK4) {
    // mj_step1/mj_step2 (needed to compute controls from fresh kinematics) fall back to Euler.
    log(LogLevel::kWarn, "model asks for RK4; the split step integrates with Euler");
  }
}

void WorkcellSim::releaseModel() {
  if (d_) mj_deleteData(d_);
  if (m_) mj_deleteModel(m_);
  d_ = nullptr;
  m_ = nullptr;
}

// Everything the constructor derives from the loaded model: joints, actuators, the base, the
// configured names checked against the model, sensors, objects, and the initial scene.
void WorkcellSim::configureFromModel() {
  for (int j = 0; j < m_->njnt; ++j) {
    if (m_->jnt_type[j] == mjJNT_HINGE || m_->jnt_type[j] == mjJNT_SLIDE) {
      joint_names_.push_back(jointName(m_, j));
      joint_ids_.push_back(j);
    }
  }
  configureActuators();

  findBaseBody();
  // A joint belongs to the robot when its body hangs from the same world child as base_link;
  // any other (the drawer's slide) is a scene object's.
  for (int j : joint_ids_)
    object_joint_.push_back(m_->body_rootid[m_->jnt_bodyid[j]] != m_->body_rootid[base_body_]);
  ee_site_ = mj_name2id(m_, mjOBJ_SITE, config_.ee_site.c_str());
  gripper_ = actuatedIndex(config_.gripper_joint);
  checkRobotNames();
  configureSensors();

  for (const std::string& name : config_.objects) {
    const int body = mj_name2id(m_, mjOBJ_BODY, name.c_str());
    if (body <= 0) {
      log(LogLevel::kWarn, "no body '" + name + "'; it will not be reported");
      continue;
    }
    objects_.emplace_back(name, body);
  }

  setNoise(config_.noise, config_.noise_seed);

  recordInitialScene();
  reset({}, true);
}

void WorkcellSim::findBaseBody() {
  base_body_ =
      config_.base_body.empty() ? -1 : mj_name2id(m_, mjOBJ_BODY, config_.base_body.c_str());
  if (base_body_ < 0) {
    // Fall back to the robot's root: the first child of the world that is not a free object.
    for (int b = 1; b < m_->nbody && base_body_ < 0; ++b) {
      if (m_->body_parentid[b] == 0 && m_->body_jntnum[b] > 0 &&
          m_->jnt_type[m_->body_jntadr[b]] != mjJNT_FREE) {
        base_body_ = b;
      }
    }
    if (base_body_ < 0) base_body_ = 0;
    if (!config_.base_body.empty())
      log(LogLevel::kWarn, "no body '" + config_.base_body + "'; using body '" +
                               mj_id2name(m_, mjOBJ_BODY, base_body_) + "' as the base");
  }
}

// The model's object poses (free joints in qpos0, fixed objects as mocap bodies): what reset and
// divergence recovery put back.
void WorkcellSim::recordInitialScene() {
  initial_qpos_.assign(m_->qpos0, m_->qpos0 + m_->nq);
  scene_qpos_ = initial_qpos_;
  scene_mocap_.assign(7 * m_->nmocap, 0.0);
  for (int b = 0; b < m_->nbody; ++b) {
    const int id = m_->body_mocapid[b];
    if (id < 0) continue;
    std::copy(m_->body_pos + 3 * b, m_->body_pos + 3 * b + 3, scene_mocap_.begin() + 7 * id);
    std::copy(m_->body_quat + 4 * b, m_->body_quat + 4 * b + 4, scene_mocap_.begin() + 7 * id + 3);
  }
}

// The robot file describes this model: a name it gives that the model lacks is a robot file for
// another robot (or a typo), which would record demos with an idle gripper or a wrong posture.
void WorkcellSim::checkRobotNames() const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("the robot file does not match the model: " + what);
  };
  if (ee_site_ < 0 && !config_.ee_site.empty())
    fail("no site or frame '" + config_.ee_site + "' (the IK tip link)");
  if (gripper_ < 0 && !config_.gripper_joint.empty())
    fail("no actuated gripper joint '" + config_.gripper_joint + "'");
  for (const auto& [name, value] : config_.initial_posture)
    if (!hasJoint(name)) fail("initial_posture names joint '" + name + "', which it does not have");
}

WorkcellSim::~WorkcellSim() {
  releaseModel();
}

void WorkcellSim::configureActuators() {
  for (int u = 0; u < m_->nu; ++u) {
    const int trn = m_->actuator_trntype[u];
    const int joint = m_->actuator_trnid[2 * u];
    if ((trn != mjTRN_JOINT && trn != mjTRN_JOINTINPARENT) || joint < 0 ||
        (m_->jnt_type[joint] != mjJNT_HINGE && m_->jnt_type[joint] != mjJNT_SLIDE)) {
      log(LogLevel::kWarn, "actuator " + std::to_string(u) +
                               " does not drive one hinge/slide "
                               "joint; left to the model");
      continue;
    }
    Actuated a;
    a.name = jointName(m_, joint);
    a.joint = joint;
    a.qpos_adr = m_->jnt_qposadr[joint];
    a.dof_adr = m_->jnt_dofadr[joint];
    a.actuator = u;
    if (std::abs(m_->actuator_gear[6 * u] - 1.0) > 1e-12) {
      log(LogLevel::kWarn, "actuator of " + a.name + " has gear != 1; forcing 1");
      m_->actuator_gear[6 * u] = 1.0;
    }
    configureGains(a);
    configureLimits(a);

    actuated_index_[a.name] = static_cast<int>(actuated_.size());
    actuated_names_.push_back(a.name);
    actuated_.push_back(a);
  }
  for (const auto& [name, value] : config_.kp) {
    if (!actuated_index_.count(name)) log(LogLevel::kWarn, "kp for unknown joint '" + name + "'");
  }
}

// Proportional gain: config, else the MJCF position actuator's, else the default; the damping
// reaches config's kd or damping_ratio (raised only: the model's own damping stays a floor).
void WorkcellSim::configureGains(Actuated& a) {
  const int u = a.actuator;
  const bool is_position_actuator = m_->actuator_gaintype[u] == mjGAIN_FIXED &&
                                    m_->actuator_biastype[u] == mjBIAS_AFFINE &&
                                    m_->actuator_biasprm[mjNBIAS * u + 1] < 0.0;
  auto kp_it = config_.kp.find(a.name);
  a.kp = kp_it != config_.kp.end() ? kp_it->second
         : is_position_actuator    ? m_->actuator_gainprm[mjNGAIN * u]
                                   : config_.default_kp;
  if (!(a.kp > 0.0)) throw std::invalid_argument("joint " + a.name + " has a non-positive kp");
  makeProportionalActuator(m_, u, a.kp);

  // Damping: raise joint damping to the requested value (implicit in MuJoCo's integrators).
  const double inertia =
      m_->dof_invweight0[a.dof_adr] > 0 ? 1.0 / m_->dof_invweight0[a.dof_adr] : 1.0;
  auto kd_it = config_.kd.find(a.name);
  const double kd = kd_it != config_.kd.end()
                        ? kd_it->second
                        : config_.damping_ratio * 2.0 * std::sqrt(a.kp * inertia);
  m_->dof_damping[a.dof_adr] = std::max(m_->dof_damping[a.dof_adr], kd);
  a.kd = m_->dof_damping[a.dof_adr];
}

// Position limits from the model; velocity and effort limits from config, else the model's force
// range (effort), else the defaults. The actuator's force range becomes the effort cap.
void WorkcellSim::configureLimits(Actuated& a) {
  const int u = a.actuator, joint = a.joint;
  if (m_->jnt_limited[joint]) {
    a.limit.position_limited = true;
    a.limit.lower = m_->jnt_range[2 * joint];
    a.limit.upper = m_->jnt_range[2 * joint + 1];
  }
  auto v_it = config_.velocity_limits.find(a.name);
  a.velocity_from_config = v_it != config_.velocity_limits.end();
  a.limit.velocity = a.velocity_from_config ? v_it->second : config_.default_velocity_limit;
  auto e_it = config_.effort_limits.find(a.name);
  a.effort_from_config = e_it != config_.effort_limits.end();
  if (a.effort_from_config) {
    a.limit.effort = e_it->second;
  } else if (m_->actuator_forcelimited[u]) {
    a.limit.effort = std::max(std::abs(m_->actuator_forcerange[2 * u]),
                              std::abs(m_->actuator_forcerange[2 * u + 1]));
  } else {
    a.limit.effort = config_.default_effort_limit;
  }
  if (!(a.limit.velocity > 0.0) || !(a.limit.effort > 0.0)) {
    throw std::invalid_argument("joint " + a.name + " needs positive velocity/effort limits");
  }
  a.effort_cap = a.limit.effort;
  m_->actuator_forcelimited[u] = 1;
  m_->actuator_forcerange[2 * u] = -a.effort_cap;
  m_->actuator_forcerange[2 * u + 1] = a.effort_cap;
}

void WorkcellSim::applyUrdfLimits(const std::string& urdf_xml) {
  urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(urdf_xml);
  if (!urdf) throw std::invalid_argument("robot description is not a valid URDF");
  int applied = 0;
  for (Actuated& a : actuated_) {
    auto it = urdf->joints_.find(a.name);
    if (it == urdf->joints_.end() || !it->second || !it->second->limits) continue;
    const urdf::JointLimits& lim = *it->second->limits;
    if (!a.velocity_from_config && lim.velocity > 0) a.limit.velocity = lim.velocity;
    if (!a.effort_from_config && lim.effort > 0) {
      a.limit.effort = lim.effort;
      a.effort_cap = lim.effort;
      m_->actuator_forcerange[2 * a.actuator] = -a.effort_cap;
      m_->actuator_forcerange[2 * a.actuator + 1] = a.effort_cap;
    }
    ++applied;
  }
  log(LogLevel::kInfo, "URDF limits applied to " + std::to_string(applied) + " of " +
                           std::to_string(actuated_.size()) + " actuated joints");
}

int WorkcellSim::actuatedIndex(const std::string& name) const {
  auto it = actuated_index_.find(name);
  return it == actuated_index_.end() ? -1 : it->second;
}

bool WorkcellSim::hasJoint(const std::string& name) const {
  return std::find(joint_names_.begin(), joint_names_.end(), name) != joint_names_.end();
}

double WorkcellSim::clampTarget(Actuated& a, double target) {
  if (!a.limit.position_limited) return target;
  if (target >= a.limit.lower && target <= a.limit.upper) return target;
  if (!a.warned_out_of_range) {
    a.warned_out_of_range = true;
    std::ostringstream s;
    s << "target " << target << " for joint " << a.name << " is outside [" << a.limit.lower << ", "
      << a.limit.upper << "]; clamping (warned once per joint)";
    log(LogLevel::kWarn, s.str());
  }
  return std::clamp(target, a.limit.lower, a.limit.upper);
}

void WorkcellSim::setJointTargets(const std::vector<std::string>& names,
                                  const std::vector<double>& positions) {
  if (names.size() != positions.size()) {
    throw std::invalid_argument("joint command has " + std::to_string(names.size()) +
                                " names but " + std::to_string(positions.size()) + " positions");
  }
  if (names.empty()) throw std::invalid_argument("joint command is empty");
  std::vector<int> index(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    index[i] = actuatedIndex(names[i]);
    if (index[i] < 0) throw std::invalid_argument("unknown or unactuated joint '" + names[i] + "'");
    if (!std::isfinite(positions[i])) {
      throw std::invalid_argument("non-finite target for joint '" + names[i] + "'");
    }
  }
  trajectory_.reset();
  for (size_t i = 0; i < names.size(); ++i) {
    Actuated& a = actuated_[index[i]];
    a.desired = clampTarget(a, positions[i]);
  }
}

// Regression: velocities of 1.7e308, clamped to the limit, still made the Hermite segments
// overshoot both waypoints of a 0.1 rad move by 0.6 rad, with nothing logged (the clamp warned once
// per joint). A waypoint velocity beyond the joint's limit is a wrong trajectory: refused whole.
void WorkcellSim::checkTrajectoryVelocities(const JointTrajectory& trajectory,
                                            const std::vector<int>& index) const {
  for (size_t k = 0; k < trajectory.points.size(); ++k) {
    const std::vector<double>& v = trajectory.points[k].velocities;
    for (size_t j = 0; j < v.size(); ++j) {
      const Actuated& a = actuated_[index[j]];
      if (std::abs(v[j]) <= a.limit.velocity) continue;
      std::ostringstream msg;
      msg << "trajectory point " << k << ", joint " << a.name << ": velocity " << v[j]
          << " is beyond the joint's limit of " << a.limit.velocity
          << " (rad/s or m/s: ~velocity_limits, else the URDF's <limit velocity>, else "
             "~default_velocity_limit); the trajectory is refused";
      throw std::invalid_argument(msg.str());
    }
  }
}

void WorkcellSim::setTrajectory(const JointTrajectory& trajectory, double start_time) {
  validateTrajectory(trajectory);
  if (trajectory_ && start_time > 0.0 && start_time == last_trajectory_stamp_ &&
      trajectory == last_trajectory_) {
    return;  // a resent copy of the running trajectory
  }
  std::vector<int> index(trajectory.joint_names.size());
  std::vector<double> start(index.size());
  for (size_t j = 0; j < index.size(); ++j) {
    index[j] = actuatedIndex(trajectory.joint_names[j]);
    if (index[j] < 0) {
      throw std::invalid_argument("unknown or unactuated joint '" + trajectory.joint_names[j] +
                                  "' in trajectory");
    }
    start[j] = actuated_[index[j]].command;
  }
  checkTrajectoryVelocities(trajectory, index);
  const double t0 = std::max(start_time, d_->time);
  trajectory_ = std::make_unique<TrajectoryInterpolator>(trajectory, t0, start);
  trajectory_to_actuated_ = index;
  last_trajectory_ = trajectory;
  last_trajectory_stamp_ = start_time;
  // Warn now (once per joint) about waypoints beyond the limits; samples are clamped each step.
  for (const TrajectoryPoint& p : trajectory.points) {
    for (size_t j = 0; j < index.size(); ++j) clampTarget(actuated_[index[j]], p.positions[j]);
  }
}

void WorkcellSim::setGripper(double opening, double max_effort) {
  if (gripper_ < 0) throw std::invalid_argument("the model has no gripper joint");
  if (!std::isfinite(opening) || !std::isfinite(max_effort)) {
    throw std::invalid_argument("gripper command has a non-finite value");
  }
  Actuated& a = actuated_[gripper_];
  // The gripper command wins over any running trajectory channel of the gripper joint.
  for (int& i : trajectory_to_actuated_) {
    if (i == gripper_) i = -1;
  }
  a.desired = clampTarget(a, opening / config_.gripper_opening_scale);
  a.effort_cap = max_effort > 0.0 ? std::min(max_effort, a.limit.effort) : a.limit.effort;
  applyGripperEffort();
}

// The commanded force limit, times the grip a fault left (1 without one).
void WorkcellSim::applyGripperEffort() {
  if (gripper_ < 0) return;
  const Actuated& a = actuated_[gripper_];
  m_->actuator_forcerange[2 * a.actuator] = -a.effort_cap * grip_fraction_;
  m_->actuator_forcerange[2 * a.actuator + 1] = a.effort_cap * grip_fraction_;
}

void WorkcellSim::computeControls() {
  const double dt = m_->opt.timestep;
  const double t_next = d_->time + dt;
  if (trajectory_) {
    trajectory_->sample(t_next, &traj_pos_, &traj_vel_);
    for (size_t j = 0; j < trajectory_to_actuated_.size(); ++j) {
      const int i = trajectory_to_actuated_[j];
      if (i < 0) continue;
      Actuated& a = actuated_[i];
      a.desired = a.limit.position_limited ? std::clamp(traj_pos_[j], a.limit.lower, a.limit.upper)
                                           : traj_pos_[j];
    }
  }
  for (Actuated& a : actuated_) {
    const double max_step = a.limit.velocity * dt;
    const double delta = std::clamp(a.desired - a.command, -max_step, max_step);
    a.command += delta;
    a.command_velocity = delta / dt;
    // force = kp (command - q) + kd * v_command + bias(q, qdot) - kd * qdot (joint damping).
    double feed_forward = a.kd * a.command_velocity;
    if (config_.gravity_compensation) feed_forward += d_->qfrc_bias[a.dof_adr];
    double ctrl = a.command + feed_forward / a.kp;
    if (!std::isfinite(ctrl)) ctrl = a.command;
    d_->ctrl[a.actuator] = ctrl;
  }
}

void WorkcellSim::step(int n) {
  ActiveSimGuard guard(this, &log_);
  for (int k = 0; k < n; ++k) {
    const double t_before = d_->time;
    const std::array<int, 4> warnings_before = badNumberWarnings();
    computeControls();
    // Split step: kinematics and velocity-stage sensors stay valid for the new state, so the
    // controls of the next step and readState() see the state the integrator just produced.
    mj_step2(m_, d_);
    mj_step1(m_, d_);
    updateTouch();
    std::string why;
    if (badNumberWarnings() != warnings_before) {
      why = "MuJoCo flagged a bad qpos/qvel/qacc/ctrl (it reset the data)";
    } else if (!(d_->time > t_before)) {
      why = "sim time did not advance";
    } else {
      diverged(&why);
    }
    if (!why.empty()) {
      d_->time = t_before;
      recoverFromDivergence(why);
      d_->time = t_before + m_->opt.timestep;
    }
  }
}

WorkcellSim::SensorSlot WorkcellSim::sensorSlot(const std::string& group,
                                                const std::string& sensor) {
  const int id = mj_name2id(m_, mjOBJ_SENSOR, sensor.c_str());
  if (id < 0)
    throw std::invalid_argument(
        "sensor table row " + group + " names sensor '" + sensor +
        "', which the model does not have (its sensors: " + sensorNames(m_) + ")");
  SensorSlot slot;
  slot.adr = m_->sensor_adr[id];
  slot.dim = m_->sensor_dim[id];
  slot.noise = noiseOfKind(m_->sensor_type[id]);
  if (m_->sensor_type[id] == mjSENS_TOUCH) {
    slot.touch_slot = static_cast<int>(touch_adr_.size());
    touch_adr_.push_back(slot.adr);
  }
  return slot;
}

// Every sensor the groups name, looked up once: a missing one is an error naming it.
void WorkcellSim::configureSensors() {
  for (const SensorGroup& group : config_.sensors) {
    std::vector<SensorSlot> slots;
    for (const std::string& sensor : group.sensors) slots.push_back(sensorSlot(group.name, sensor));
    sensor_slots_.push_back(std::move(slots));
  }
  touch_filtered_.assign(touch_adr_.size(), 0.0);
}

int WorkcellSim::sensorDimension(const std::string& sensor) const {
  const int id = mj_name2id(m_, mjOBJ_SENSOR, sensor.c_str());
  if (id < 0)
    throw std::invalid_argument("the model has no sensor '" + sensor +
                                "' (its sensors: " + sensorNames(m_) + ")");
  return m_->sensor_dim[id];
}

void WorkcellSim::updateTouch() {
  const double tau = config_.touch_time_constant;
  const double alpha = tau > 0.0 ? 1.0 - std::exp(-m_->opt.timestep / tau) : 1.0;
  for (size_t i = 0; i < touch_adr_.size(); ++i)
    touch_filtered_[i] += alpha * (d_->sensordata[touch_adr_[i]] - touch_filtered_[i]);
}

// Group by group, sensor by sensor: the order the noise is drawn in. A touch sensor reports its
// filtered normal force, which noise must not make negative.
void WorkcellSim::readSensors(WorkcellState* s) {
  s->sensors.resize(config_.sensors.size());
  for (size_t g = 0; g < config_.sensors.size(); ++g) {
    SensorReading& r = s->sensors[g];
    r.name = config_.sensors[g].name;
    r.sensors = config_.sensors[g].sensors;
    r.values.resize(sensor_slots_[g].size());
    for (size_t k = 0; k < sensor_slots_[g].size(); ++k) {
      const SensorSlot& slot = sensor_slots_[g][k];
      const double std = slot.noise ? config_.noise.*slot.noise : 0.0;
      std::vector<double>& v = r.values[k];
      v.resize(slot.dim);
      for (int i = 0; i < slot.dim; ++i) {
        if (slot.touch_slot >= 0) {
          v[i] = std::max(0.0, touch_filtered_[slot.touch_slot] + noise(std));
        } else {
          v[i] = d_->sensordata[slot.adr + i] + (noisy_ ? noise(std) : 0.0);
        }
      }
    }
    const auto frozen = frozen_readings_.find(g);
    if (frozen != frozen_readings_.end()) r.values = frozen->second;
  }
}

const SensorReading* WorkcellState::sensor(const std::string& group) const {
  for (const SensorReading& r : sensors)
    if (r.name == group) return &r;
  return nullptr;
}

std::array<int, 4> WorkcellSim::badNumberWarnings() const {
  return {d_->warning[mjWARN_BADQPOS].number, d_->warning[mjWARN_BADQVEL].number,
          d_->warning[mjWARN_BADQACC].number, d_->warning[mjWARN_BADCTRL].number};
}

bool WorkcellSim::diverged(std::string* why) const {
  if (!allFinite(d_->qpos, m_->nq)) {
    *why = "non-finite qpos";
  } else if (!allFinite(d_->qvel, m_->nv)) {
    *why = "non-finite qvel";
  } else if (!allFinite(d_->qacc, m_->nv)) {
    *why = "non-finite qacc";
  } else {
    for (int i = 0; i < m_->nv; ++i) {
      if (std::abs(d_->qvel[i]) > config_.max_abs_velocity) {
        *why = "|qvel| of dof " + std::to_string(i) + " = " +
               std::to_string(std::abs(d_->qvel[i])) + " exceeds " +
               std::to_string(config_.max_abs_velocity);
        break;
      }
    }
  }
  return !why->empty();
}

void WorkcellSim::recoverFromDivergence(const std::string& why) {
  ++divergence_count_;
  std::ostringstream s;
  s << "simulation diverged at t=" << d_->time << " s (" << why
    << "); resetting robot to the initial posture and objects to their scene poses (divergence #"
    << divergence_count_ << ")";
  log(LogLevel::kError, s.str());
  const double t = d_->time;
  mj_resetData(m_, d_);
  touch_filtered_.assign(touch_adr_.size(), 0.0);
  for (const auto& [name, body] : objects_) {
    const int jnt = freeJointOf(body);
    if (jnt < 0) continue;
    const int adr = m_->jnt_qposadr[jnt];
    std::copy(scene_qpos_.begin() + adr, scene_qpos_.begin() + adr + 7, d_->qpos + adr);
  }
  restoreMocap();
  applyPosture({});
  d_->time = t;
  mj_forward(m_, d_);
}

void WorkcellSim::applyPosture(const std::map<std::string, double>& posture) {
  auto value_for = [&](const std::string& name, double fallback) {
    auto it = posture.find(name);
    if (it != posture.end()) return it->second;
    it = config_.initial_posture.find(name);
    return it != config_.initial_posture.end() ? it->second : fallback;
  };
  for (size_t k = 0; k < joint_ids_.size(); ++k) {
    const int j = joint_ids_[k];
    const int adr = m_->jnt_qposadr[j];
    d_->qpos[adr] = value_for(joint_names_[k], m_->qpos0[adr]);
    d_->qvel[m_->jnt_dofadr[j]] = 0.0;
  }
  trajectory_.reset();
  for (Actuated& a : actuated_) {
    double q = d_->qpos[a.qpos_adr];
    if (a.limit.position_limited) q = std::clamp(q, a.limit.lower, a.limit.upper);
    d_->qpos[a.qpos_adr] = q;
    a.desired = a.command = q;
    a.command_velocity = 0.0;
    a.effort_cap = a.limit.effort;
    m_->actuator_forcerange[2 * a.actuator] = -a.effort_cap;
    m_->actuator_forcerange[2 * a.actuator + 1] = a.effort_cap;
  }
}

void WorkcellSim::reset(const std::map<std::string, double>& posture, bool reset_objects) {
  for (const auto& [name, value] : posture) {
    if (!hasJoint(name)) throw std::invalid_argument("reset names unknown joint '" + name + "'");
    if (!std::isfinite(value)) {
      throw std::invalid_argument("reset has a non-finite position for '" + name + "'");
    }
  }
  const double t = d_->time;
  std::vector<mjtNum> qpos(d_->qpos, d_->qpos + m_->nq), qvel(d_->qvel, d_->qvel + m_->nv);
  mj_resetData(m_, d_);  // fixed (mocap) objects back at their model poses
  touch_filtered_.assign(touch_adr_.size(), 0.0);
  if (reset_objects) {
    for (int b = 0; b < m_->nbody; ++b) {
      const int id = m_->body_mocapid[b];
      if (id < 0) continue;
      std::copy(d_->mocap_pos + 3 * id, d_->mocap_pos + 3 * id + 3, scene_mocap_.begin() + 7 * id);
      std::copy(d_->mocap_quat + 4 * id, d_->mocap_quat + 4 * id + 4,
                scene_mocap_.begin() + 7 * id + 3);
    }
  } else {
    restoreMocap();
  }
  for (const auto& [name, body] : objects_) {
    const int jnt = freeJointOf(body);
    if (jnt < 0) continue;
    const int qadr = m_->jnt_qposadr[jnt], vadr = m_->jnt_dofadr[jnt];
    if (reset_objects) {
      std::copy(initial_qpos_.begin() + qadr, initial_qpos_.begin() + qadr + 7, d_->qpos + qadr);
      std::copy(initial_qpos_.begin() + qadr, initial_qpos_.begin() + qadr + 7,
                scene_qpos_.begin() + qadr);
    } else {
      std::copy(qpos.begin() + qadr, qpos.begin() + qadr + 7, d_->qpos + qadr);
      std::copy(qvel.begin() + vadr, qvel.begin() + vadr + 6, d_->qvel + vadr);
    }
  }
  applyPosture(posture);
  clearFaults();
  d_->time = t;
  ActiveSimGuard guard(this, &log_);
  mj_forward(m_, d_);
}

int WorkcellSim::freeJointOf(int body) const {
  const int jnt = m_->body_jntadr[body];
  return m_->body_jntnum[body] >= 1 && m_->jnt_type[jnt] == mjJNT_FREE ? jnt : -1;
}

void WorkcellSim::restoreMocap() {
  for (int id = 0; id < m_->nmocap; ++id) {
    std::copy(scene_mocap_.begin() + 7 * id, scene_mocap_.begin() + 7 * id + 3,
              d_->mocap_pos + 3 * id);
    std::copy(scene_mocap_.begin() + 7 * id + 3, scene_mocap_.begin() + 7 * id + 7,
              d_->mocap_quat + 4 * id);
  }
}

void WorkcellSim::checkObjectPose(const std::string& object, const Pose& pose) const {
  const auto it = std::find_if(objects_.begin(), objects_.end(),
                               [&](const auto& o) { return o.first == object; });
  if (it == objects_.end())
    throw std::invalid_argument("unknown object '" + object.substr(0, 64) +
                                (object.size() > 64 ? "...'" : "'"));
  if (freeJointOf(it->second) < 0 && m_->body_mocapid[it->second] < 0)
    throw std::invalid_argument("object '" + object +
                                "' is part of an articulated object and moves with its joint; "
                                "it cannot be placed");
  for (int i = 0; i < 3; ++i) {
    const double v = pose.position[i];
    if (!std::isfinite(v)) throw std::invalid_argument("non-finite position for " + object);
    if (v < config_.workspace_min[i] || v > config_.workspace_max[i]) {
      std::ostringstream msg;
      msg << "position of " << object << " ("
          << "xyz"[i] << " = " << v << " m) is outside the workspace [" << config_.workspace_min[i]
          << ", " << config_.workspace_max[i] << "] m (workspace_min / workspace_max)";
      throw std::invalid_argument(msg.str());
    }
  }
  const auto& q = pose.orientation;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= config_.quaternion_tolerance)) {
    std::ostringstream msg;
    msg << "orientation of " << object << " has norm " << norm << ", not a unit quaternion within "
        << config_.quaternion_tolerance << " (quaternion_tolerance)";
    throw std::invalid_argument(msg.str());
  }
}

void WorkcellSim::setObjectPose(const std::string& object, const Pose& pose) {
  checkObjectPose(object, pose);
  auto it = std::find_if(objects_.begin(), objects_.end(),
                         [&](const auto& o) { return o.first == object; });
  mjtNum quat[4] = {pose.orientation[0], pose.orientation[1], pose.orientation[2],
                    pose.orientation[3]};
  mju_scl(quat, quat, 1.0 / std::sqrt(mju_dot(quat, quat, 4)), 4);
  ActiveSimGuard guard(this, &log_);
  const int mocap = m_->body_mocapid[it->second];
  if (mocap >= 0) {  // a fixed object: placed, never moved by contact
    for (int i = 0; i < 3; ++i) d_->mocap_pos[3 * mocap + i] = pose.position[i];
    for (int i = 0; i < 4; ++i) d_->mocap_quat[4 * mocap + i] = quat[i];
    std::copy(d_->mocap_pos + 3 * mocap, d_->mocap_pos + 3 * mocap + 3,
              scene_mocap_.begin() + 7 * mocap);
    std::copy(quat, quat + 4, scene_mocap_.begin() + 7 * mocap + 3);
    mj_forward(m_, d_);
    return;
  }
  const int jnt = freeJointOf(it->second);
  const int qadr = m_->jnt_qposadr[jnt], vadr = m_->jnt_dofadr[jnt];
  for (int i = 0; i < 3; ++i) d_->qpos[qadr + i] = pose.position[i];
  for (int i = 0; i < 4; ++i) d_->qpos[qadr + 3 + i] = quat[i];
  mju_zero(d_->qvel + vadr, 6);
  std::copy(d_->qpos + qadr, d_->qpos + qadr + 7, scene_qpos_.begin() + qadr);
  mj_forward(m_, d_);
}

double WorkcellSim::time() const {
  return d_->time;
}
double WorkcellSim::timestep() const {
  return m_->opt.timestep;
}

Pose WorkcellSim::bodyPose(int body) const {
  Pose p;
  for (int i = 0; i < 3; ++i) p.position[i] = d_->xpos[3 * body + i];
  for (int i = 0; i < 4; ++i) p.orientation[i] = d_->xquat[4 * body + i];
  return p;
}

Pose WorkcellSim::basePoseInWorld() const {
  return bodyPose(base_body_);
}

void WorkcellSim::setNoise(const SensorNoise& noise, uint64_t seed) {
  config_.noise = noise;
  config_.noise_seed = seed;
  rng_.seed(seed);
  const SensorNoise& n = config_.noise;
  noisy_ = n.joint_position > 0 || n.joint_velocity > 0 || n.joint_effort > 0 || n.force > 0 ||
           n.torque > 0 || n.touch > 0 || n.gyro > 0 || n.accel > 0 || n.ee_position > 0 ||
           n.ee_orientation > 0 || n.gripper > 0 || n.object_position > 0;
}

double WorkcellSim::noise(double std) {
  if (!(std > 0.0)) return 0.0;
  return std::normal_distribution<double>(0.0, std)(rng_);
}

WorkcellState WorkcellSim::readState() {
  WorkcellState s;
  readState(&s);
  return s;
}

void WorkcellSim::readState(WorkcellState* s) {
  const SensorNoise& n = config_.noise;
  s->time = d_->time;
  const size_t nj = joint_ids_.size();
  s->joint_names = joint_names_;
  s->object_joint = object_joint_;
  s->joint_positions.resize(nj);
  s->joint_velocities.resize(nj);
  s->joint_efforts.resize(nj);
  for (size_t k = 0; k < nj; ++k) {
    const int j = joint_ids_[k];
    const int dof = m_->jnt_dofadr[j];
    s->joint_positions[k] = d_->qpos[m_->jnt_qposadr[j]];
    s->joint_velocities[k] = d_->qvel[dof];
    s->joint_efforts[k] = d_->qfrc_actuator[dof];
    if (noisy_) {
      s->joint_positions[k] += noise(n.joint_position);
      s->joint_velocities[k] += noise(n.joint_velocity);
      s->joint_efforts[k] += noise(n.joint_effort);
    }
  }
  readSensors(s);
  if (gripper_ >= 0) {
    const Actuated& g = actuated_[gripper_];
    s->gripper_opening = config_.gripper_opening_scale * d_->qpos[g.qpos_adr] + noise(n.gripper);
    s->gripper_velocity = config_.gripper_opening_scale * d_->qvel[g.dof_adr];
    s->gripper_effort = d_->actuator_force[g.actuator];
  }

  // End effector in the base body: p = R_b^T (p_s - p_b), R = R_b^T R_s; the base is fixed in the
  // world, so the world-frame site velocity rotated into the base is its velocity there.
  if (ee_site_ >= 0) {
    const mjtNum* Rb = d_->xmat + 9 * base_body_;
    const mjtNum* pb = d_->xpos + 3 * base_body_;
    const mjtNum* Rs = d_->site_xmat + 9 * ee_site_;
    const mjtNum* ps = d_->site_xpos + 3 * ee_site_;
    mjtNum diff[3], p[3], R[9], q[4];
    mju_sub3(diff, ps, pb);
    mju_mulMatTVec(p, Rb, diff, 3, 3);
    mju_mulMatTMat(R, Rb, Rs, 3, 3, 3);
    mju_mat2Quat(q, R);
    for (int i = 0; i < 3; ++i) s->ee_pose.position[i] = p[i] + noise(n.ee_position);
    for (int i = 0; i < 4; ++i) s->ee_pose.orientation[i] = q[i];
    if (noisy_ && n.ee_orientation > 0) {
      perturbQuaternion(&s->ee_pose.orientation, {noise(n.ee_orientation), noise(n.ee_orientation),
                                                  noise(n.ee_orientation)});
    }
    mjtNum vel[6], w[3], v[3];
    mj_objectVelocity(m_, d_, mjOBJ_SITE, ee_site_, vel, 0);  // [angular; linear], world axes
    mju_mulMatTVec(w, Rb, vel, 3, 3);
    mju_mulMatTVec(v, Rb, vel + 3, 3, 3);
    for (int i = 0; i < 3; ++i) {
      s->ee_angular_velocity[i] = w[i];
      s->ee_linear_velocity[i] = v[i];
    }
  }
  s->object_names.resize(objects_.size());
  s->object_poses.resize(objects_.size());
  for (size_t i = 0; i < objects_.size(); ++i) {
    s->object_names[i] = objects_[i].first;
    s->object_poses[i] = bodyPose(objects_[i].second);
    if (noisy_) {
      for (double& x : s->object_poses[i].position) x += noise(n.object_position);
    }
  }
}

JointLimit WorkcellSim::jointLimit(const std::string& name) const {
  const int i = actuatedIndex(name);
  if (i < 0) throw std::invalid_argument("unknown or unactuated joint '" + name + "'");
  return actuated_[i].limit;
}

double WorkcellSim::jointPosition(const std::string& name) const {
  for (size_t k = 0; k < joint_names_.size(); ++k) {
    if (joint_names_[k] == name) return d_->qpos[m_->jnt_qposadr[joint_ids_[k]]];
  }
  throw std::invalid_argument("unknown joint '" + name + "'");
}

double WorkcellSim::jointTarget(const std::string& name) const {
  const int i = actuatedIndex(name);
  if (i < 0) throw std::invalid_argument("unknown or unactuated joint '" + name + "'");
  return actuated_[i].command;
}

double WorkcellSim::actuatorForce(const std::string& name) const {
  const int i = actuatedIndex(name);
  if (i < 0) throw std::invalid_argument("unknown or unactuated joint '" + name + "'");
  return d_->actuator_force[actuated_[i].actuator];
}

bool WorkcellSim::trajectoryActive() const {
  // Half a step of slack: sim time accumulates rounding over thousands of steps.
  return trajectory_ && d_->time < trajectory_->endTime() - 0.5 * m_->opt.timestep;
}

double WorkcellSim::trajectoryEndTime() const {
  return trajectory_ ? trajectory_->endTime() : 0.0;
}

void WorkcellSim::injectNaNForTest() {
  if (m_->nv > 0) d_->qvel[0] = std::numeric_limits<double>::quiet_NaN();
}

void WorkcellSim::log(LogLevel level, const std::string& text) const {
  if (log_) {
    log_(level, text);
  } else {
    std::fprintf(stderr, "[lfd_sim %s] %s\n",
                 level == LogLevel::kError  ? "ERROR"
                 : level == LogLevel::kWarn ? "WARN"
                                            : "INFO",
                 text.c_str());
  }
}

}  // namespace lfd_sim
