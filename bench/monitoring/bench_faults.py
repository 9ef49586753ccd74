#!/usr/bin/env python3
"""Execution monitoring against injected faults (docs/results.md, "Detection"): how many faults the
executor's monitor raises, how soon after the fault, and how well its anomaly score separates
faulty runs from nominal ones (ROC AUC).

Every goal runs once as it is (nominal) and once per fault that applies to its task, in MuJoCo
through the bridge's /bridge/inject_fault (sim only). Nothing is chosen per task: the faults are
derived from the skill library and the task file.
  object_removed  the object of the first segment's goal frame goes to its park pose (config
                  scene.yaml) halfway through that segment: the hand reaches for nothing.
  grip_lost       the grip's force drops to 0 at 30% of the first segment whose demonstrations
                  hold something (the pads loaded over most of it, from the sensory signature).
  sensors_frozen  every sensor row of the signature repeats its reading from 0.3 s into the motion
                  (a stale driver); detected only where the demonstrations sensed a change later.
  sensors_silenced  every sensor row of the signature stops publishing at 30% of the first segment
                  (a dead driver).
  joint_locked    each scene joint of the task (the drawer's slide) is stuck from the start.
And two cases of goals that follow a moving object (executor.yaml follow_objects/*: the goal gives
each object's pose in the object's own tf frame), counted apart from the faults ("following"):
  nominal_followed  the nominal goal, its objects followed: nothing moves, nothing may be replanned.
  object_moved    the object of the first segment's goal frame is shoved 3-8 cm (horizontally,
                  distance and direction drawn per goal, seeded by its id) at 30% of that segment,
                  while the hand approaches it: the task should still succeed. Not for a fixed
                  object (scene.yaml: the drawer's cabinet), whose place defines the task's goal.
  moved_from_start  the reference for object_moved: the object stands where that shove puts it
                  from the start (nothing is injected, nothing followed). An object_moved failure
                  that fails here too is the goal's generalization there, not the following.
And two cases of recovery after a lost grasp (executor.yaml recovery/*: the executor opens the
gripper, goes back to the start of the segment that reached for the object, looks again and
retries), their objects followed, counted apart too ("recovery"), for the tasks that grasp something
(tasks.grasps: not a fist that pushes or wipes):
  grasp_dropped   the grip's force drops to 0 at 30% of the held segment (as grip_lost) and comes
                  back 0.5 s later: the object falls, the hand must pick it up again.
  grasp_missed    the object of the first segment's goal frame is shoved 3-8 cm across itself
                  (along its narrower horizontal side, scene.yaml half_size) at 75% of that
                  segment, after it is followed: the gripper closes on nothing (shoved along a
                  stick, the hand would still grasp it, further along).
Detection counts the sensor faults and the faulty runs whose task failed (judged by the task file's
success rules, as a demonstration is); a fault of the world the task survived (a weak grip while
pushing) is counted apart. Delay: sim s from the fault to the alarm (the alarm's "s into the
motion"), for the faults with a moment (not sensors_frozen, which is wrong only once the sensors
should have changed).

  bench_faults.py --library-dir DIR [--mode sim] [--tasks grasp,drawer] [--goals N]
                  [--cases none,object_moved,...] [--attach] [--out result.json] [--update-docs]

--update-docs: after the run, rewrite docs/results.md's section bench-faults from its summary
(lfd_tools.results_doc).
"""
import json
import math
import os
import random
import re
import statistics
import sys
import time

from lfd_tools import bags, lockstep, master, report, reproduction, results_doc, tasks

FROZEN_AT_S = 0.3
# faults of the monitoring itself: always counted
SENSOR_FAULTS = ("sensors_frozen", "sensors_silenced")
# goals sent with their objects followed; counted apart (summary "following")
FOLLOWED_CASES = ("nominal_followed", "object_moved")
# object_moved's shoved pose from the start, nothing followed; counted with "following"
REFERENCE_CASES = ("moved_from_start",)
# recovery after a lost grasp, objects followed too; counted apart (summary "recovery")
RECOVERY_CASES = ("grasp_dropped", "grasp_missed")
DROP_FOR_S = 0.5
SHOVE_M = (0.03, 0.08)
ALARM_TIME = re.compile(r"\(([-\d.]+) s into the motion\)")


