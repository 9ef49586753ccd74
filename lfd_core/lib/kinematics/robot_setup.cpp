#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_core/io/safe_paths.hpp"

#include <cmath>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace lfd {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("robot file '" + path + "': " + what);
}

double positiveNumber(const YAML::Node& node, const std::string& path, const std::string& key) {
  const double v = node.as<double>();
  if (!(v > 0.0) || !std::isfinite(v)) fail(path, key + " must be a positive number");
  return v;
}

std::map<std::string, double> jointMap(const YAML::Node& node, const std::string& path,
                                       const std::string& key) {
  if (!node) return {};
  if (!node.IsMap()) fail(path, key + " must map joint names to numbers");
  std::map<std::string, double> out;
  for (const auto& entry : node) {
    const double v = entry.second.as<double>();
    if (!std::isfinite(v)) fail(path, key + "." + entry.first.as<std::string>() + " is not finite");
    out[entry.first.as<std::string>()] = v;
  }
  return out;
}

void readIk(const YAML::Node& ik, const std::string& path, RobotSetup* setup) {
  if (!ik || !ik.IsMap()) fail(path, "needs an 'ik:' block (base_link, tip_link)");
  if (!ik["tip_link"]) fail(path, "ik.tip_link is missing");
  if (ik["base_link"]) setup->base_link = ik["base_link"].as<std::string>();
  setup->tip_link = ik["tip_link"].as<std::string>();
  if (ik["cartesian_frame"]) setup->cartesian_frame = ik["cartesian_frame"].as<std::string>();
  setup->joint_costs = jointMap(ik["joint_costs"], path, "ik.joint_costs");
  for (const auto& [joint, cost] : setup->joint_costs)
    if (!(cost > 0.0)) fail(path, "ik.joint_costs." + joint + " must be > 0");
  setup->preferred_posture = jointMap(ik["preferred_posture"], path, "ik.preferred_posture");
  if (const YAML::Node tol = ik["tolerance"]) {
    if (tol["position"])
      setup->ik_tolerance.position = positiveNumber(tol["position"], path, "ik.tolerance.position");
    if (tol["orientation"])
      setup->ik_tolerance.orientation =
          positiveNumber(tol["orientation"], path, "ik.tolerance.orientation");
  }
}

std::string text(const YAML::Node& node, const std::string& path, const std::string& key) {
  if (!node || !node.IsScalar() || node.as<std::string>().empty())
    fail(path, key + " must be a non-empty string");
  return node.as<std::string>();
}

void readGripper(const YAML::Node& g, const std::string& path, GripperSetup* gripper) {
  if (!g) return;
  if (!g.IsMap()) fail(path, "gripper must be a mapping");
  gripper->joint = text(g["joint"], path, "gripper.joint");  // no default: it names the robot's
  if (g["open_opening"]) gripper->open_opening = g["open_opening"].as<double>();
  if (g["close_opening"]) gripper->close_opening = g["close_opening"].as<double>();
  if (g["close_effort"])
    gripper->close_effort = positiveNumber(g["close_effort"], path, "gripper.close_effort");
  if (g["opening_scale"])
    gripper->opening_scale = positiveNumber(g["opening_scale"], path, "gripper.opening_scale");
  if (!std::isfinite(gripper->open_opening) || !std::isfinite(gripper->close_opening) ||
      gripper->open_opening < gripper->close_opening)
    fail(path, "gripper.open_opening must be finite and >= close_opening");
}

// A field's device sensors: one name, or a list of names (e.g. the touch pads).
std::vector<std::string> sensorNames(const YAML::Node& node, const std::string& path,
                                     const std::string& key) {
  if (node.IsScalar()) return {text(node, path, key)};
  if (!node.IsSequence() || node.size() == 0)
    fail(path, key + " must name a sensor or a non-empty list of sensors");
  std::vector<std::string> names;
  for (std::size_t i = 0; i < node.size(); ++i)
    names.push_back(text(node[i], path, key + "[" + std::to_string(i) + "]"));
  return names;
}

