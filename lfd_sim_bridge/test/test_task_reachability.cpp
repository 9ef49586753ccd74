// config/tasks.yaml is consistent with the protocol (counts, workspace sizes, unseen goals inside
// the demonstrated workspace and different from every demo) and every pose the demonstrator and
// the executor will ask for is reachable by the core IK along continuous paths, with margin from
// the joint limits. The path geometry mirrors test_grasp_feasibility.cpp and the tasks.yaml header.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "lfd_core/inverse_kinematics.hpp"
#include "lfd_core/kinematic_chain.hpp"

namespace {

const std::string kModelDir = LFD_SIM_MODEL_DIR;
const std::string kTasksPath = kModelDir + "/../../config/tasks.yaml";
const std::string kRobotPath = kModelDir + "/../../config/robot.yaml";

constexpr double kGraspAboveCenter = 0.005, kPregrasp = 0.10, kLift = 0.15;
constexpr double kPushFace = 0.04 + 0.012, kPushClearance = 0.02, kPushPrelift = 0.08;
constexpr double kRetreat = 0.06;

struct Pose4 {
  Eigen::Vector3d p;
  double yaw = 0.0;
};

struct Entry {
  int id = 0;
  Pose4 start, goal;  // stick/box start, stick goal/box target
};

Pose4 readPose(const YAML::Node& n) {
  if (!n.IsSequence() || n.size() != 4) throw std::runtime_error("pose must be [x, y, z, yaw]");
  return {Eigen::Vector3d(n[0].as<double>(), n[1].as<double>(), n[2].as<double>()),
          n[3].as<double>()};
}

std::vector<Entry> readList(const YAML::Node& list, const std::string& object,
                            const std::string& goal_key) {
  std::vector<Entry> out;
  for (const auto& e : list)
    out.push_back({e["id"].as<int>(), readPose(e[object]), readPose(e[goal_key])});
  return out;
}

class Tasks : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = YAML::LoadFile(kTasksPath);
    table_ = root_["table_top"].as<double>();
    base_z_ = root_["base_link_in_world"][2].as<double>();
    const YAML::Node ik = YAML::LoadFile(kRobotPath)["ik"];
    chain_ = std::make_unique<lfd::KinematicChain>(lfd::KinematicChain::fromUrdfFile(
        kModelDir + "/jvrc1_like.urdf", ik["base_link"].as<std::string>(),
        ik["tip_link"].as<std::string>()));
    lfd::IkOptions options;
    options.joint_costs = Eigen::VectorXd::Ones(chain_->dof());
    for (const auto& kv : ik["joint_costs"]) {
      const int i = chain_->jointIndex(kv.first.as<std::string>());
      ASSERT_GE(i, 0) << kv.first.as<std::string>();
      options.joint_costs[i] = kv.second.as<double>();
    }
    home_ = Eigen::VectorXd::Zero(chain_->dof());
    for (const auto& kv : ik["preferred_posture"]) {
      const int i = chain_->jointIndex(kv.first.as<std::string>());
      ASSERT_GE(i, 0) << kv.first.as<std::string>();
      home_[i] = kv.second.as<double>();
    }
    min_margin_ = ik["min_limit_margin"].as<double>();
    ik_ = std::make_unique<lfd::InverseKinematics>(*chain_, options);
    ik_->setPreferredPosture(home_);
  }

  // TCP target in base_link for a world position and yaw (fingers down).
  Eigen::Isometry3d tcp(const Eigen::Vector3d& world, double yaw) const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = world - Eigen::Vector3d(0, 0, base_z_);
    t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return t;
  }

  // Follows waypoints (straight lines, `samples` per leg) from home, warm-started like the
  // demonstrator; every sample must converge, keep the margin and not jump branches.
  void expectPath(const std::vector<Eigen::Isometry3d>& waypoints, const std::string& what) {
    Eigen::Isometry3d from = chain_->forward(home_);
    lfd::IkResult r;
    r.q = home_;
    for (size_t w = 0; w < waypoints.size(); ++w) {
      const Eigen::Quaterniond qa(from.linear()), qb(waypoints[w].linear());
      const int samples = 25;
      for (int k = 1; k <= samples; ++k) {
        const double s = static_cast<double>(k) / samples;
        Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
        pose.translation() =
            from.translation() + s * (waypoints[w].translation() - from.translation());
        pose.linear() = qa.slerp(s, qb).toRotationMatrix();
        const Eigen::VectorXd previous = r.q;
        ik_->solve(pose, previous, r);
        ASSERT_TRUE(r.converged) << what << " waypoint " << w << " sample " << k << ": "
                                 << r.position_error << " m, " << r.orientation_error << " rad";
        const double margin = chain_->limitMargin(r.q);
        worst_margin_ = std::min(worst_margin_, margin);
        if (w > 0)  // the move from the arbitrary home may swing further
          EXPECT_LT((r.q - previous).cwiseAbs().maxCoeff(), 0.25)
              << what << " waypoint " << w << " sample " << k << " jumps";
        if (margin < min_margin_) {
          int worst = 0;
          (r.q - chain_->lowerLimits()).cwiseMin(chain_->upperLimits() - r.q).minCoeff(&worst);
          ADD_FAILURE() << what << " waypoint " << w << " sample " << k << ": "
                        << chain_->jointNames()[worst] << " only " << margin
                        << " rad from its limit";
          return;
        }
      }
      from = waypoints[w];
    }
  }

  void expectGraspReachable(const std::vector<Entry>& list, const std::string& what) {
    for (const auto& e : list) {
      const std::string name = what + " id " + std::to_string(e.id);
      EXPECT_NEAR(e.start.p.z(), table_ + 0.015, 1e-6) << name << ": stick not on the table";
      EXPECT_GE(e.goal.p.z() - table_, 0.10) << name << ": goal not lifted";
      EXPECT_GE((e.goal.p - e.start.p).head<2>().norm(), 0.08) << name << ": goal too close";
      const Eigen::Vector3d above(0, 0, kGraspAboveCenter);
      // The demonstrator varies the grasp point along the stick and the gripper yaw a little.
      for (const double along : {-0.015, 0.0, 0.015}) {
        for (const double dyaw : {-0.08, 0.0, 0.08}) {
          const double yaw = e.start.yaw + dyaw;
          const Eigen::Vector3d grasp =
              e.start.p + above + along * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0);
          const Eigen::Vector3d lifted = grasp + Eigen::Vector3d(0, 0, kLift);
          expectPath({tcp(grasp + Eigen::Vector3d(0, 0, kPregrasp), yaw), tcp(grasp, yaw),
                      tcp(lifted, yaw), tcp(e.goal.p + above, e.goal.yaw + dyaw)},
                     name);
          if (HasFailure()) return;
        }
      }
    }
  }

  void expectPushReachable(const std::vector<Entry>& list, const std::string& what) {
    for (const auto& e : list) {
      const std::string name = what + " id " + std::to_string(e.id);
      EXPECT_NEAR(e.start.p.z(), table_ + 0.04, 1e-6) << name << ": box not on the table";
      Eigen::Vector3d dir = e.goal.p - e.start.p;
      dir.z() = 0;
      EXPECT_GE(dir.norm(), 0.10) << name << ": push too short";
      dir.normalize();
      // The closed fingers are a square block: any face pushes, so the yaw is taken modulo pi/2.
      const double yaw = std::remainder(std::atan2(dir.y(), dir.x()), M_PI / 2);
      const Eigen::Vector3d behind = e.start.p - (kPushFace + kPushClearance) * dir;
      const Eigen::Vector3d pushed = e.goal.p - kPushFace * dir;
      const Eigen::Vector3d up(0, 0, 1);
      expectPath({tcp(behind + kPushPrelift * up, yaw), tcp(behind, yaw), tcp(pushed, yaw),
                  tcp(pushed - kRetreat * dir + kRetreat * up, yaw)},
                 name);
      if (HasFailure()) return;
    }
  }

  YAML::Node root_;
  double table_ = 0.0, base_z_ = 0.0, min_margin_ = 0.0;
  double worst_margin_ = 1e9;
  std::unique_ptr<lfd::KinematicChain> chain_;
  std::unique_ptr<lfd::InverseKinematics> ik_;
  Eigen::VectorXd home_;
};

