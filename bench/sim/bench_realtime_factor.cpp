// Real-time factor of the full workcell scene, headless, 1 ms steps:
//   plain     mj_step on the MJCF as written (its own position actuators, constant ctrl)
//   workcell  lfd_sim::WorkcellSim::step: targets, rate/position/effort limits, gravity
//             feed-forward, divergence checks
//   +sensors  workcell plus readState() at the bridge's publish rate (every 5 steps = 200 Hz)
//   +traj     as +sensors while a trajectory sweeps every joint of the robot file's ready posture
//             but the gripper by +-0.05 rad (a contact-free motion of the whole arm)
// Usage: bench_realtime_factor [sim_seconds=10] [repeats=3] [model=LFD_SIM_MODEL_DIR/workcell.xml]
//                              [robot_file=LFD_ROBOT_FILE] (the default robot's; another robot:
// its workcell.xml and config/robot.yaml). Prints the best of `repeats` runs per variant (least
// disturbed by other processes).
#include <mujoco/mujoco.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "lfd_core/kinematics/robot_setup.hpp"
#include "lfd_sim_bridge/workcell_sim.hpp"

namespace {

double wallSeconds(const std::function<void()>& run) {
  const auto start = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double best(int repeats, const std::function<double()>& one_run) {
  double best_rtf = 0.0;
  for (int r = 0; r < repeats; ++r) best_rtf = std::max(best_rtf, one_run());
  return best_rtf;
}

lfd_sim::WorkcellConfig benchConfig(const lfd::RobotSetup& robot) {
  lfd_sim::WorkcellConfig c;
  c.initial_posture = robot.initial_posture;
  return c;
}

// Ten waypoints alternating +-0.05 rad about the ready posture on every joint but the gripper's.
lfd_sim::JointTrajectory sweep(const lfd::RobotSetup& robot, double seconds) {
  lfd_sim::JointTrajectory traj;
  std::vector<double> ready;
  for (const auto& [joint, value] : robot.initial_posture) {
    if (joint == robot.gripper.joint) continue;
    traj.joint_names.push_back(joint);
    ready.push_back(value);
  }
  for (int i = 1; i <= 10; ++i) {
    std::vector<double> q = ready;
    for (double& v : q) v += (i % 2 ? 0.05 : -0.05);
    traj.points.push_back({seconds * i / 10.0, q, {}});
  }
  return traj;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::string model = argc > 3 ? argv[3] : std::string(LFD_SIM_MODEL_DIR) + "/workcell.xml";
  const lfd::RobotSetup robot = lfd::loadRobotSetup(argc > 4 ? argv[4] : LFD_ROBOT_FILE);
  if (!(seconds > 0) || repeats < 1) {
    std::fprintf(stderr, "usage: %s [sim_seconds>0] [repeats>=1] [model] [robot_file]\n", argv[0]);
    return 2;
  }

  char error[1024] = "";
  mjModel* m = mj_loadXML(model.c_str(), nullptr, error, sizeof(error));
  if (!m) {
    std::fprintf(stderr, "cannot load %s: %s\n", model.c_str(), error);
    return 1;
  }
  const double dt = m->opt.timestep;
  const long steps = std::lround(seconds / dt);
  std::printf("model %s: nq %d nv %d nu %d, dt %.4f s, %ld steps per run, best of %d\n",
              model.c_str(), m->nq, m->nv, m->nu, dt, steps, repeats);

  const double plain = best(repeats, [&] {
    mjData* d = mj_makeData(m);
    for (int i = 0; i < m->nu; ++i) d->ctrl[i] = d->qpos[m->jnt_qposadr[m->actuator_trnid[2 * i]]];
    const double wall = wallSeconds([&] {
      for (long k = 0; k < steps; ++k) mj_step(m, d);
    });
    mj_deleteData(d);
    return seconds / wall;
  });
  mj_deleteModel(m);

  auto quiet = [](lfd_sim::LogLevel, const std::string&) {};
  const double workcell = best(repeats, [&] {
    lfd_sim::WorkcellSim sim(model, benchConfig(robot), quiet);
    return seconds / wallSeconds([&] { sim.step(static_cast<int>(steps)); });
  });

  const double with_sensors = best(repeats, [&] {
    lfd_sim::WorkcellSim sim(model, benchConfig(robot), quiet);
    lfd_sim::WorkcellState state;
    return seconds / wallSeconds([&] {
             for (long k = 1; k <= steps; ++k) {
               sim.step();
               if (k % 5 == 0) sim.readState(&state);
             }
           });
  });

  const double with_trajectory = best(repeats, [&] {
    lfd_sim::WorkcellSim sim(model, benchConfig(robot), quiet);
    sim.setTrajectory(sweep(robot, seconds));
    lfd_sim::WorkcellState state;
    return seconds / wallSeconds([&] {
             for (long k = 1; k <= steps; ++k) {
               sim.step();
               if (k % 5 == 0) sim.readState(&state);
             }
           });
  });

  std::printf("%-34s %8s %10s\n", "variant", "RTF", "vs plain");
  auto row = [&](const char* name, double rtf) {
    std::printf("%-34s %7.2fx %9.1f%%\n", name, rtf, 100.0 * rtf / plain);
  };
  row("plain mj_step", plain);
  row("workcell step (control+limits)", workcell);
  row("  + readState at 200 Hz", with_sensors);
  row("  + arm trajectory", with_trajectory);
  std::printf("target: >= 10x real time for the bridge\n");
  return 0;
}
