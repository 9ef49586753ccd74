// The URDF (used by every kinematics consumer) and the MJCF workcell (used by the simulator) are
// generated from one source; this test proves they describe the same robot: same joints, axes,
// limits, actuators and sensors, and the same tool pose for random configurations; that the scene's
// objects and joints are those of config/scene.yaml; that the files are up to date with it; and
// that the scene simulates (the robot holds its ready posture, the gripper closes on nothing).
// Every robot description package is checked the same way (the humanoid jvrc1_description and the
// 7-DoF arm arm7_description): only the names and the expected counts differ.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>
#include <urdf_parser/urdf_parser.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <cstdlib>
#include <fstream>
#include <iterator>

#include "lfd_core/kinematics/kinematic_chain.hpp"
#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/sensor_table.hpp"
#include "lfd_sim_bridge/task_file.hpp"

namespace task = lfd_sim_bridge::task;

namespace {

const std::string kSceneFile = std::string(LFD_CONFIG_DIR) + "/scene.yaml";

// A frame whose pose the URDF chain and the MJCF must agree on (an MJCF site or body).
struct Frame {
  std::string link;
  bool is_site;
};

// One robot description package and what its models must contain.
struct RobotCase {
  std::string name;                    // test name suffix
  std::string dir;                     // the package's folder (models/, config/robot.yaml)
  std::string urdf;                    // URDF file name in models/
  std::string mjcf;                    // the MJCF robot file in models/ (workcell.xml includes it)
  std::string root;                    // the root link (fixed at the mount point)
  size_t movable_joints;               // moving URDF joints
  std::map<std::string, int> sensors;  // MJCF sensor -> type
  std::string ft_site;                 // the wrist force/torque site
  std::string finger;                  // a finger body (hangs from the F/T site's body)
  std::string imu_site;                // "" = no IMU
  double min_mass, max_mass;           // kg, the whole robot
  std::vector<Frame> frames;           // URDF chains from the root checked against MuJoCo

  std::string modelDir() const { return dir + "/models"; }
  std::string urdfPath() const { return modelDir() + "/" + urdf; }
  std::string scenePath() const { return modelDir() + "/workcell.xml"; }
  std::string robotFile() const { return dir + "/config/robot.yaml"; }
};

std::ostream& operator<<(std::ostream& os, const RobotCase& r) {
  return os << r.name;
}

std::vector<RobotCase> robots() {
  RobotCase humanoid;
  humanoid.name = "jvrc1";
  humanoid.dir = LFD_JVRC1_ROBOT_DIR;
  humanoid.urdf = "jvrc1_like.urdf";
  humanoid.mjcf = "jvrc1_like.xml";
  humanoid.root = "base_link";
  humanoid.movable_joints = 34;  // 12 legs + 3 waist + 3 neck + 14 arms + 2 fingers
  humanoid.sensors = {{"r_wrist_force", mjSENS_FORCE}, {"r_wrist_torque", mjSENS_TORQUE},
                      {"r_touch_left", mjSENS_TOUCH},  {"r_touch_right", mjSENS_TOUCH},
                      {"imu_gyro", mjSENS_GYRO},       {"imu_accel", mjSENS_ACCELEROMETER},
                      {"imu_quat", mjSENS_FRAMEQUAT}};
  humanoid.ft_site = "r_wrist_ft";
  humanoid.finger = "r_gripper_finger_l";
  humanoid.imu_site = "imu";
  humanoid.min_mass = 55.0;  // JVRC-1-like (~62 kg)
  humanoid.max_mass = 70.0;
  humanoid.frames = {{"r_gripper_tcp", true},
                     {"r_wrist_ft", true},
                     {"l_wrist_y_link", false},
                     {"head_link", false},
                     {"r_ankle_p_link", false}};

  RobotCase arm;
  arm.name = "arm7";
  arm.dir = LFD_ARM7_ROBOT_DIR;
  arm.urdf = "arm7.urdf";
  arm.mjcf = "arm7.xml";
  arm.root = "base_link";
  arm.movable_joints = 9;  // 7 arm joints + 2 fingers
  arm.sensors = {{"ft_force", mjSENS_FORCE},
                 {"ft_torque", mjSENS_TORQUE},
                 {"pad_left", mjSENS_TOUCH},
                 {"pad_right", mjSENS_TOUCH}};
  arm.ft_site = "ft_frame";
  arm.finger = "finger_left";
  arm.min_mass = 15.0;  // the arm, its stand and the hand (~23 kg)
  arm.max_mass = 35.0;
  arm.frames = {{"tcp", true}, {"ft_frame", true}, {"arm_link_4", false}, {"finger_left", false}};
  return {humanoid, arm};
}

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using DataPtr = std::unique_ptr<mjData, MjDataDeleter>;

ModelPtr loadScene(const RobotCase& robot) {
  std::array<char, 1000> error{};
  const std::string path = robot.scenePath();
  ModelPtr model(mj_loadXML(path.c_str(), nullptr, error.data(), error.size()));
  if (!model) ADD_FAILURE() << "mj_loadXML(" << path << "): " << error.data();
  return model;
}

urdf::ModelInterfaceSharedPtr loadUrdf(const RobotCase& robot) {
  auto model = urdf::parseURDFFile(robot.urdfPath());
  if (!model) ADD_FAILURE() << "cannot parse " << robot.urdfPath();
  return model;
}

class ModelConsistency : public ::testing::TestWithParam<RobotCase> {};

Eigen::Isometry3d bodyPose(const mjData* d, int body) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * body);
  t.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * body);
  return t;
}