def held_segment(signature):
    """The first segment in which the demonstrations' pads were loaded over most of the segment
    (mean level above half of the pads' largest mean), or None."""
    touch = [k for k, c in enumerate(signature["channels"])
             if c.startswith(bags.touch_topic() + "/")]
    if not touch:
        return None
    levels = [max(statistics.mean(seg["channels"][k]["mean"]) for k in touch)
              for seg in signature["segments"]]
    top = max(levels)
    for s, level in enumerate(levels):
        if s > 0 and top > 0 and level > 0.5 * top:
            return s
    return None


def shoved(pose, seed):
    """geometry_msgs/Pose of `pose` (lfd_tools.tasks) moved horizontally by SHOVE_M, its distance
    and direction drawn from `seed`."""
    rng = random.Random(seed)
    distance, angle = rng.uniform(*SHOVE_M), rng.uniform(0.0, 2.0 * math.pi)
    x, y, z = pose["position"]
    return lockstep.pose_msg(dict(pose, position=[x + distance * math.cos(angle),
                                                  y + distance * math.sin(angle), z]))


def shoved_across(pose, half_size, seed):
    """geometry_msgs/Pose of `pose` moved by SHOVE_M along the object's narrower horizontal axis
    (its yaw from the pose's quaternion), to a side drawn from `seed`."""
    rng = random.Random(seed)
    distance, side = rng.uniform(*SHOVE_M), rng.choice((-1.0, 1.0))
    w, qx, qy, qz = pose["orientation"]
    yaw = math.atan2(2.0 * (w * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    if half_size[1] > half_size[0]:  # across = the object's x axis
        yaw -= 0.5 * math.pi
    x, y, z = pose["position"]
    return lockstep.pose_msg(dict(pose, position=[x - side * distance * math.sin(yaw),
                                                  y + side * distance * math.cos(yaw), z]))


def shoved_scene(scene, obj):
    """The goal's scene with `obj` where object_moved shoves it (the same draw)."""
    moved = shoved(scene["objects"][obj], scene["id"])
    objects = dict(scene["objects"], **{obj: dict(scene["objects"][obj], position=[
        moved.position.x, moved.position.y, moved.position.z])})
    return dict(scene, objects=objects)


def faults_for(task, library, scene, durations):
    """[(name, [InjectFault requests], offset s into the motion or None, the scene placed or None
    for the goal's)] that apply to the task."""
    from geometry_msgs.msg import Pose
    from lfd_msgs.srv import InjectFaultRequest

    def request(kind, target="", at=0.0, pose=None, value=0.0):
        return InjectFaultRequest(kind=kind, target=target, at_time=at, pose=pose or Pose(),
                                  value=value)

    def at(segment, fraction):
        return sum(durations[:segment]) + fraction * durations[segment]

    out = []
    # object:<name>, heading:<name>, goal
    frame = library["segments"][0]["goal"]["position"]["frame"]
    obj = frame.split(":", 1)[1] if ":" in frame else None
    if obj in tasks.scene()["objects"]:
        park = lockstep.pose_msg(tasks.pose(tasks.scene()["objects"][obj]["park"]))
        out.append(("object_removed", [request("move_object", obj, at(0, 0.5), park)], at(0, 0.5)))
        # Not a fixed object (the drawer's cabinet): the task's goal is defined where it stands
        # (the drawer open by so much), and the judge, given the scene's goal, would hold the
        # moved cabinet's drawer to the old place.
        if obj in scene["objects"] and not tasks.scene()["objects"][obj].get("fixed"):
            out.append(("object_moved", [request("move_object", obj, at(0, 0.3),
                                                 shoved(scene["objects"][obj], scene["id"]))],
                        at(0, 0.3)))
            if tasks.grasps(task):
                across = shoved_across(scene["objects"][obj],
                                       tasks.scene()["objects"][obj]["half_size"], scene["id"])
                out.append(("grasp_missed", [request("move_object", obj, at(0, 0.75), across)],
                            at(0, 0.75)))
    out.append(("nominal_followed", [], None))
    held = held_segment(library["sensory_signature"])
    if held is not None:
        out.append(("grip_lost", [request("weaken_grip", at=at(held, 0.3), value=0.0)],
                    at(held, 0.3)))
        if tasks.grasps(task):
            out.append(("grasp_dropped", [request("weaken_grip", at=at(held, 0.3), value=0.0),
                                          request("weaken_grip", at=at(held, 0.3) + DROP_FOR_S,
                                                  value=1.0)],
                        at(held, 0.3)))
    rows = sorted(set(library["sensory_signature"]["sources"]))
    out.append(("sensors_frozen", [request("freeze_sensor", r, FROZEN_AT_S) for r in rows], None))
    out.append(("sensors_silenced",
                [request("silence_sensor", r, at(0, 0.3)) for r in rows], at(0, 0.3)))
    joints = list((scene.get("joints") or {}).keys())
    if joints:
        out.append(("joint_locked", [request("lock_joint", j, 0.0) for j in joints], 0.0))
    out = [case + (None,) for case in out]
    if any(case[0] == "object_moved" for case in out):
        out.append(("moved_from_start", [], None, shoved_scene(scene, obj)))
    return out


def run_goal(cell, inject, task, scene, library_path, faults, offset, follow=False):
    """One goal with `faults` (requests with at_time relative to the motion start), judged by the
    task's success rules: its record. follow: the goal's objects are followed."""
    def schedule(feedback):
        t0 = feedback.motion_start.to_sec()
        for f in faults:
            f.at_time += t0
            r = inject(f)
            if not r.success:
                raise RuntimeError("inject_fault: " + r.message)

    try:
        res, _, outcome = reproduction.execute_and_judge(cell, task, scene, library_path,
                                                         on_moving=schedule, follow=follow)
    except reproduction.NotJudged as exc:  # a silenced sensor the task's judge reads: a failed task
        res, outcome = exc.result, {"success": False, "reason": str(exc)}
    alarm = ALARM_TIME.search(res.monitor_alarm or "")
    alarm_time = float(alarm.group(1)) if alarm else None
    return {"monitored": res.monitored, "score": res.max_anomaly_score, "alarm": res.monitor_alarm,
            "alarm_time_s": alarm_time, "fault_time_s": offset,
            "delay_s": (alarm_time - offset if alarm_time is not None and offset is not None
                        else None),
            "goal_succeeded": res.success,
            "task_succeeded": bool(res.success and outcome["success"]), "judged": outcome["reason"],
            "error": res.error, "replans": list(res.replans),
            "recoveries": list(res.recoveries)}


def auc(negatives, positives):
    """P(a faulty run scores above a nominal one), ties counting half."""
    if not negatives or not positives:
        return None
    wins = sum((p > n) + 0.5 * (p == n) for p in positives for n in negatives)
    return wins / (len(negatives) * len(positives))


def summarize(runs):
    """Detection over the sensor faults and the faults that made the task fail (one the task
    survived, e.g. a weak grip while pushing, is counted apart); false alarms over the nominal
    runs."""
    following = {c: [r for r in runs if r["fault"] == c]
                 for c in FOLLOWED_CASES + REFERENCE_CASES}
    recovery = {c: [r for r in runs if r["fault"] == c] for c in RECOVERY_CASES}
    runs = [r for r in runs
            if r["fault"] not in FOLLOWED_CASES + REFERENCE_CASES + RECOVERY_CASES]
    nominal = [r["score"] for r in runs if r["fault"] == "none"]
    faulty = [r for r in runs if r["fault"] != "none"
              and (not r["task_succeeded"] or r["fault"] in SENSOR_FAULTS)]
    by_fault = {}
    for r in faulty:
        by_fault.setdefault(r["fault"], []).append(r)
    delays = [r["delay_s"] for r in faulty if r["delay_s"] is not None]
    return {
        "nominal_runs": len(nominal),
        "nominal_task_failures": sum(not r["task_succeeded"] for r in runs if r["fault"] == "none"),
        "harmless_faults": sum(r["fault"] not in ("none",) + SENSOR_FAULTS and r["task_succeeded"]
                               for r in runs),
        "harmless_faults_alarmed": sum(r["fault"] not in ("none",) + SENSOR_FAULTS
                                       and r["task_succeeded"] and
                                       bool(r["alarm"]) for r in runs),
        "false_alarms": sum(bool(r["alarm"]) for r in runs if r["fault"] == "none"),
        "faulty_runs": len(faulty),
        "detected": sum(bool(r["alarm"]) for r in faulty),
        "detection_rate": sum(bool(r["alarm"]) for r in faulty) / len(faulty) if faulty else None,
        "median_delay_s": statistics.median(delays) if delays else None,
        "roc_auc": auc(nominal, [r["score"] for r in faulty]),
        "per_fault": {f: {"runs": len(rs), "detected": sum(bool(r["alarm"]) for r in rs),
                          "median_delay_s": statistics.median([r["delay_s"] for r in rs
                                                               if r["delay_s"] is not None])
                          if any(r["delay_s"] is not None for r in rs) else None}
                      for f, rs in sorted(by_fault.items())},
        "following": {c: {"runs": len(rs), "task_succeeded": sum(r["task_succeeded"] for r in rs),
                          "replanned_runs": sum(bool(r.get("replans")) for r in rs),
                          "alarms": sum(bool(r["alarm"]) for r in rs),
                          "failed_tasks": sorted({r["task"] for r in rs
                                                  if not r["task_succeeded"]})}
                      for c, rs in following.items() if rs},
        "recovery": {c: {"runs": len(rs), "task_succeeded": sum(r["task_succeeded"] for r in rs),
                         "recovered_runs": sum(bool(r.get("recoveries")) for r in rs),
                         "recoveries": sum(len(r.get("recoveries", [])) for r in rs),
                         "failed_tasks": sorted({r["task"] for r in rs
                                                 if not r["task_succeeded"]})}
                     for c, rs in recovery.items() if rs},
    }


def main():
    ap = reproduction.goal_bench_parser(__doc__, goals=5)
    ap.add_argument("--out", default=None)
    ap.add_argument("--cases", default=None,
                    help="comma-separated: none and the fault names (default: all)")
    ap.add_argument("--update-docs", action="store_true",
                    help="rewrite docs/results.md's section bench-faults from the result")
    args = ap.parse_args()
    if args.update_docs:
        results_doc.check("faults")  # before the run, not after its 20 minutes
    lib_dir = os.path.abspath(args.library_dir)
    names = reproduction.selected_tasks(args.tasks)
    results = {"runs": []}
    with report.written_on_exit(args.out or os.path.join(lib_dir, "bench_faults.json"), results):
        with master.graph_for_this_process(["lfd_launch", "reproduce.launch",
                                            "library_dir:=" + lib_dir],
                                           args.attach):
            cell = lockstep.Cell(node_name="bench_faults")
            from lfd_msgs.srv import InjectFault
            # up with the bridge
            inject = cell.rospy.ServiceProxy("/bridge/inject_fault", InjectFault)
            for task in names:
                path = os.path.join(lib_dir, "%s_%s.json" % (task, args.mode))
                with open(path) as f:
                    library = json.load(f)
                if "sensory_signature" not in library:
                    print("%s: no sensory signature, skipped" % task, flush=True)
                    continue
                for scene in tasks.unseen_scenes(task, args.mode)[:args.goals]:
                    reproduction.place_scene(cell, task, scene)
                    plan, _ = cell.execute(lockstep.execute_goal(path, scene, dry_run=True))
                    cases = [("none", [], None, None)] + faults_for(
                        task, library, scene, list(plan.segment_durations))
                    if args.cases:
                        cases = [c for c in cases if c[0] in args.cases.split(",")]
                    for name, faults, offset, placed in cases:
                        started = time.time()
                        try:
                            r = run_goal(cell, inject, task, placed or scene, path, faults,
                                         offset, follow=name in FOLLOWED_CASES + RECOVERY_CASES)
                        except RuntimeError as exc:
                            r = {"monitored": False, "score": 0.0, "alarm": "",
                                 "alarm_time_s": None, "fault_time_s": offset, "delay_s": None,
                                 "goal_succeeded": False, "task_succeeded": False, "judged": "",
                                 "error": str(exc), "replans": [], "recoveries": []}
                        r.update(task=task, goal=scene["id"], fault=name)
                        results["runs"].append(r)
                        print("%-6s goal %3d %-16s %-7s score %6.2f %-6s delay %s  %.1f s  %s" % (
                            task, scene["id"], name, "ok" if r["task_succeeded"] else "FAILED",
                            r["score"], "ALARM" if r["alarm"] else "-",
                            "-" if r["delay_s"] is None else "%.3f s" % r["delay_s"],
                            time.time() - started,
                            (r["error"] or "; ".join(r["recoveries"] + r["replans"])
                             or r["alarm"])[:160]),
                            flush=True)
            results["summary"] = summarize(results["runs"])
            print(json.dumps(results["summary"], indent=1))
    if args.update_docs:
        results_doc.report_update("faults", results)
    return 0


if __name__ == "__main__":
    sys.exit(report.run_client(main))