Eigen::Vector4d boundsOf(const std::vector<Entry>& list, bool goals) {
  Eigen::Vector4d b(1e9, -1e9, 1e9, -1e9);  // xmin xmax ymin ymax
  for (const auto& e : list) {
    const Eigen::Vector3d& p = goals ? e.goal.p : e.start.p;
    b << std::min(b[0], p.x()), std::max(b[1], p.x()), std::min(b[2], p.y()), std::max(b[3], p.y());
  }
  return b;
}

TEST_F(Tasks, CountsWorkspacesAndUnseenGoalsFollowTheProtocol) {
  struct Spec {
    std::string task, object, goal_key;
  };
  for (const Spec& s : {Spec{"grasp", "stick", "goal"}, Spec{"push", "box", "target"}}) {
    for (const std::string mode : {"sim", "teleop"}) {
      const auto demos = readList(root_[s.task][mode], s.object, s.goal_key);
      const auto unseen = readList(root_[s.task]["unseen"][mode], s.object, s.goal_key);
      const std::string what = s.task + "." + mode;
      if (s.task == "grasp") {
        EXPECT_EQ(demos.size(), 9u) << what;
      } else {
        EXPECT_GE(demos.size(), 6u) << what;
      }
      EXPECT_EQ(unseen.size(), 10u) << what;
      std::set<int> ids;
      for (const auto& e : demos) ids.insert(e.id);
      for (const auto& e : unseen) ids.insert(e.id);
      EXPECT_EQ(ids.size(), demos.size() + unseen.size()) << what << ": duplicate ids";
      // Workspace of the object starts: 40 x 40 cm (sim grasp), within 15 x 15 cm (teleop).
      const Eigen::Vector4d b = boundsOf(demos, false);
      const Eigen::Vector4d g = boundsOf(demos, true);
      if (mode == "teleop") {
        for (const Eigen::Vector4d& box : {b, g}) {
          EXPECT_LE(box[1] - box[0], 0.15 + 1e-9) << what;
          EXPECT_LE(box[3] - box[2], 0.15 + 1e-9) << what;
        }
      } else if (s.task == "grasp") {
        EXPECT_NEAR(b[1] - b[0], 0.40, 1e-9) << what;
        EXPECT_NEAR(b[3] - b[2], 0.40, 1e-9) << what;
      }
      // Unseen goals: inside the demonstrated ranges, and never a demonstrated situation.
      for (const auto& u : unseen) {
        for (const bool goal : {false, true}) {
          const Eigen::Vector3d& p = goal ? u.goal.p : u.start.p;
          const Eigen::Vector4d& box = goal ? g : b;
          EXPECT_TRUE(p.x() >= box[0] - 1e-9 && p.x() <= box[1] + 1e-9 && p.y() >= box[2] - 1e-9 &&
                      p.y() <= box[3] + 1e-9)
              << what << " unseen id " << u.id << (goal ? " goal" : " start")
              << " outside the demonstrated workspace";
        }
        for (const auto& d : demos)
          EXPECT_GT((u.start.p - d.start.p).norm() + (u.goal.p - d.goal.p).norm(), 0.02)
              << what << " unseen id " << u.id << " repeats demo " << d.id;
      }
    }
  }
}