Eigen::Isometry3d sitePose(const mjData* d, int site) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Map<const Eigen::Vector3d>(d->site_xpos + 3 * site);
  t.linear() =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->site_xmat + 9 * site);
  return t;
}

TEST_P(ModelConsistency, SameJointsAxesAndLimits) {
  const RobotCase& robot = GetParam();
  const auto urdf_model = loadUrdf(robot);
  const ModelPtr m = loadScene(robot);
  ASSERT_TRUE(urdf_model && m);
  std::set<std::string> urdf_movable;
  for (const auto& [name, joint] : urdf_model->joints_) {
    if (joint->type == urdf::Joint::FIXED) continue;
    urdf_movable.insert(name);
    const int id = mj_name2id(m.get(), mjOBJ_JOINT, name.c_str());
    ASSERT_GE(id, 0) << "URDF joint " << name << " missing in the MJCF";
    const bool prismatic = joint->type == urdf::Joint::PRISMATIC;
    EXPECT_EQ(m->jnt_type[id], prismatic ? mjJNT_SLIDE : mjJNT_HINGE) << name;
    EXPECT_TRUE(m->jnt_limited[id]) << name;
    EXPECT_NEAR(m->jnt_range[2 * id], joint->limits->lower, 1e-9) << name;
    EXPECT_NEAR(m->jnt_range[2 * id + 1], joint->limits->upper, 1e-9) << name;
    // Joint frames are aligned with their bodies in both files, so the axes compare directly.
    const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
    EXPECT_NEAR((Eigen::Map<const Eigen::Vector3d>(m->jnt_axis + 3 * id) - axis).norm(), 0, 1e-9)
        << name;
    // Its body is the URDF child link.
    EXPECT_STREQ(mj_id2name(m.get(), mjOBJ_BODY, m->jnt_bodyid[id]),
                 joint->child_link_name.c_str());

    const int act = mj_name2id(m.get(), mjOBJ_ACTUATOR, name.c_str());
    if (joint->mimic) {
      EXPECT_LT(act, 0) << "mimic joint " << name << " must not be actuated";
      continue;
    }
    ASSERT_GE(act, 0) << "no actuator named like joint " << name;
    EXPECT_EQ(m->actuator_trntype[act], mjTRN_JOINT);
    EXPECT_EQ(m->actuator_trnid[2 * act], id) << name;
    EXPECT_NEAR(m->actuator_ctrlrange[2 * act], joint->limits->lower, 1e-9) << name;
    EXPECT_NEAR(m->actuator_ctrlrange[2 * act + 1], joint->limits->upper, 1e-9) << name;
    EXPECT_TRUE(m->actuator_forcelimited[act]) << name;
    EXPECT_NEAR(m->actuator_forcerange[2 * act + 1], joint->limits->effort, 1e-9) << name;
    EXPECT_NEAR(m->actuator_forcerange[2 * act], -joint->limits->effort, 1e-9) << name;
  }
  EXPECT_EQ(urdf_movable.size(), robot.movable_joints);
  // Every hinge/slide joint of the robot's MJCF bodies exists in the URDF; the others (free
  // objects, the drawer's slide) are the scene's, declared in config/scene.yaml.
  const int base = mj_name2id(m.get(), mjOBJ_BODY, robot.root.c_str());
  ASSERT_GE(base, 0) << robot.root;
  const task::Scene scene = task::loadScene(kSceneFile);
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] == mjJNT_FREE) continue;
    const std::string name = mj_id2name(m.get(), mjOBJ_JOINT, j);
    int body = m->jnt_bodyid[j];
    while (body > 0 && body != base) body = m->body_parentid[body];
    if (body == base) {
      EXPECT_TRUE(urdf_movable.count(name)) << "MJCF joint " << name << " missing in the URDF";
      continue;
    }
    bool declared = false;
    for (const task::SceneObject& o : scene.objects) declared = declared || o.joints.count(name);
    EXPECT_TRUE(declared) << "scene joint " << name << " is not in " << kSceneFile;
  }
  for (const task::SceneObject& o : scene.objects) {  // every object of the scene file is there
    const int body = mj_name2id(m.get(), mjOBJ_BODY, o.name.c_str());
    ASSERT_GE(body, 0) << o.name;
    EXPECT_EQ(m->body_mocapid[body] >= 0, o.fixed) << o.name;
    if (!o.fixed)
      EXPECT_GE(mj_name2id(m.get(), mjOBJ_JOINT, (o.name + "_free").c_str()), 0) << o.name;
    for (const auto& [name, frame] : o.frames)
      if (!frame.body.empty()) EXPECT_GE(mj_name2id(m.get(), mjOBJ_BODY, frame.body.c_str()), 0);
  }
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_BODY, "table"), 0);
  EXPECT_EQ(m->opt.timestep, 0.001);
}

