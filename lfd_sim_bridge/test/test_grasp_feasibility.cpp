// Physics feasibility of the workcell (plain MuJoCo, no bridge, no ROS): the arm, driven only
// through its position actuators with joint targets from the core IK, can pick the stick up and
// carry it to a goal, and can push the box to a target. If the model's friction, gripper force,
// finger geometry or solver settings regress, downstream demonstrations would fail; this test
// catches it first.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lfd_core/kinematics/inverse_kinematics.hpp"
#include "lfd_core/kinematics/kinematic_chain.hpp"

namespace {

const std::string kModelDir = LFD_SIM_MODEL_DIR;
constexpr double kTableTop = 0.80;           // world z of the table surface (generate_models.py)
constexpr double kPelvisHeight = 0.85;       // world z of base_link
constexpr double kGraspAboveCenter = 0.005;  // TCP above the stick's centre when grasping
constexpr double kFingerHalfWidth = 0.012;   // finger half extent along the push direction

struct Pose {
  Eigen::Vector3d position;  // world
  double yaw = 0.0;          // about world z
};

Eigen::Isometry3d tcpTarget(const Eigen::Vector3d& world_position, double yaw) {
  // Fingers down, closing across the stick: the zero-pose TCP orientation turned by the yaw.
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = world_position - Eigen::Vector3d(0, 0, kPelvisHeight);
  t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return t;
}

double minimumJerk(double s) {
  return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
}

// Drives the right arm (waist + 7 joints, base_link -> r_gripper_tcp) through Cartesian moves:
// IK every 2 ms warm-started from the previous solution, joint targets sent to the position
// actuators, physics at the model's 1 kHz.
class ArmDriver {
 public:
  ArmDriver()
      : chain_(lfd::KinematicChain::fromUrdfFile(kModelDir + "/jvrc1_like.urdf", "base_link",
                                                 "r_gripper_tcp")),
        ik_(chain_, ikOptions(chain_)) {
    std::array<char, 1000> error{};
    model_ = mj_loadXML((kModelDir + "/workcell.xml").c_str(), nullptr, error.data(), error.size());
    if (!model_) throw std::runtime_error(std::string("mj_loadXML: ") + error.data());
    data_ = mj_makeData(model_);
    for (const auto& name : chain_.jointNames()) {
      const int j = mj_name2id(model_, mjOBJ_JOINT, name.c_str());
      const int a = mj_name2id(model_, mjOBJ_ACTUATOR, name.c_str());
      if (j < 0 || a < 0) throw std::runtime_error("missing joint/actuator " + name);
      qpos_adr_.push_back(model_->jnt_qposadr[j]);
      actuator_.push_back(a);
    }
    gripper_ = mj_name2id(model_, mjOBJ_ACTUATOR, "R_GRIPPER");
    touch_left_ = model_->sensor_adr[mj_name2id(model_, mjOBJ_SENSOR, "r_touch_left")];
    touch_right_ = model_->sensor_adr[mj_name2id(model_, mjOBJ_SENSOR, "r_touch_right")];
    home_ = Eigen::VectorXd::Zero(chain_.dof());
    home_[chain_.jointIndex("WAIST_P")] = 0.2;
    home_[chain_.jointIndex("R_SHOULDER_P")] = -0.5;
    home_[chain_.jointIndex("R_SHOULDER_R")] = -0.15;
    home_[chain_.jointIndex("R_ELBOW_P")] = -1.5;
    home_[chain_.jointIndex("R_WRIST_Y")] = 0.5;
    ik_.setPreferredPosture(home_);
    // Start at home, holding it, with the gripper open.
    q_ = home_;
    for (int i = 0; i < chain_.dof(); ++i) data_->qpos[qpos_adr_[i]] = q_[i];
    sendJoints(q_);
    setGripper(0.04);
    mj_forward(model_, data_);
    tcp_ = chain_.forward(q_);
  }
  ~ArmDriver() {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }

  static lfd::IkOptions ikOptions(const lfd::KinematicChain& chain) {
    lfd::IkOptions o;
    o.joint_costs = Eigen::VectorXd::Ones(chain.dof());
    o.joint_costs.head(3) << 3.0, 3.0, 20.0;  // keep the waist quiet, roll least of all
    return o;
  }

