#!/usr/bin/python3
"""Reproduction of learned skill libraries toward the unseen goals of each task, judged physically
(DESIGN.md "How we judge it").

  reproduce_goals.py --library-dir DIR [--mode sim] [--tasks grasp,push]
                     [--library-name '{task}_{mode}.json'] [--goals 100,101] [--duration-scale 1]
                     [--record-dir DIR] [--real-time] [--attach] [--out FILE.json]

The scenes, the parked objects and what counts as success come from lfd_tools.tasks (nothing here
is task-specific; --tasks defaults to every task). Per goal: /bridge/reset (the articulated joints
at their start), /bridge/set_scene (the scene's objects at their start, the others parked), then
the executor's action /executor/execute (lfd_msgs/ExecuteTaskAction) with the scene and the goal;
what the task's success rules read is measured meanwhile (lfd_tools.bags.measure, as for a
demonstration) and judged by lfd_tools.judge.

Lockstep (default, lfd_tools.lockstep): the simulation is paused and stepped while the goal moves,
so a goal costs its physics and planning, not its duration in wall time, and runs the same
whatever the load. The executor knows no simulator: it follows sim time. --real-time leaves the
bridge running, paced at wall-clock time (real_time_factor 1, for watching in rviz). Time ratio =
executed time (sim) / mean demonstrated duration of the learned segments (same span).

Starts a private master with lfd_launch/reproduce.launch for the run, or with --attach uses the
nodes running at ROS_MASTER_URI (the pipeline's reproduce stage, which runs reproduce.launch once).
Writes {"<reproduction key>": {task: record}} (lfd_tools.report.reproduction_record; the key is
`reproduction` for sim, `reproduction_<mode>` otherwise) to --out, also after an error or Ctrl-C
with the goals done ("complete": false). Exit status 0 only if every goal was reached.
"""
import argparse
import itertools
import json
import os
import subprocess
import sys

from lfd_tools import bags, lockstep, master, report, reproduction, tasks


def library_summary(path):
    """(mean demonstrated duration s, demos, segments) of a skill library."""
    with open(path) as f:
        lib = json.load(f)
    spans = {}
    for seg in lib["segments"]:
        for d in seg["demos"]:
            lo, hi = spans.get(d["demo_id"], (float("inf"), -float("inf")))
            spans[d["demo_id"]] = (min(lo, d["start_time"]), max(hi, d["end_time"]))
    full = [hi - lo for lo, hi in spans.values()]
    return (sum(full) / len(full) if full else None), len(full), len(lib["segments"])


RECORDER_TIMEOUT_S = 30.0


class BagRecording(object):
    """`rosbag record` of one reproduction (for snapshots and rviz replay); stopped by SIGINT so
    the bag is closed properly."""
    count = itertools.count()

    def __init__(self, path, objects):
        self.path = path
        # A name of its own: a node taking a running node's name makes the master shut the
        # running one down.
        node = "lfd_goal_recorder_%d_%d" % (os.getpid(), next(BagRecording.count))
        topics = ["/joint_states", "/objects/joint_states", "/ee_pose", "/gripper/state",
                  bags.touch_topic(), "/executor/planned_path", "/executor/executed_path",
                  "/executor/segment_markers"]
        topics += ["/objects/%s/pose" % o for o in objects]
        self.proc = subprocess.Popen(["rosbag", "record", "-q", "-O", path] + topics
                                     + ["__name:=" + node],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     start_new_session=True)
        # Nothing moves before rosbag receives every published topic: a fixed 1.5 s wait missed
        # the first 5 s of a goal's motion on a loaded machine (lockstep does not wait for it).
        missing = master.wait_for_inbound("/" + node, topics, RECORDER_TIMEOUT_S, self.proc)
        if missing:
            print("warning: %s not connected to %s after %.0f s: the bag may miss the motion's "
                  "start" % (node, ", ".join(missing), RECORDER_TIMEOUT_S), file=sys.stderr)

    def stop(self):
        master.stop_group(self.proc, 20)
        return self.path if os.path.exists(self.path) else None


def reproduce(cell, task, scene, library, demo_duration, args, record_path=None):
    """One unseen scene: a goal record (report.goal_record), judged with the task's success rules
    on what was measured during and after the motion (as a demonstration is judged)."""
    recording = []

    def start_recording():  # once the scene is placed: the bag shows the motion, not the reset
        if record_path:
            recording.append(BagRecording(record_path,
                                          list(scene["objects"]) + list(tasks.parked(task))))

    try:
        res, wall, outcome = reproduction.execute_and_judge(
            cell, task, scene, library, args.duration_scale, args.allow_extrapolation,
            after_scene=start_recording)
    finally:
        bag = recording[0].stop() if recording else None
    g = report.goal_record(scene["id"], res, outcome, demo_duration=demo_duration, wall_time=wall)
    if bag and res.success:  # sim times at which each segment ended (snapshots per segment)
        t = res.motion_start.to_sec()
        g["bag"], g["segment_end_times_s"] = bag, []
        for d in res.segment_durations:
            t += d
            g["segment_end_times_s"].append(t)
    return g