std::string readFile(const std::string& path) {
  std::ifstream f(path);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

// The committed model files are what generate_models.py makes of config/scene.yaml now: an edit of
// the scene file that was not regenerated would let the simulator and the task files disagree.
// The generators import lfd_tools.robot_models (PYTHONPATH of devel/setup.bash, as the tests run).
TEST_P(ModelConsistency, GeneratedFilesAreUpToDate) {
  const RobotCase& robot = GetParam();
  const std::string out = testing::TempDir() + "lfd_models_" + robot.name;
  ASSERT_EQ(std::system(("mkdir -p " + out + " && /usr/bin/python3 " + robot.modelDir() +
                         "/generate_models.py " + out + " > /dev/null")
                            .c_str()),
            0)
      << robot.modelDir() << "/generate_models.py failed (is devel/setup.bash sourced, for "
      << "lfd_tools.robot_models?)";
  for (const std::string& file : {std::string("workcell.xml"), robot.mjcf, robot.urdf})
    EXPECT_EQ(readFile(out + "/" + file), readFile(robot.modelDir() + "/" + file))
        << file << " differs from what generate_models.py writes: run it and commit the result";
}

TEST_P(ModelConsistency, SensorsSitesAndMassesMatchTheContract) {
  const RobotCase& robot = GetParam();
  const auto urdf_model = loadUrdf(robot);
  const ModelPtr m = loadScene(robot);
  ASSERT_TRUE(urdf_model && m);
  for (const auto& [name, type] : robot.sensors) {
    const int id = mj_name2id(m.get(), mjOBJ_SENSOR, name.c_str());
    ASSERT_GE(id, 0) << name;
    EXPECT_EQ(m->sensor_type[id], type) << name;
  }
  EXPECT_EQ(static_cast<size_t>(m->nsensor), robot.sensors.size());
  const lfd::RobotSetup setup = lfd::loadRobotSetup(robot.robotFile());
  for (const std::string& site : {setup.tip_link, robot.ft_site})
    EXPECT_GE(mj_name2id(m.get(), mjOBJ_SITE, site.c_str()), 0) << site;
  // The F/T site's body carries the whole gripper (palm + fingers) so it measures grasped loads.
  const int ft = mj_name2id(m.get(), mjOBJ_SITE, robot.ft_site.c_str());
  ASSERT_GE(ft, 0);
  const int finger = mj_name2id(m.get(), mjOBJ_BODY, robot.finger.c_str());
  ASSERT_GE(finger, 0) << robot.finger;
  EXPECT_EQ(m->body_parentid[finger], m->site_bodyid[ft]);
  const int root = mj_name2id(m.get(), mjOBJ_BODY, robot.root.c_str());
  if (!robot.imu_site.empty())
    EXPECT_EQ(m->site_bodyid[mj_name2id(m.get(), mjOBJ_SITE, robot.imu_site.c_str())], root);

  // Same masses link by link, and the expected total.
  double urdf_total = 0.0;
  for (const auto& [name, link] : urdf_model->links_) {
    if (!link->inertial) continue;
    urdf_total += link->inertial->mass;
    const int body = mj_name2id(m.get(), mjOBJ_BODY, name.c_str());
    ASSERT_GE(body, 0) << "link " << name << " has mass but no MJCF body";
    EXPECT_NEAR(m->body_mass[body], link->inertial->mass, 1e-9) << name;
    EXPECT_NEAR(m->body_inertia[3 * body], link->inertial->ixx, 1e-9) << name;
  }
  EXPECT_NEAR(m->body_subtreemass[root], urdf_total, 1e-9);
  EXPECT_GT(urdf_total, robot.min_mass);
  EXPECT_LT(urdf_total, robot.max_mass);
}

// The shipped robot file describes this model: every sensor table row binds to its message type,
// names sensors the model has with its fields' dimensions, in a frame the model has (a site or a
// body), and the gripper joint and end effector exist.
TEST_P(ModelConsistency, TheRobotFileMatchesTheModel) {
  const ModelPtr m = loadScene(GetParam());
  ASSERT_TRUE(m);
  const lfd::RobotSetup robot = lfd::loadRobotSetup(GetParam().robotFile());
  ASSERT_FALSE(robot.sensors.empty());
  const auto dimension = [&](const std::string& sensor) {
    const int id = mj_name2id(m.get(), mjOBJ_SENSOR, sensor.c_str());
    if (id < 0) ADD_FAILURE() << "the sensor table names '" << sensor << "', not in the model";
    return id < 0 ? -1 : m->sensor_dim[id];
  };
  const auto bindings = lfd_sim::bindSensorTable(robot.sensors);
  EXPECT_NO_THROW(lfd_sim::checkSensorDimensions(bindings, dimension));
  for (const lfd::SensorEntry& row : robot.sensors)
    EXPECT_TRUE(mj_name2id(m.get(), mjOBJ_SITE, row.frame.c_str()) >= 0 ||
                mj_name2id(m.get(), mjOBJ_BODY, row.frame.c_str()) >= 0)
        << row.topic << ": frame " << row.frame << " is neither a site nor a body";
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_ACTUATOR, robot.gripper.joint.c_str()), 0);
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_SITE, robot.tip_link.c_str()), 0);
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_BODY, robot.base_link.c_str()), 0);
  // The ready posture names joints of the model, inside their limits.
  EXPECT_FALSE(robot.initial_posture.empty());
  for (const auto& [joint, value] : robot.initial_posture) {
    const int j = mj_name2id(m.get(), mjOBJ_JOINT, joint.c_str());
    ASSERT_GE(j, 0) << "initial_posture names " << joint << ", not in the model";
    EXPECT_GE(value, m->jnt_range[2 * j]) << joint;
    EXPECT_LE(value, m->jnt_range[2 * j + 1]) << joint;
  }
  EXPECT_EQ(robot.initial_posture.count(robot.gripper.joint), 1u);
  // The Cartesian frame of the task poses (the chain's base_link) is the robot's mount point of
  // config/scene.yaml, not rotated.
  DataPtr d(mj_makeData(m.get()));
  mj_kinematics(m.get(), d.get());
  const Eigen::Isometry3d base =
      bodyPose(d.get(), mj_name2id(m.get(), mjOBJ_BODY, robot.base_link.c_str()));
  const task::Scene scene = task::loadScene(kSceneFile);
  EXPECT_NEAR((base.translation() - scene.base_in_world).norm(), 0.0, 1e-9);
  EXPECT_NEAR((base.linear() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
}

TEST_P(ModelConsistency, ToolPoseAgreesWithUrdfKinematics) {
  const RobotCase& robot = GetParam();
  const ModelPtr m = loadScene(robot);
  ASSERT_TRUE(m);
  DataPtr d(mj_makeData(m.get()));
  const int base = mj_name2id(m.get(), mjOBJ_BODY, robot.root.c_str());
  const std::vector<Frame>& frames = robot.frames;
  std::vector<lfd::KinematicChain> chains;
  for (const auto& f : frames)
    chains.push_back(lfd::KinematicChain::fromUrdfFile(robot.urdfPath(), robot.root, f.link));

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_position = 0.0, worst_angle = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    mj_resetData(m.get(), d.get());
    for (int j = 0; j < m->njnt; ++j) {
      if (m->jnt_type[j] == mjJNT_FREE) continue;
      const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
      d->qpos[m->jnt_qposadr[j]] = lo + unit(rng) * (hi - lo);
    }
    mj_kinematics(m.get(), d.get());
    const Eigen::Isometry3d base_pose = bodyPose(d.get(), base);
    for (size_t k = 0; k < frames.size(); ++k) {
      const auto& chain = chains[k];
      Eigen::VectorXd q(chain.dof());
      for (int i = 0; i < chain.dof(); ++i) {
        const int j = mj_name2id(m.get(), mjOBJ_JOINT, chain.jointNames()[i].c_str());
        ASSERT_GE(j, 0);
        q[i] = d->qpos[m->jnt_qposadr[j]];
      }
      const int id =
          mj_name2id(m.get(), frames[k].is_site ? mjOBJ_SITE : mjOBJ_BODY, frames[k].link.c_str());
      ASSERT_GE(id, 0) << frames[k].link;
      const Eigen::Isometry3d world =
          frames[k].is_site ? sitePose(d.get(), id) : bodyPose(d.get(), id);
      const Eigen::Isometry3d in_base = base_pose.inverse() * world;
      const Eigen::Isometry3d fk = chain.forward(q);
      worst_position = std::max(worst_position, (in_base.translation() - fk.translation()).norm());
      worst_angle = std::max(worst_angle,
                             Eigen::AngleAxisd(in_base.linear() * fk.linear().transpose()).angle());
    }
  }
  RecordProperty("max_position_error_m", std::to_string(worst_position));
  std::printf("%s: URDF FK vs MuJoCo over 100 random configurations: %.3g m, %.3g rad\n",
              robot.name.c_str(), worst_position, worst_angle);
  EXPECT_LT(worst_position, 1e-3);
  EXPECT_LT(worst_angle, 1e-3);
}

