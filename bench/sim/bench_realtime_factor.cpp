// Real-time factor of the full workcell scene, headless, 1 ms steps:
//   plain     mj_step on the MJCF as written (its own position actuators, constant ctrl)
//   workcell  lfd_sim::WorkcellSim::step: targets, rate/position/effort limits, gravity
//             feed-forward, divergence checks
//   +sensors  workcell plus readState() at the bridge's publish rate (every 5 steps = 200 Hz)
//   +traj     as +sensors while a trajectory sweeps the right arm (contacts-free motion)
// Usage: bench_realtime_factor [sim_seconds=10] [repeats=3] [model=LFD_SIM_MODEL_DIR/workcell.xml,
// jvrc1_description] Prints the best of `repeats` runs per variant (least disturbed by other
// processes).
#include <mujoco/mujoco.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

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

lfd_sim::WorkcellConfig benchConfig() {
  lfd_sim::WorkcellConfig c;
  c.initial_posture = {
      {"R_SHOULDER_P", -0.3}, {"R_ELBOW_P", -1.3}, {"R_WRIST_Y", 1.4}, {"R_GRIPPER", 0.03}};
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::string model = argc > 3 ? argv[3] : std::string(LFD_SIM_MODEL_DIR) + "/workcell.xml";
  if (!(seconds > 0) || repeats < 1) {
    std::fprintf(stderr, "usage: %s [sim_seconds>0] [repeats>=1] [model]\n", argv[0]);
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
    lfd_sim::WorkcellSim sim(model, benchConfig(), quiet);
    return seconds / wallSeconds([&] { sim.step(static_cast<int>(steps)); });
  });

  const double with_sensors = best(repeats, [&] {
    lfd_sim::WorkcellSim sim(model, benchConfig(), quiet);
    lfd_sim::WorkcellState state;
    return seconds / wallSeconds([&] {
             for (long k = 1; k <= steps; ++k) {
               sim.step();
               if (k % 5 == 0) sim.readState(&state);
             }
           });
  });

  const double with_trajectory = best(repeats, [&] {
    lfd_sim::WorkcellSim sim(model, benchConfig(), quiet);
    lfd_sim::JointTrajectory traj{{"R_SHOULDER_Y", "R_ELBOW_Y"}, {}};
    for (int i = 1; i <= 10; ++i) {
      const double sign = (i % 2) ? 1.0 : -1.0;
      traj.points.push_back({seconds * i / 10.0, {0.6 * sign, -0.5 * sign}, {}});
    }
    sim.setTrajectory(traj);
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
