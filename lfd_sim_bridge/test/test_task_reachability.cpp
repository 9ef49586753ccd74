// Every task file (config/tasks/*.yaml) follows the protocol -- counts, unseen goals inside the
// demonstrated range and different from every demonstration, parked objects out of the way -- and
// every path the demonstrator plans for any of its scenes, demonstrated or unseen, sim or teleop,
// whatever the per-demo variation draws, is reachable by the IK of each robot's robot file
// (jvrc1_description: the humanoid, arm7_description: the 7-DoF arm) along a continuous branch with
// margin from the joint limits (as the demonstrator converts it).
#include <gtest/gtest.h>

#include <dirent.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/demo_plan.hpp"

namespace demo = lfd_sim_bridge::demo;
namespace task = lfd_sim_bridge::task;

namespace {

const std::string kConfig = std::string(LFD_CONFIG_DIR) + "/";

// One robot description package: its robot file and its URDF.
struct RobotCase {
  std::string name;
  std::string dir;   // the package's folder (models/, config/robot.yaml)
  std::string urdf;  // URDF file name in models/
  std::string robotFile() const { return dir + "/config/robot.yaml"; }
  std::string urdfPath() const { return dir + "/models/" + urdf; }
};

std::ostream& operator<<(std::ostream& os, const RobotCase& r) {
  return os << r.name;
}

const std::vector<RobotCase> kRobots = {{"jvrc1", LFD_JVRC1_ROBOT_DIR, "jvrc1_like.urdf"},
                                        {"arm7", LFD_ARM7_ROBOT_DIR, "arm7.urdf"}};

std::vector<std::string> taskNames() {
  std::vector<std::string> names;
  if (DIR* d = opendir((kConfig + "tasks").c_str())) {
    while (dirent* e = readdir(d)) {
      const std::string f = e->d_name;
      if (f.size() > 5 && f.substr(f.size() - 5) == ".yaml")
        names.push_back(f.substr(0, f.size() - 5));
    }
    closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The task files themselves (robot-independent).
class TaskFiles : public ::testing::Test {
 protected:
  void SetUp() override { scene_ = task::loadScene(kConfig + "scene.yaml"); }
  task::Scene scene_;
};

// Per-task tally of the reachability check.
struct TaskTally {
  size_t paths = 0, samples = 0;
  double worst_margin = 1e9;
};

// The task files on one robot.
class TaskReach : public ::testing::TestWithParam<RobotCase> {
 protected:
  void SetUp() override {
    scene_ = task::loadScene(kConfig + "scene.yaml");
    robot_ = lfd::loadRobotSetup(GetParam().robotFile());
    std::ifstream f(GetParam().urdfPath());
    urdf_.assign(std::istreambuf_iterator<char>(f), {});
    ASSERT_FALSE(urdf_.empty()) << GetParam().urdfPath();
    min_margin_ = YAML::LoadFile(GetParam().robotFile())["ik"]["min_limit_margin"].as<double>();
    world_from_base_.translation() = scene_.base_in_world;
  }

  // The demonstrator's start: the robot file's ready posture.
  Eigen::VectorXd ready(const lfd::KinematicChain& chain) const {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(chain.dof());
    for (const auto& [joint, value] : robot_.initial_posture) {
      const int i = chain.jointIndex(joint);
      if (i >= 0) q[i] = value;
    }
    return q;
  }

  // Plans and converts one scene's demonstration like the demonstrator; every sample within the
  // IK tolerance (convert throws otherwise), the margin kept, no jump between samples.
  void expectReachable(const task::TaskDefinition& t, const task::Configuration& c, bool teleop,
                       uint32_t seed, const std::string& what, TaskTally* tally) {
    demo::TeleopStyle style;
    style.enabled = teleop;
    const demo::TaskInterpreter in(t, scene_, robot_.gripper, demo::ToolGeometry{}, style);
    lfd::CartesianToJoints converter = lfd::makeCartesianToJoints(urdf_, robot_);
    const lfd::KinematicChain& chain = converter.chain();
    Eigen::VectorXd q = ready(chain);
    const demo::Pose start = converter.forward(q);
    std::mt19937 rng(seed);
    const demo::DemoPlan plan = in.planAll(in.begin(c, world_from_base_, start, 1.0, rng));
    demo::Pose from = start;
    ++tally->paths;
    for (const demo::Phase& phase : plan.phases) {
      lfd::JointPath path;
      try {
        path = converter.convert(demo::samplePhase(from, phase, 0.02, 0.0), q);
      } catch (const std::exception& e) {
        ADD_FAILURE() << what << " phase " << phase.name << ": " << e.what();
        return;
      }
      tally->samples += path.positions.size();
      for (size_t k = 0; k < path.positions.size(); ++k) {
        const double margin = chain.limitMargin(path.positions[k]);
        worst_margin_ = std::min(worst_margin_, margin);
        tally->worst_margin = std::min(tally->worst_margin, margin);
        if (margin < min_margin_) {
          int worst = 0;
          (path.positions[k] - chain.lowerLimits())
              .cwiseMin(chain.upperLimits() - path.positions[k])
              .minCoeff(&worst);
          ADD_FAILURE() << what << " phase " << phase.name << " sample " << k << ": "
                        << chain.jointNames()[worst] << " only " << margin << " rad from its limit";
          return;
        }
        if (k > 0 && (phase.index > 0 || k > 5))  // the first move from the ready posture may swing
          ASSERT_LT((path.positions[k] - path.positions[k - 1]).cwiseAbs().maxCoeff(), 0.25)
              << what << " phase " << phase.name << " sample " << k << " jumps";
      }
      q = path.positions.back();
      from = phase.segments.back().target;
    }
  }

  task::Scene scene_;
  lfd::RobotSetup robot_;
  std::string urdf_;
  double min_margin_ = 0.0, worst_margin_ = 1e9;
  Eigen::Isometry3d world_from_base_ = Eigen::Isometry3d::Identity();
};

// Horizontal bounds (x min, x max, y min, y max) of the scenes' poses of `key` (an object or goal).
Eigen::Vector4d boundsOf(const std::vector<task::Configuration>& list, const std::string& key) {
  Eigen::Vector4d b(1e9, -1e9, 1e9, -1e9);
  for (const auto& c : list) {
    const Eigen::Vector3d& p = key == "goal" ? c.goal.position : c.objects.at(key).position;
    b << std::min(b[0], p.x()), std::max(b[1], p.x()), std::min(b[2], p.y()), std::max(b[3], p.y());
  }
  return b;
}

TEST_F(TaskFiles, TheShippedTasksAreThere) {
  const std::vector<std::string> names = taskNames();
  for (const char* t : {"drawer", "grasp", "place", "push", "wipe"})
    EXPECT_TRUE(std::count(names.begin(), names.end(), t)) << t;
}

TEST_F(TaskFiles, CountsAndUnseenGoalsFollowTheProtocol) {
  for (const std::string& name : taskNames()) {
    const task::TaskDefinition t =
        task::loadTask(task::taskFilePath(kConfig + "tasks", name), scene_);
    for (const std::string mode : {"sim", "teleop"}) {
      const auto& demos = t.configurations.at(mode);
      const auto& unseen = t.unseen.at(mode);
      const std::string what = name + "." + mode;
      EXPECT_GE(demos.size(), mode == "sim" ? 9u : 6u) << what;
      EXPECT_EQ(unseen.size(), 10u) << what;
      std::vector<std::string> keys = t.objects;
      keys.push_back("goal");
      for (const std::string& key : keys) {
        const Eigen::Vector4d b = boundsOf(demos, key);
        if (mode == "teleop") {  // the teleop-like workspace: at most 15 x 15 cm
          EXPECT_LE(b[1] - b[0], 0.15 + 1e-9) << what << " " << key;
          EXPECT_LE(b[3] - b[2], 0.15 + 1e-9) << what << " " << key;
        }
        for (const auto& u : unseen) {  // inside the demonstrated range
          const Eigen::Vector3d& p = key == "goal" ? u.goal.position : u.objects.at(key).position;
          EXPECT_TRUE(p.x() >= b[0] - 1e-9 && p.x() <= b[1] + 1e-9 && p.y() >= b[2] - 1e-9 &&
                      p.y() <= b[3] + 1e-9)
              << what << " unseen id " << u.id << " " << key << " outside the demonstrated range";
        }
      }
      for (const auto& u : unseen)  // never a demonstrated situation
        for (const auto& d : demos) {
          double distance = (u.goal.position - d.goal.position).norm();
          for (const std::string& o : t.objects)
            distance += (u.objects.at(o).position - d.objects.at(o).position).norm();
          EXPECT_GT(distance, 0.02) << what << " unseen id " << u.id << " repeats demo " << d.id;
        }
    }
  }
}

TEST_P(TaskReach, EveryPlannedPathIsReachableWithMargin) {
  std::map<std::string, TaskTally> tallies;
  for (const std::string& name : taskNames()) {
    const task::TaskDefinition t =
        task::loadTask(task::taskFilePath(kConfig + "tasks", name), scene_);
    TaskTally& tally = tallies[name];
    for (const std::string mode : {"sim", "teleop"}) {
      for (const auto* list : {&t.configurations.at(mode), &t.unseen.at(mode)}) {
        for (const task::Configuration& c : *list) {
          for (uint32_t seed : {1u, 2u}) {  // the per-demo variation and the operator's draws
            expectReachable(
                t, c, mode == "teleop", seed,
                GetParam().name + ": " + name + "." + mode + " id " + std::to_string(c.id), &tally);
            if (HasFailure()) return;
          }
        }
      }
    }
  }
  for (const auto& [name, tally] : tallies)
    std::printf("%s %s: %zu paths, %zu IK samples, smallest joint-limit margin %.3f rad\n",
                GetParam().name.c_str(), name.c_str(), tally.paths, tally.samples,
                tally.worst_margin);
  std::printf("%s task paths: smallest joint-limit margin %.3f rad\n", GetParam().name.c_str(),
              worst_margin_);
}

TEST_F(TaskFiles, ParkedObjectsAreOnTheTableAndOutOfTheWorkspace) {
  for (const task::SceneObject& o : scene_.objects) {
    const Eigen::Vector3d& p = o.park.position;
    EXPECT_GT(p.y(), 0.05) << o.name;  // left of the work area (y < -0.05)
    EXPECT_NEAR(p.z(), scene_.table_top + (o.fixed ? 0.0 : o.half_size.z()), 1e-9) << o.name;
    for (const task::SceneObject& other : scene_.objects) {
      if (&other == &o) continue;
      const double gap = (p - other.park.position).head<2>().cwiseAbs().maxCoeff() -
                         o.half_size.head<2>().maxCoeff() - other.half_size.head<2>().maxCoeff();
      EXPECT_GT(gap, 0.02) << o.name << " and " << other.name << " parked on each other";
    }
  }
}

TEST_P(TaskReach, IkRefusesAnUnreachableGoal) {
  // Guard for the executor: a goal far outside the workspace is reported, not silently clipped.
  const auto chain =
      lfd::KinematicChain::fromUrdfFile(GetParam().urdfPath(), robot_.base_link, robot_.tip_link);
  lfd::InverseKinematics ik(chain);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() << 1.2, -0.9, -0.05;
  EXPECT_FALSE(ik.reach(far, chain.midRange()).converged);
}

INSTANTIATE_TEST_SUITE_P(Robots, TaskReach, ::testing::ValuesIn(kRobots),
                         [](const auto& info) { return info.param.name; });

}  // namespace