def reproduce_task(cell, task, mode, library, scenes, args, record):
    """Reproduces every scene of a task into `record` (updated after each goal)."""
    summary = library_summary(library)
    done = []
    for n, scene in enumerate(scenes, 1):
        bag = (os.path.join(args.record_dir, "%s_%s_%d.bag" % (task, mode, scene["id"]))
               if args.record_dir and n == 1 else None)
        try:
            g = reproduce(cell, task, scene, library, summary[0], args, bag)
        except (RuntimeError, cell.rospy.ServiceException) as exc:
            if cell.rospy.is_shutdown():
                raise
            g = report.goal_record(scene["id"], error=str(exc))  # this goal failed; try the next
        done.append(g)
        record.clear()
        record.update(report.reproduction_record(library, summary, done))
        print("%-5s goal %3d (%d/%d): %-7s obj err %s  time ratio %s  wall %s %s" % (
            task, g["id"], n, len(scenes), "OK" if g["success"] else "FAILED",
            ("-" if g["object_position_error_m"] is None
             else "%.1f mm" % (1e3 * g["object_position_error_m"])),
            "-" if g["time_ratio"] is None else "%.3f" % g["time_ratio"],
            "-" if g["wall_time_s"] is None else "%.1f s" % g["wall_time_s"],
            g["error"] or ("" if g["success"] else g["judged"])), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--library-dir", required=True)
    ap.add_argument("--library-name", default="{task}_{mode}.json",
                    help="{task} and {mode} are replaced")
    ap.add_argument("--mode", default="sim", help="unseen goal set (sim | teleop)")
    ap.add_argument("--tasks", default=None, help="comma-separated (default: every task)")
    ap.add_argument("--goals", default="", help="comma-separated unseen ids (default all)")
    ap.add_argument("--duration-scale", type=float, default=1.0)
    ap.add_argument("--allow-extrapolation", action="store_true",
                    help="run goals outside the demonstrated range (reported either way)")
    ap.add_argument("--record-dir", default=None,
                    help="record the first goal of each task into a bag there (snapshots, rviz)")
    ap.add_argument("--real-time", action="store_true",
                    help="do not step the simulation: it runs on its own (launch it with "
                         "real_time_factor:=1)")
    ap.add_argument("--out", default=None, help="default: <library-dir>/reproduction_<mode>.json")
    ap.add_argument("--attach", action="store_true",
                    help="use the nodes running at ROS_MASTER_URI (default: start a private master "
                         "and the launch)")
    args = ap.parse_args()
    lib_dir = os.path.abspath(args.library_dir)
    out = args.out or os.path.join(lib_dir, "reproduction_%s.json" % args.mode)
    names = [t for t in args.tasks.split(",") if t] if args.tasks else tasks.names()
    wanted = {int(g) for g in args.goals.split(",") if g}
    scenes = {}
    for t in names:
        try:
            scenes[t] = [s for s in tasks.unseen_scenes(t, args.mode)
                         if not wanted or s["id"] in wanted]
        except (KeyError, TypeError) as exc:
            raise RuntimeError("task %s has no unseen %s scenes (%s: %s)"
                               % (t, args.mode, type(exc).__name__, exc))
    key = report.reproduction_key(args.mode)
    results, status = {key: {}}, 0
    launch = ["lfd_launch", "reproduce.launch", "library_dir:=" + lib_dir]
    if args.real_time:
        launch.append("real_time_factor:=1.0")
    with report.written_on_exit(out, results):
        with master.graph_for_this_process(launch, args.attach):
            cell = lockstep.Cell(lockstep=not args.real_time, node_name="reproduce_goals")
            for task in names:
                record = results[key][task] = {}
                library = os.path.join(lib_dir, args.library_name.format(task=task, mode=args.mode))
                if not os.path.exists(library):
                    record.update(report.reproduction_record(
                        library, (None, 0, 0), [], "no skill library %s: learn it first" % library))
                    status = 1
                    continue
                reproduce_task(cell, task, args.mode, library, scenes[task], args, record)
                if not scenes[task] or record["successes"] < len(scenes[task]):
                    status = 1
    return status


if __name__ == "__main__":
    sys.exit(report.run_client(main))