  void placeObject(const std::string& joint, const Pose& pose, double half_height) {
    const int j = mj_name2id(model_, mjOBJ_JOINT, joint.c_str());
    double* qpos = data_->qpos + model_->jnt_qposadr[j];
    qpos[0] = pose.position.x();
    qpos[1] = pose.position.y();
    qpos[2] = kTableTop + half_height;
    qpos[3] = std::cos(pose.yaw / 2);
    qpos[4] = qpos[5] = 0.0;
    qpos[6] = std::sin(pose.yaw / 2);
    std::fill_n(data_->qvel + model_->jnt_dofadr[j], 6, 0.0);
    mj_forward(model_, data_);
  }

  Eigen::Vector3d objectPosition(const std::string& body) const {
    const int b = mj_name2id(model_, mjOBJ_BODY, body.c_str());
    return Eigen::Map<const Eigen::Vector3d>(data_->xpos + 3 * b);
  }

  void setGripper(double half_opening) { data_->ctrl[gripper_] = half_opening; }
  double touchLeft() const { return data_->sensordata[touch_left_]; }
  double touchRight() const { return data_->sensordata[touch_right_]; }

  // Minimum-jerk Cartesian move of the TCP to `target` (base_link) in `duration` seconds.
  // Returns false when IK cannot follow the path.
  bool moveTo(const Eigen::Isometry3d& target, double duration) {
    const Eigen::Isometry3d from = tcp_;
    const Eigen::Quaterniond qa(from.linear()), qb(target.linear());
    const int steps = static_cast<int>(std::round(duration / model_->opt.timestep));
    lfd::IkResult result;
    result.q = q_;
    Eigen::VectorXd previous = q_;
    for (int k = 1; k <= steps; ++k) {
      if (k % 2 == 0 || k == steps) {
        const double s = minimumJerk(static_cast<double>(k) / steps);
        Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
        pose.translation() = from.translation() + s * (target.translation() - from.translation());
        pose.linear() = qa.slerp(s, qb).toRotationMatrix();
        ik_.solve(pose, result.q, result);
        if (result.position_error > 1e-3 || result.orientation_error > 1e-2) {
          std::printf("IK failed at step %d: %.4f m %.4f rad\n", k, result.position_error,
                      result.orientation_error);
          return false;
        }
        previous = q_;
        q_ = result.q;
        sendJoints(q_);
      }
      mj_step(model_, data_);
    }
    tcp_ = target;
    return true;
  }

  void hold(double duration) {
    const int steps = static_cast<int>(std::round(duration / model_->opt.timestep));
    for (int k = 0; k < steps; ++k) mj_step(model_, data_);
  }

  // Measured TCP (MuJoCo site) in base_link, to report tracking errors.
  Eigen::Vector3d measuredTcp() const {
    const int s = mj_name2id(model_, mjOBJ_SITE, "r_gripper_tcp");
    return Eigen::Map<const Eigen::Vector3d>(data_->site_xpos + 3 * s) -
           Eigen::Vector3d(0, 0, kPelvisHeight);
  }
  const Eigen::Isometry3d& commandedTcp() const { return tcp_; }
  double simTime() const { return data_->time; }

 private:
  void sendJoints(const Eigen::VectorXd& q) {
    for (int i = 0; i < chain_.dof(); ++i) data_->ctrl[actuator_[i]] = q[i];
  }

