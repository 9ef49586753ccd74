#include "lfd_core/robot_setup.hpp"
#include "lfd_core/safe_paths.hpp"

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

void readGripper(const YAML::Node& g, const std::string& path, GripperSetup* gripper) {
  if (!g) return;
  if (!g.IsMap()) fail(path, "gripper must be a mapping");
  if (g["joint"]) gripper->joint = g["joint"].as<std::string>();
  if (g["open_opening"]) gripper->open_opening = g["open_opening"].as<double>();
  if (g["close_opening"]) gripper->close_opening = g["close_opening"].as<double>();
  if (g["close_effort"])
    gripper->close_effort = positiveNumber(g["close_effort"], path, "gripper.close_effort");
  if (!std::isfinite(gripper->open_opening) || !std::isfinite(gripper->close_opening) ||
      gripper->open_opening < gripper->close_opening)
    fail(path, "gripper.open_opening must be finite and >= close_opening");
}

}  // namespace

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
    readIk(root["ik"], path, &setup);
    readGripper(root["gripper"], path, &setup.gripper);
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
  const std::string& frame =
      setup.cartesian_frame.empty() ? setup.base_link : setup.cartesian_frame;
  if (frame != setup.base_link) {
    // The chain root's pose in the Cartesian frame, with every joint between them at zero.
    const KinematicChain to_root = KinematicChain::fromUrdfString(urdf_xml, frame, setup.base_link);
    chain_base = to_root.forward(Eigen::VectorXd::Zero(to_root.dof()));
  }
  CartesianToJoints converter(chain, chain_base, options, setup.ik_tolerance);
  converter.setPreferredPosture(preferred);
  return converter;
}

}  // namespace lfd
