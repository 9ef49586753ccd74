// The URDF (used by every kinematics consumer) and the MJCF workcell (used by the simulator) are
// generated from one source; this test proves they describe the same robot: same joints, axes,
// limits, actuators and sensors, and the same tool pose for random configurations; that the scene's
// objects and joints are those of config/scene.yaml; and that the files are up to date with it.
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

#include <cstdlib>
#include <fstream>
#include <iterator>

#include "lfd_core/kinematic_chain.hpp"
#include "lfd_core/robot_setup.hpp"
#include "lfd_sim_bridge/sensor_table.hpp"
#include "lfd_sim_bridge/task_file.hpp"

namespace task = lfd_sim_bridge::task;

namespace {

const std::string kModelDir = LFD_SIM_MODEL_DIR;
const std::string kUrdfPath = kModelDir + "/jvrc1_like.urdf";
const std::string kSceneFile = std::string(LFD_CONFIG_DIR) + "/scene.yaml";
const std::string kScenePath = kModelDir + "/workcell.xml";
const std::string kRobotFile = LFD_ROBOT_FILE;

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using DataPtr = std::unique_ptr<mjData, MjDataDeleter>;

ModelPtr loadScene() {
  std::array<char, 1000> error{};
  ModelPtr model(mj_loadXML(kScenePath.c_str(), nullptr, error.data(), error.size()));
  if (!model) ADD_FAILURE() << "mj_loadXML(" << kScenePath << "): " << error.data();
  return model;
}

urdf::ModelInterfaceSharedPtr loadUrdf() {
  auto model = urdf::parseURDFFile(kUrdfPath);
  if (!model) ADD_FAILURE() << "cannot parse " << kUrdfPath;
  return model;
}

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

TEST(ModelConsistency, SameJointsAxesAndLimits) {
  const auto urdf_model = loadUrdf();
  const ModelPtr m = loadScene();
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
  EXPECT_EQ(urdf_movable.size(), 34u);  // 12 legs + 3 waist + 3 neck + 14 arms + 2 fingers
  // Every hinge/slide joint of the robot's MJCF bodies exists in the URDF; the others (free
  // objects, the drawer's slide) are the scene's, declared in config/scene.yaml.
  const int base = mj_name2id(m.get(), mjOBJ_BODY, "base_link");
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
TEST(ModelConsistency, GeneratedFilesAreUpToDate) {
  const std::string out = testing::TempDir() + "lfd_models";
  ASSERT_EQ(std::system(("mkdir -p " + out + " && /usr/bin/python3 " + kModelDir +
                         "/generate_models.py " + out + " > /dev/null")
                            .c_str()),
            0);
  for (const char* file : {"workcell.xml", "jvrc1_like.xml", "jvrc1_like.urdf"})
    EXPECT_EQ(readFile(out + "/" + file), readFile(kModelDir + "/" + file))
        << file << " differs from what generate_models.py writes: run it and commit the result";
}

TEST(ModelConsistency, SensorsSitesAndMassesMatchTheContract) {
  const auto urdf_model = loadUrdf();
  const ModelPtr m = loadScene();
  ASSERT_TRUE(urdf_model && m);
  const std::map<std::string, int> sensors = {
      {"r_wrist_force", mjSENS_FORCE}, {"r_wrist_torque", mjSENS_TORQUE},
      {"r_touch_left", mjSENS_TOUCH},  {"r_touch_right", mjSENS_TOUCH},
      {"imu_gyro", mjSENS_GYRO},       {"imu_accel", mjSENS_ACCELEROMETER},
      {"imu_quat", mjSENS_FRAMEQUAT}};
  for (const auto& [name, type] : sensors) {
    const int id = mj_name2id(m.get(), mjOBJ_SENSOR, name.c_str());
    ASSERT_GE(id, 0) << name;
    EXPECT_EQ(m->sensor_type[id], type) << name;
  }
  for (const char* site : {"r_gripper_tcp", "r_wrist_ft", "imu"})
    EXPECT_GE(mj_name2id(m.get(), mjOBJ_SITE, site), 0) << site;
  // The F/T site's body carries the whole gripper (palm + fingers) so it measures grasped loads.
  const int ft_body = m->site_bodyid[mj_name2id(m.get(), mjOBJ_SITE, "r_wrist_ft")];
  const int finger = mj_name2id(m.get(), mjOBJ_BODY, "r_gripper_finger_l");
  EXPECT_EQ(m->body_parentid[finger], ft_body);
  EXPECT_EQ(m->site_bodyid[mj_name2id(m.get(), mjOBJ_SITE, "imu")],
            mj_name2id(m.get(), mjOBJ_BODY, "base_link"));

  // Same masses link by link, and a JVRC-1-like total (~62 kg).
  double urdf_total = 0.0;
  for (const auto& [name, link] : urdf_model->links_) {
    if (!link->inertial) continue;
    urdf_total += link->inertial->mass;
    const int body = mj_name2id(m.get(), mjOBJ_BODY, name.c_str());
    ASSERT_GE(body, 0) << "link " << name << " has mass but no MJCF body";
    EXPECT_NEAR(m->body_mass[body], link->inertial->mass, 1e-9) << name;
    EXPECT_NEAR(m->body_inertia[3 * body], link->inertial->ixx, 1e-9) << name;
  }
  const int base = mj_name2id(m.get(), mjOBJ_BODY, "base_link");
  EXPECT_NEAR(m->body_subtreemass[base], urdf_total, 1e-9);
  EXPECT_GT(urdf_total, 55.0);
  EXPECT_LT(urdf_total, 70.0);
}

// The shipped robot file describes this model: every sensor table row binds to its message type,
// names sensors the model has with its fields' dimensions, in a frame the model has (a site or a
// body), and the gripper joint and end effector exist.
TEST(ModelConsistency, TheRobotFileMatchesTheModel) {
  const ModelPtr m = loadScene();
  ASSERT_TRUE(m);
  const lfd::RobotSetup robot = lfd::loadRobotSetup(kRobotFile);
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
}

TEST(ModelConsistency, ToolPoseAgreesWithUrdfKinematics) {
  const ModelPtr m = loadScene();
  ASSERT_TRUE(m);
  DataPtr d(mj_makeData(m.get()));
  const int base = mj_name2id(m.get(), mjOBJ_BODY, "base_link");
  struct Frame {
    std::string link;
    bool is_site;
  };
  const std::vector<Frame> frames = {{"r_gripper_tcp", true},
                                     {"r_wrist_ft", true},
                                     {"l_wrist_y_link", false},
                                     {"head_link", false},
                                     {"r_ankle_p_link", false}};
  std::vector<lfd::KinematicChain> chains;
  for (const auto& f : frames)
    chains.push_back(lfd::KinematicChain::fromUrdfFile(kUrdfPath, "base_link", f.link));

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
  std::printf("URDF FK vs MuJoCo over 100 random configurations: %.3g m, %.3g rad\n",
              worst_position, worst_angle);
  EXPECT_LT(worst_position, 1e-3);
  EXPECT_LT(worst_angle, 1e-3);
}

}  // namespace
