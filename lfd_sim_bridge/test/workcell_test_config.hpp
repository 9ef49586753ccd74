// The workcell as the bridge configures it, for the master-free tests of lfd_sim.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/sensor_table.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"

namespace {

const std::string kModel = std::string(LFD_SIM_MODEL_DIR) + "/workcell.xml";
const std::string kRobotFile = LFD_ROBOT_FILE;

// The robot's part as the bridge configures it: from the shipped robot file.
inline lfd_sim::WorkcellConfig robotConfig() {
  const lfd::RobotSetup robot = lfd::loadRobotSetup(kRobotFile);
  lfd_sim::WorkcellConfig c;
  c.gripper_joint = robot.gripper.joint;
  c.base_body = robot.base_link;
  c.ee_site = robot.tip_link;
  c.sensors = lfd_sim::sensorGroups(lfd_sim::bindSensorTable(robot.sensors));
  return c;
}

// Readings of the table row `topic`'s sensor `k` (1-D sensors: its value).
inline const std::vector<double>& reading(const lfd_sim::WorkcellState& s, const std::string& topic,
                                          size_t k) {
  const lfd_sim::SensorReading* r = s.sensor(topic);
  if (!r) throw std::runtime_error("no sensor row " + topic);
  return r->values.at(k);
}

// Arm bent over the table (like the robot file's ready posture), so arm joints move without hitting
// anything.
inline lfd_sim::WorkcellConfig readyConfig() {
  lfd_sim::WorkcellConfig c = robotConfig();
  c.initial_posture = {
      {"R_SHOULDER_P", -0.3}, {"R_ELBOW_P", -1.3}, {"R_WRIST_Y", 1.4}, {"R_GRIPPER", 0.03}};
  return c;
}

}  // namespace