TEST_F(Tasks, EveryGraspPathIsReachableWithMargin) {
  for (const std::string mode : {"sim", "teleop"}) {
    expectGraspReachable(readList(root_["grasp"][mode], "stick", "goal"), "grasp." + mode);
    expectGraspReachable(readList(root_["grasp"]["unseen"][mode], "stick", "goal"),
                         "grasp.unseen." + mode);
  }
  std::printf("grasp paths: smallest joint-limit margin %.3f rad\n", worst_margin_);
}

TEST_F(Tasks, EveryPushPathIsReachableWithMargin) {
  for (const std::string mode : {"sim", "teleop"}) {
    expectPushReachable(readList(root_["push"][mode], "box", "target"), "push." + mode);
    expectPushReachable(readList(root_["push"]["unseen"][mode], "box", "target"),
                        "push.unseen." + mode);
  }
  std::printf("push paths: smallest joint-limit margin %.3f rad\n", worst_margin_);
}

TEST_F(Tasks, ParkedObjectsAreOnTheTableAndOutOfTheWorkspace) {
  const Pose4 stick = readPose(root_["park"]["stick"]), box = readPose(root_["park"]["box"]);
  EXPECT_NEAR(stick.p.z(), table_ + 0.015, 1e-6);
  EXPECT_NEAR(box.p.z(), table_ + 0.04, 1e-6);
  EXPECT_GT(stick.p.y(), 0.05);
  EXPECT_GT(box.p.y(), 0.05);
  EXPECT_GT((stick.p - box.p).head<2>().norm(), 0.15);
}

TEST(TasksFile, IkRefusesAnUnreachableGoal) {
  // Guard for the executor: a goal far outside the workspace is reported, not silently clipped.
  const auto chain = lfd::KinematicChain::fromUrdfFile(kModelDir + "/jvrc1_like.urdf", "base_link",
                                                       "r_gripper_tcp");
  lfd::InverseKinematics ik(chain);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() << 1.2, -0.9, -0.05;
  EXPECT_FALSE(ik.reach(far, chain.midRange()).converged);
}

}  // namespace