// The scene simulates: started in the robot file's ready posture (as the bridge starts it) and held
// there by the position actuators, the robot touches nothing, sags little, and the gripper closes
// on nothing and opens again without blowing up (the mimic finger follows, the pads read ~0).
TEST_P(ModelConsistency, TheWorkcellSimulatesTheReadyPostureAndTheGripper) {
  const RobotCase& robot = GetParam();
  const ModelPtr m = loadScene(robot);
  ASSERT_TRUE(m);
  DataPtr d(mj_makeData(m.get()));
  const lfd::RobotSetup setup = lfd::loadRobotSetup(robot.robotFile());
  // Every actuator drives the joint it is named like; unlisted joints hold 0.
  for (int a = 0; a < m->nu; ++a) {
    const int j = m->actuator_trnid[2 * a];
    const auto it = setup.initial_posture.find(mj_id2name(m.get(), mjOBJ_JOINT, j));
    const double value = it == setup.initial_posture.end() ? 0.0 : it->second;
    d->qpos[m->jnt_qposadr[j]] = value;
    d->ctrl[a] = value;
  }
  mj_forward(m.get(), d.get());
  const int gripper = mj_name2id(m.get(), mjOBJ_ACTUATOR, setup.gripper.joint.c_str());
  ASSERT_GE(gripper, 0);
  const int finger_joint = m->actuator_trnid[2 * gripper];
  int mimic = -1;
  for (int e = 0; e < m->neq; ++e)
    if (m->eq_type[e] == mjEQ_JOINT && m->eq_obj2id[e] == finger_joint) mimic = m->eq_obj1id[e];
  ASSERT_GE(mimic, 0) << "no equality couples a finger to " << setup.gripper.joint;
  const int tip = mj_name2id(m.get(), mjOBJ_SITE, setup.tip_link.c_str());
  const Eigen::Vector3d tip_start = sitePose(d.get(), tip).translation();
  const int root = mj_name2id(m.get(), mjOBJ_BODY, robot.root.c_str());
  const auto robot_body = [&](int body) {
    while (body > 0 && body != root) body = m->body_parentid[body];
    return body == root;
  };
  const auto step = [&](double seconds) {
    for (int k = 0; k < static_cast<int>(seconds / m->opt.timestep); ++k) mj_step(m.get(), d.get());
    for (int i = 0; i < m->nq; ++i) ASSERT_TRUE(std::isfinite(d->qpos[i])) << "qpos " << i;
    EXPECT_EQ(d->warning[mjWARN_BADQACC].number, 0);
  };
  const auto finger = [&](int joint) { return d->qpos[m->jnt_qposadr[joint]]; };
  ASSERT_NO_FATAL_FAILURE(step(1.0));
  for (int c = 0; c < d->ncon; ++c)  // the hand above the table, the stand beside it
    EXPECT_FALSE(robot_body(m->geom_bodyid[d->contact[c].geom1]) ||
                 robot_body(m->geom_bodyid[d->contact[c].geom2]))
        << "the robot touches " << mj_id2name(m.get(), mjOBJ_GEOM, d->contact[c].geom1) << " / "
        << mj_id2name(m.get(), mjOBJ_GEOM, d->contact[c].geom2) << " in its ready posture";
  const double sag = (sitePose(d.get(), tip).translation() - tip_start).norm();
  std::printf("%s: the TCP sags %.1f mm in the ready posture\n", robot.name.c_str(), 1e3 * sag);
  EXPECT_LT(sag, 0.01) << "the ready posture sags under gravity";
  d->ctrl[gripper] = setup.gripper.close_opening / setup.gripper.opening_scale;
  ASSERT_NO_FATAL_FAILURE(step(1.5));
  EXPECT_NEAR(finger(finger_joint), setup.gripper.close_opening / setup.gripper.opening_scale,
              2e-3);
  EXPECT_NEAR(finger(mimic), finger(finger_joint), 2e-3);
  for (const lfd::SensorEntry& row : setup.sensors)
    if (row.type == "lfd_msgs/Touch")
      for (const auto& [field, names] : row.fields)
        for (const std::string& pad : names) {
          const int s = mj_name2id(m.get(), mjOBJ_SENSOR, pad.c_str());
          ASSERT_GE(s, 0) << pad;
          EXPECT_LT(d->sensordata[m->sensor_adr[s]], 1.0) << pad << " touches something";
        }
  d->ctrl[gripper] = setup.gripper.open_opening / setup.gripper.opening_scale;
  ASSERT_NO_FATAL_FAILURE(step(1.5));
  EXPECT_NEAR(finger(finger_joint), setup.gripper.open_opening / setup.gripper.opening_scale, 2e-3);
  EXPECT_NEAR(finger(mimic), finger(finger_joint), 2e-3);
  EXPECT_LT((sitePose(d.get(), tip).translation() - tip_start).norm(), 0.01);
}

INSTANTIATE_TEST_SUITE_P(Robots, ModelConsistency, ::testing::ValuesIn(robots()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
