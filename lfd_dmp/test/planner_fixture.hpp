// The executor tests' shared world (test_executor, test_recovery): the JVRC-1-like arm's chain and
// home posture, a "reach then carry" library of three min-jerk demos, and the planner fixture.
#pragma once

#include "lfd_dmp/executor.hpp"
#include "lfd_dmp/skill_learner.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace lfd_test {

// From CMake, not __FILE__: ccache (CCACHE_BASEDIR) makes __FILE__ relative to the build tree.
inline const std::string kUrdf = std::string(LFD_ROBOT_DIR) + "/models/jvrc1_like.urdf";

inline lfd::KinematicChain chain() {
  return lfd::KinematicChain::fromUrdfFile(kUrdf, "base_link", "r_gripper_tcp");
}

// robot.yaml (jvrc1_description) preferred posture (TCP fingers-down above the workspace centre).
inline Eigen::VectorXd homePosture(const lfd::KinematicChain& c) {
  const std::map<std::string, double> p = {
      {"WAIST_Y", 0.08},       {"WAIST_P", 0.24},       {"R_SHOULDER_P", -0.72},
      {"R_SHOULDER_R", -0.23}, {"R_SHOULDER_Y", -0.06}, {"R_ELBOW_P", -1.02},
      {"R_ELBOW_Y", -0.19},    {"R_WRIST_R", 0.09},     {"R_WRIST_Y", 1.51}};
  Eigen::VectorXd q = Eigen::VectorXd::Zero(c.dof());
  for (int i = 0; i < c.dof(); ++i)
    if (p.count(c.jointNames()[i])) q[i] = p.at(c.jointNames()[i]);
  return q;
}

inline double minJerk(double u) {
  return u * u * u * (10 - 15 * u + 6 * u * u);
}

// A min-jerk segment between two points with a gripper ramp from g0 to g1.
inline lfd::SegmentDmp learnSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Quaterniond& q, double g0, double g1, double T) {
  const int m = 200;
  lfd::SegmentDemo d;
  d.times.resize(m);
  d.positions.resize(m, 3);
  d.quaternions.resize(m, 4);
  d.gripper.resize(m);
  for (int k = 0; k < m; ++k) {
    const double u = static_cast<double>(k) / (m - 1);
    d.times[k] = u * T;
    d.positions.row(k) = (a + minJerk(u) * (b - a)).transpose();
    d.quaternions.row(k) << q.w(), q.x(), q.y(), q.z();
    d.gripper[k] = g0 + minJerk(u) * (g1 - g0);
  }
  lfd::DmpParameters params;
  params.num_basis = 20;
  return lfd::SegmentDmp::learn(d, params);
}

// A two-segment library: demo j moves home -> via[j] in t0 s (gripper g0 -> g1), then
// via[j] -> end[j] in t1 s (gripper held at g1).
struct TwoSegmentTask {
  std::string task, first, second;
  double g0 = 0.0, g1 = 0.0, t0 = 2.0, t1 = 2.5;
};
inline lfd_dmp::SkillLibrary twoSegmentLibrary(const TwoSegmentTask& spec,
                                               const lfd_dmp::TcpPose& home,
                                               const std::vector<Eigen::Vector3d>& via,
                                               const std::vector<Eigen::Vector3d>& end) {
  lfd_dmp::SkillLibrary lib;
  lib.task = spec.task;
  lib.segments.resize(2);
  lib.segments[0].name = spec.first;
  lib.segments[1].name = spec.second;
  for (size_t j = 0; j < via.size(); ++j) {
    for (int s = 0; s < 2; ++s) {
      lfd_dmp::DemoSkill d;
      d.demo_id = spec.task + "_" + std::to_string(j);
      d.dmp = s == 0
                  ? learnSegment(home.position, via[j], home.orientation, spec.g0, spec.g1, spec.t0)
                  : learnSegment(via[j], end[j], home.orientation, spec.g1, spec.g1, spec.t1);
      d.parameters = lfd::goalParameters(d.dmp);
      lib.dmp_parameters = d.dmp.params;
      lib.segments[s].demos.push_back(d);
    }
  }
  return lib;
}

// Three demos of a two-segment "reach then carry" task around the home TCP pose; the gripper
// closes during the first segment.
inline lfd_dmp::SkillLibrary library(const lfd_dmp::TcpPose& home) {
  const Eigen::Vector3d offsets[3] = {
      {0.05, -0.05, -0.04}, {-0.05, -0.03, -0.05}, {0.0, 0.06, -0.045}};
  std::vector<Eigen::Vector3d> grasp, goal;
  for (int j = 0; j < 3; ++j) {
    grasp.push_back(home.position + offsets[j]);
    goal.push_back(grasp.back() + Eigen::Vector3d(-0.04 * j, 0.05, 0.12));
  }
  return twoSegmentLibrary({"grasp", "approach", "move", 0.04, 0.015, 2.0, 2.5}, home, grasp, goal);
}

// The planner's IK: the chain with default options, pulled toward the home posture.
inline lfd::CartesianToJoints converter(const lfd::KinematicChain& chain,
                                        const Eigen::VectorXd& home) {
  lfd::CartesianToJoints ik(chain);
  ik.setPreferredPosture(home);
  return ik;
}

class PlannerTest : public ::testing::Test {
 protected:
  PlannerTest() : chain_(chain()), q0_(homePosture(chain_)), planner_(converter(chain_, q0_)) {
    home_ = planner_.forward(q0_);
    lib_ = library(home_);
  }
  lfd_dmp::SegmentTarget target(const std::string& name, const Eigen::Vector3d& p) const {
    lfd_dmp::SegmentTarget t;
    t.name = name;
    t.goal.position = p;
    t.goal.orientation = home_.orientation;
    return t;
  }
  std::vector<lfd_dmp::SegmentTarget> targets(const Eigen::Vector3d& grasp,
                                              const Eigen::Vector3d& goal) const {
    return {target("approach", grasp), target("move", goal)};
  }
  // The reach-then-carry goals most tests plan toward, and their options (dt 4 ms).
  Eigen::Vector3d grasp() const { return home_.position + Eigen::Vector3d(0.02, 0.0, -0.045); }
  Eigen::Vector3d goal() const { return grasp() + Eigen::Vector3d(-0.03, 0.05, 0.12); }
  static lfd_dmp::ExecutorOptions coarse() {
    lfd_dmp::ExecutorOptions opt;
    opt.dt = 0.004;
    return opt;
  }
  lfd::KinematicChain chain_;
  Eigen::VectorXd q0_;
  lfd_dmp::TaskPlanner planner_;
  lfd_dmp::TcpPose home_;
  lfd_dmp::SkillLibrary lib_;
};

}  // namespace lfd_test
