#!/usr/bin/python3
"""Reproduction of learned skill libraries toward the unseen goals of config/tasks.yaml, judged
physically (DESIGN.md "How we judge it").

  reproduce_goals.py --library-dir DIR [--mode sim] [--tasks grasp,push]
                     [--library-name '{task}_{mode}.json'] [--goals 100,101] [--duration-scale 1]
                     [--record-dir DIR] [--attach] [--out FILE.json]

Per goal: /bridge/reset (robot posture + objects), /bridge/set_scene (the task's object at its
start, the other objects parked), /executor/execute toward the goal; then the object's final pose
is judged with the task's criteria of config/evaluation.yaml `reproduction` (lfd_tools.judge).
Time ratio = executed time / mean demonstrated duration of the learned segments (same span).
Starts a private master with launch/reproduce.launch for the run, or with --attach uses the nodes
running at ROS_MASTER_URI (the pipeline's reproduce stage, which runs reproduce.launch once).
Writes {"<reproduction key>": {task: record}} (lfd_tools.report.reproduction_record; the key is
`reproduction` for sim, `reproduction_<mode>` otherwise) to --out, also after an error or Ctrl-C
with the goals done ("complete": false). Exit status 0 only if every goal was reached.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

from lfd_tools import config as lfd_config
from lfd_tools import judge, master, report

RECORDED_TOPICS = ["/joint_states", "/ee_pose", "/gripper/state", "/objects/stick/pose",
                   "/objects/box/pose", "/executor/planned_path", "/executor/executed_path",
                   "/executor/segment_markers"]
SETTLE_BEFORE_S = 0.3  # sim s after placing the objects, before executing
SETTLE_AFTER_S = 1.0   # sim s for the objects to come to rest before they are judged


def pose_of(entry):
    """geometry_msgs/Pose of a tasks.yaml [x, y, z, yaw]."""
    from geometry_msgs.msg import Point, Pose, Quaternion
    yaw = entry[3]
    return Pose(position=Point(*entry[:3]),
                orientation=Quaternion(w=math.cos(yaw / 2), x=0.0, y=0.0, z=math.sin(yaw / 2)))


def yaw_of(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


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


class BagRecording(object):
    """`rosbag record` of one reproduction (for snapshots and rviz replay); stopped by SIGINT so
    the bag is closed properly."""

    def __init__(self, path):
        self.path = path
        self.proc = subprocess.Popen(["rosbag", "record", "-q", "-O", path] + RECORDED_TOPICS,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     start_new_session=True)
        time.sleep(1.5)  # wall time for rosbag to subscribe before anything moves

    def stop(self):
        master.stop_group(self.proc, 20)
        return self.path if os.path.exists(self.path) else None


class Cell(object):
    """The simulated work cell and executor, through their services."""

    def __init__(self, tasks_cfg, evaluation):
        import rospy
        from lfd_msgs.srv import ExecuteTask, ResetSim, SetScene
        self.rospy, self.tasks, self.evaluation = rospy, tasks_cfg, evaluation
        master.wait_for_param("/use_sim_time", 120)  # rospy reads it once, at init
        self.srv = master.service_proxies("reproduce_goals", {
            "/executor/execute": ExecuteTask, "/bridge/reset": ResetSim, "/bridge/set_scene": SetScene})
        while rospy.Time.now().is_zero():
            time.sleep(0.05)

    def sleep_sim(self, seconds):
        end = self.rospy.Time.now() + self.rospy.Duration(seconds)
        while self.rospy.Time.now() < end and not self.rospy.is_shutdown():
            time.sleep(0.002)

    def set_scene(self, obj, start):
        r = self.srv["/bridge/reset"](joint_names=[], positions=[], reset_objects=True)
        if not r.success:
            raise RuntimeError("reset failed: " + r.message)
        others = [c["object"] for c in self.evaluation["reproduction"].values() if c["object"] != obj]
        s = self.srv["/bridge/set_scene"](object_names=[obj] + others,
                                          poses=[pose_of(start)] + [pose_of(self.tasks["park"][o]) for o in others])
        if not s.success:
            raise RuntimeError("set_scene failed: " + s.message)
        self.sleep_sim(SETTLE_BEFORE_S)

    def object_pose(self, name):
        from geometry_msgs.msg import PoseStamped
        return self.rospy.wait_for_message("/objects/%s/pose" % name, PoseStamped, timeout=30).pose

    def reproduce(self, task, entry, library, demo_duration, duration_scale, record_path=None):
        """One unseen goal: a goal record (report.goal_record)."""
        criteria = lfd_config.criteria_of(self.evaluation, task)
        start, goal = entry[criteria["object"]], entry["goal"] if "goal" in entry else entry["target"]
        self.set_scene(criteria["object"], start)
        recording = BagRecording(record_path) if record_path else None
        started = self.rospy.get_time()
        try:
            res = self.srv["/executor/execute"](library=library, object_pose=pose_of(start), goal=pose_of(goal),
                                                duration_scale=duration_scale, dry_run=False)
            self.sleep_sim(SETTLE_AFTER_S)
        finally:
            bag = recording.stop() if recording else None
        p = self.object_pose(criteria["object"])
        outcome = judge.physical_outcome(criteria, (p.position.x, p.position.y, p.position.z), goal[:3],
                                         self.tasks["table_top"], yaw_of(p.orientation), goal[3])
        g = report.goal_record(entry["id"], res, outcome, demo_duration=demo_duration)
        if bag:  # sim times at which each segment's streaming ended (snapshots per segment)
            t = started + max(0.0, res.execution_time - sum(res.segment_durations))
            g["bag"], g["segment_end_times_s"] = bag, []
            for d in res.segment_durations:
                t += d
                g["segment_end_times_s"].append(t)
        return g


def reproduce_task(cell, task, mode, library, goals, args, record):
    """Reproduces every goal of a task into `record` (updated after each goal)."""
    summary = library_summary(library)
    done = []
    for n, entry in enumerate(goals, 1):
        bag = (os.path.join(args.record_dir, "%s_%s_%d.bag" % (task, mode, entry["id"]))
               if args.record_dir and n == 1 else None)
        try:
            g = cell.reproduce(task, entry, library, summary[0], args.duration_scale, bag)
        except (RuntimeError, cell.rospy.ServiceException) as exc:
            if cell.rospy.is_shutdown():
                raise
            g = report.goal_record(entry["id"], error=str(exc))  # this goal failed; try the next
        done.append(g)
        record.clear()
        record.update(report.reproduction_record(library, summary, done))
        print("%-5s goal %3d (%d/%d): %-7s obj err %s  time ratio %s %s" % (
            task, g["id"], n, len(goals), "OK" if g["success"] else "FAILED",
            "-" if g["object_position_error_m"] is None else "%.1f mm" % (1e3 * g["object_position_error_m"]),
            "-" if g["time_ratio"] is None else "%.2f" % g["time_ratio"], g["error"]), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--library-dir", required=True)
    ap.add_argument("--library-name", default="{task}_{mode}.json", help="{task} and {mode} are replaced")
    ap.add_argument("--mode", default="sim", help="unseen goal set (sim | teleop)")
    ap.add_argument("--tasks", default="grasp,push")
    ap.add_argument("--goals", default="", help="comma-separated unseen ids (default all)")
    ap.add_argument("--duration-scale", type=float, default=1.0)
    ap.add_argument("--record-dir", default=None,
                    help="record the first goal of each task into a bag there (snapshots, rviz)")
    ap.add_argument("--out", default=None, help="default: <library-dir>/reproduction_<mode>.json")
    ap.add_argument("--attach", action="store_true",
                    help="use the nodes running at ROS_MASTER_URI (default: start a private master and the launch)")
    args = ap.parse_args()
    lib_dir = os.path.abspath(args.library_dir)
    out = args.out or os.path.join(lib_dir, "reproduction_%s.json" % args.mode)
    tasks_cfg, evaluation = lfd_config.load_tasks(), lfd_config.load_evaluation()
    wanted = {int(g) for g in args.goals.split(",") if g}
    key = report.reproduction_key(args.mode)
    results, status = {key: {}}, 0
    with report.written_on_exit(out, results):
        with master.graph_for_this_process(["lfd_launch", "reproduce.launch", "library_dir:=" + lib_dir], args.attach):
            cell = Cell(tasks_cfg, evaluation)
            for task in [t for t in args.tasks.split(",") if t]:
                record = results[key][task] = {}
                library = os.path.join(lib_dir, args.library_name.format(task=task, mode=args.mode))
                if not os.path.exists(library):
                    record.update(report.reproduction_record(library, (None, 0, 0), [],
                                                             "no skill library %s: learn it first" % library))
                    status = 1
                    continue
                goals = [e for e in tasks_cfg[task]["unseen"][args.mode] if not wanted or e["id"] in wanted]
                reproduce_task(cell, task, args.mode, library, goals, args, record)
                if not goals or record["successes"] < len(goals):
                    status = 1
    return status


if __name__ == "__main__":
    sys.exit(report.run_client(main))