  lfd::KinematicChain chain_;
  lfd::InverseKinematics ik_;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::vector<int> qpos_adr_, actuator_;
  int gripper_ = -1, touch_left_ = -1, touch_right_ = -1;
  Eigen::VectorXd home_, q_;
  Eigen::Isometry3d tcp_;
};

struct GraspCase {
  Pose stick;
  Eigen::Vector3d goal;  // world position of the stick's centre at the end (lifted)
};

void runGrasp(const GraspCase& c) {
  ArmDriver arm;
  arm.placeObject("stick_free", c.stick, 0.015);
  arm.hold(0.3);
  const Eigen::Vector3d grasp(c.stick.position.x(), c.stick.position.y(),
                              kTableTop + 0.015 + kGraspAboveCenter);
  const double yaw = c.stick.yaw;
  ASSERT_TRUE(arm.moveTo(tcpTarget(grasp + Eigen::Vector3d(0, 0, 0.10), yaw), 2.0));
  ASSERT_TRUE(arm.moveTo(tcpTarget(grasp, yaw), 1.2));
  arm.hold(0.3);
  const Eigen::Vector3d tracking = arm.measuredTcp() - arm.commandedTcp().translation();
  arm.setGripper(0.0);
  arm.hold(0.8);
  EXPECT_GT(arm.touchLeft(), 1.0) << "left pad does not touch the stick";
  EXPECT_GT(arm.touchRight(), 1.0) << "right pad does not touch the stick";
  const Eigen::Vector3d lifted = grasp + Eigen::Vector3d(0, 0, 0.15);
  ASSERT_TRUE(arm.moveTo(tcpTarget(lifted, yaw), 1.2));
  const Eigen::Vector3d goal_tcp = c.goal + Eigen::Vector3d(0, 0, kGraspAboveCenter);
  ASSERT_TRUE(arm.moveTo(tcpTarget(goal_tcp, yaw + 0.3), 2.0));
  arm.hold(0.6);
  const Eigen::Vector3d end = arm.objectPosition("stick");
  std::printf(
      "grasp: tracking error at grasp %.1f mm, stick %.1f cm above the table, %.1f cm "
      "from the goal, touch %.1f/%.1f N\n",
      1000 * tracking.norm(), 100 * (end.z() - kTableTop), 100 * (end - c.goal).norm(),
      arm.touchLeft(), arm.touchRight());
  EXPECT_GE(end.z() - kTableTop, 0.10);
  EXPECT_LE((end - c.goal).norm(), 0.03);
}

TEST(GraspFeasibility, PicksUpTheStickAndCarriesItToTheGoal) {
  runGrasp(
      {{Eigen::Vector3d(0.45, -0.25, 0.0), 0.2}, Eigen::Vector3d(0.55, -0.10, kTableTop + 0.15)});
}

TEST(GraspFeasibility, PicksUpTheStickAtAFarCorner) {
  runGrasp(
      {{Eigen::Vector3d(0.68, -0.45, 0.0), -0.3}, Eigen::Vector3d(0.40, -0.30, kTableTop + 0.15)});
}

void runPush(const Pose& box, const Eigen::Vector3d& target) {
  ArmDriver arm;
  arm.placeObject("box_free", box, 0.04);
  arm.hold(0.3);
  const Eigen::Vector3d start(box.position.x(), box.position.y(), kTableTop + 0.04);
  Eigen::Vector3d dir = target - start;
  dir.z() = 0;
  dir.normalize();
  // The closed fingers form a square block, so any of its faces pushes: yaw modulo pi/2.
  const double yaw = std::remainder(std::atan2(dir.y(), dir.x()), M_PI / 2);
  const double face = 0.04 + kFingerHalfWidth;
  const Eigen::Vector3d behind = start - (face + 0.02) * dir;
  const Eigen::Vector3d pushed = target - face * dir;
  arm.setGripper(0.0);  // closed fist
  ASSERT_TRUE(arm.moveTo(tcpTarget(behind + Eigen::Vector3d(0, 0, 0.08), yaw), 2.0));
  ASSERT_TRUE(arm.moveTo(tcpTarget(behind, yaw), 1.0));
  ASSERT_TRUE(arm.moveTo(tcpTarget(pushed, yaw), 2.5));
  ASSERT_TRUE(arm.moveTo(tcpTarget(pushed - 0.06 * dir + Eigen::Vector3d(0, 0, 0.06), yaw), 1.0));
  arm.hold(0.5);
  const Eigen::Vector3d end = arm.objectPosition("box");
  const double error = (end - target).head<2>().norm();
  std::printf("push: box %.1f cm from its target (moved %.1f cm)\n", 100 * error,
              100 * (end - start).head<2>().norm());
  EXPECT_LE(error, 0.03);
  EXPECT_NEAR(end.z(), kTableTop + 0.04, 0.005);  // still flat on the table
}

TEST(PushFeasibility, PushesTheBoxAwayToItsTarget) {
  runPush({Eigen::Vector3d(0.45, -0.30, 0.0), 0.0}, Eigen::Vector3d(0.60, -0.28, kTableTop + 0.04));
}

TEST(PushFeasibility, PushesTheBoxSidewaysToItsTarget) {
  runPush({Eigen::Vector3d(0.50, -0.16, 0.0), 0.0}, Eigen::Vector3d(0.50, -0.30, kTableTop + 0.04));
}

}  // namespace
