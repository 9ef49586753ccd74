#!/usr/bin/python3
"""Where the wall time of reproducing goals goes, between the simulated steps.

  profile_reproduction.py --library-dir DIR [--mode sim] [--tasks grasp,wipe] [--goals 2]
                          [--attach] [--json FILE] [--update-docs]

Reproduces the first `--goals` unseen goals of each task in lockstep, as the reproduce stage does
(reproduce.launch: bridge, executor, robot_state_publisher; lfd_tools.reproduction), and breaks
each goal's wall time down by what the lockstep client was doing (lfd_tools.lockstep.Cell.timed):
  scene_calls   the bridge's reset and set_scene services
  planning      from sending the goal until the executor's feedback says the motion is sent (the
                executor's planning, the action's round trips)
  motion        stepping the goal to its end; of it, motion_step_calls is the /bridge/step round
                trips (physics, publishing, sockets) and the rest the client's loop and the
                action's status traffic
  judge_waits   waiting for the last sensor messages before judging; judging: the task's rules
Settling before and after the motion is stepped too (step_calls outside `motion`). Also prints the
CPU time of every process of the graph (from /proc). Run after `./lfd build` with
devel/setup.bash sourced, on a skill library the learn stage wrote. --update-docs rewrites
docs/results.md's section profile-reproduction from the figures (lfd_tools.results_doc).
"""
import json
import os
import sys
import time

from lfd_tools import master, reproduction, report, results_doc, tasks
from lfd_tools.lockstep import Cell
from lfd_tools.processes import CpuSampler


def profile_goals(cell, lib_dir, mode, names, goals):
    """[{task, goal, wall_s, sim_s, parts, calls, success}] of every goal reproduced."""
    rows = []
    for task in names:
        library = os.path.join(lib_dir, "%s_%s.json" % (task, mode))
        for scene in tasks.unseen_scenes(task, mode)[:goals]:
            cell.take_wall()
            started, sim_start = time.perf_counter(), cell.now()
            try:
                _, _, outcome = reproduction.execute_and_judge(cell, task, scene, library)
                success = bool(outcome.get("success"))
            except RuntimeError as exc:
                print("%s goal %d: %s" % (task, scene["id"], exc), flush=True)
                success = False
            wall = time.perf_counter() - started
            parts, calls = cell.take_wall()
            rows.append({"task": task, "goal": scene["id"], "wall_s": wall,
                         "sim_s": cell.now() - sim_start, "parts": parts, "calls": calls,
                         "success": success})
            print("%-7s goal %3d  %5.1f s sim in %5.2f s wall  %s" % (
                task, scene["id"], rows[-1]["sim_s"], wall,
                "ok" if success else "FAILED"), flush=True)
    return rows


def show(rows, cpu):
    summary, parts = results_doc.reproduction_profile(rows)
    print(summary)
    for name, seconds, share in parts:
        print("  %-44s %6.2f s" % (name, seconds) + ("" if share is None else "  %5.1f%%" % share))
    print("CPU by process (user + system) over the whole run:")
    for name, (user, system) in cpu.items():
        if user + system >= 0.05:
            print("  %-24s %6.2f + %6.2f s" % (name, user, system))


def main():
    ap = reproduction.goal_bench_parser(__doc__, goals=2)
    ap.add_argument("--json", default=None)
    ap.add_argument("--update-docs", action="store_true",
                    help="rewrite docs/results.md's section profile-reproduction from the figures")
    args = ap.parse_args()
    if args.update_docs:
        results_doc.check("profile-reproduction")
    lib_dir = os.path.abspath(args.library_dir)
    names = reproduction.selected_tasks(args.tasks)
    sampler = CpuSampler(os.getpid())
    sampler.start()
    with master.graph_for_this_process(["lfd_launch", "reproduce.launch",
                                        "library_dir:=" + lib_dir], args.attach):
        rows = profile_goals(Cell(node_name="profile_reproduction"), lib_dir, args.mode,
                             names, args.goals)
        sampler.stop()  # before the graph goes down with its CPU readings
    cpu = sampler.by_name()
    show(rows, cpu)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"goals": rows, "cpu_s": cpu}, f, indent=1)
    if args.update_docs:
        results_doc.report_update("profile-reproduction", {"goals": rows, "cpu_s": cpu})
    return 0


if __name__ == "__main__":
    sys.exit(report.run_client(main))
