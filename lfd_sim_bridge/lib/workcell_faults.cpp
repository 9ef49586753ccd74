// Faults injected into the workcell (sim only): what execution monitoring must notice. Each is a
// change of the model a real cell could suffer (a weak gripper, a stuck joint, a frozen sensor);
// reset() undoes them all.
#include <mujoco/mujoco.h>

#include <stdexcept>

#include "lfd_sim_bridge/workcell_sim.hpp"

namespace lfd_sim {

void WorkcellSim::weakenGrip(double fraction) {
  if (gripper_ < 0) throw std::invalid_argument("the model has no gripper joint");
  if (!(fraction >= 0.0 && fraction <= 1.0))
    throw std::invalid_argument("a weakened grip keeps a fraction in [0, 1] of its force, got " +
                                std::to_string(fraction));
  grip_fraction_ = fraction;
  applyGripperEffort();
}

void WorkcellSim::lockJoint(const std::string& joint, double holding_force) {
  const int id = mj_name2id(m_, mjOBJ_JOINT, joint.c_str());
  if (id < 0 || (m_->jnt_type[id] != mjJNT_HINGE && m_->jnt_type[id] != mjJNT_SLIDE))
    throw std::invalid_argument("no hinge or slide joint '" + joint + "' to lock");
  if (!(holding_force > 0.0) || !std::isfinite(holding_force))
    throw std::invalid_argument("a locked joint's holding force must be finite and > 0, got " +
                                std::to_string(holding_force));
  // A damping that lets the joint creep at 1 mm/s (1 mrad/s) under its holding force. MuJoCo's
  // dry friction (frictionloss) is a soft constraint: 1e4 N of it let the drawer slide 34 mm in
  // 0.5 s under a 30 N pull. The Euler integrator treats damping implicitly, so any is stable.
  constexpr double kCreepSpeed = 1e-3;
  const int dof = m_->jnt_dofadr[id];
  locked_dofs_.emplace(dof, m_->dof_damping[dof]);  // the model's own, kept once
  m_->dof_damping[dof] = holding_force / kCreepSpeed;
}

bool WorkcellSim::hasSensorGroup(const std::string& group) const {
  for (const SensorGroup& g : config_.sensors)
    if (g.name == group) return true;
  return false;
}

void WorkcellSim::freezeSensor(const std::string& group) {
  for (std::size_t g = 0; g < config_.sensors.size(); ++g) {
    if (config_.sensors[g].name != group) continue;
    WorkcellState now;
    readSensors(&now);
    frozen_readings_[g] = now.sensors[g].values;
    return;
  }
  std::string rows;
  for (const SensorGroup& g : config_.sensors) rows += (rows.empty() ? "" : ", ") + g.name;
  throw std::invalid_argument("no sensor table row '" + group + "' to freeze (rows: " + rows + ")");
}

void WorkcellSim::clearFaults() {
  grip_fraction_ = 1.0;
  applyGripperEffort();
  for (const auto& [dof, damping] : locked_dofs_) m_->dof_damping[dof] = damping;
  locked_dofs_.clear();
  frozen_readings_.clear();
}

}  // namespace lfd_sim