SensorEntry readSensor(const YAML::Node& row, const std::string& path, const std::string& key) {
  if (!row.IsMap()) fail(path, key + " must be a mapping (topic, type, frame, fields)");
  for (const auto& item : row) {
    const std::string k = item.first.as<std::string>();
    if (k != "topic" && k != "type" && k != "frame" && k != "fields")
      fail(path, key + " has an unknown key '" + k + "' (topic, type, frame, fields)");
  }
  SensorEntry entry;
  entry.topic = text(row["topic"], path, key + ".topic");
  entry.type = text(row["type"], path, key + ".type");
  entry.frame = text(row["frame"], path, key + ".frame");
  const YAML::Node fields = row["fields"];
  if (!fields || !fields.IsMap() || fields.size() == 0)
    fail(path, key + ".fields must map message fields to device sensors");
  for (const auto& item : fields) {
    const std::string field = item.first.as<std::string>();
    entry.fields.emplace_back(field, sensorNames(item.second, path, key + ".fields." + field));
  }
  return entry;
}

// Each topic once, and each device sensor in one place: a sensor read twice would draw its noise
// twice and publish two different readings of one measurement.
void checkUnique(const std::vector<SensorEntry>& table, const std::string& path) {
  std::map<std::string, std::string> topic_of_sensor;
  std::map<std::string, int> topics;
  for (const SensorEntry& entry : table) {
    if (topics[entry.topic]++) fail(path, "sensors: topic " + entry.topic + " appears twice");
    for (const auto& [field, names] : entry.fields)
      for (const std::string& name : names) {
        auto [it, fresh] = topic_of_sensor.emplace(name, entry.topic);
        if (!fresh)
          fail(path, "sensors: sensor '" + name + "' is read twice (" + it->second + " and " +
                         entry.topic + ")");
      }
  }
}

void readSensors(const YAML::Node& node, const std::string& path, RobotSetup* setup) {
  if (!node) return;
  if (!node.IsSequence()) fail(path, "sensors must be a list of sensor table rows");
  for (std::size_t i = 0; i < node.size(); ++i)
    setup->sensors.push_back(readSensor(node[i], path, "sensors[" + std::to_string(i) + "]"));
  checkUnique(setup->sensors, path);
}

}  // namespace

const SensorEntry* findSensorOfType(const RobotSetup& setup, const std::string& type) {
  for (const SensorEntry& entry : setup.sensors)
    if (entry.type == type) return &entry;
  return nullptr;
}

RobotSetup loadRobotSetup(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(openInputFile(path).readPath());  // opened once: no FIFO swapped in
  } catch (const std::invalid_argument& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  } catch (const YAML::Exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
  RobotSetup setup;
  try {
    if (root["name"]) setup.name = text(root["name"], path, "name");
    readIk(root["ik"], path, &setup);
    readGripper(root["gripper"], path, &setup.gripper);
    setup.initial_posture = jointMap(root["initial_posture"], path, "initial_posture");
    readSensors(root["sensors"], path, &setup);
  } catch (const YAML::Exception& e) {
    fail(path, std::string("invalid value: ") + e.what());
  }
  return setup;
}

CartesianToJoints makeCartesianToJoints(const std::string& urdf_xml, const RobotSetup& setup,
                                        IkOptions options) {
  const KinematicChain chain =
      KinematicChain::fromUrdfString(urdf_xml, setup.base_link, setup.tip_link);
  options.joint_costs = Eigen::VectorXd::Ones(chain.dof());
  Eigen::VectorXd preferred = Eigen::VectorXd::Zero(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    const std::string& joint = chain.jointNames()[i];
    if (setup.joint_costs.count(joint)) options.joint_costs[i] = setup.joint_costs.at(joint);
    if (setup.preferred_posture.count(joint)) preferred[i] = setup.preferred_posture.at(joint);
  }
  Eigen::Isometry3d chain_base = Eigen::Isometry3d::Identity();
  const std::string& frame = setup.poseFrame();
  if (frame != setup.base_link) {
    // The chain root's pose in the Cartesian frame, with every joint between them at zero.
    const KinematicChain to_root = KinematicChain::fromUrdfString(urdf_xml, frame, setup.base_link);
    chain_base = to_root.forward(Eigen::VectorXd::Zero(to_root.dof()));
  }
  CartesianToJoints converter(chain, chain_base, options, setup.ik_tolerance);
  converter.setPreferredPosture(preferred);
  converter.setRobotName(setup.name.empty() ? "the robot" : "robot " + setup.name);
  return converter;
}

}  // namespace lfd
