#!/usr/bin/python3
"""Reproduction evaluation (DESIGN.md "How we judge it"): learn each task's skill library from the
simulated dataset, then reproduce every unseen goal of config/tasks.yaml in the MuJoCo sim.

  evaluate_reproduction.py --dataset DIR [--tasks grasp,push] [--changepoints segmentation|ground_truth]
                           [--library-dir DIR] [--library-name '{task}.json'] [--reuse-libraries]
                           [--learn-only | --no-learn] [--attach] [--mode sim|teleop]
                           [--goals 100,101] [--out FILE.json]

DIR holds <DIR>/sim_grasp/*.bag and <DIR>/sim_push/*.bag (lfd_sim_bridge/scripts/generate_datasets.py).
Changepoints: `segmentation` (default) calls /segmentation/segment (lfd_segmentation's node) on the
bags; `ground_truth` uses the demonstrator's /lfd/phase transitions recorded in the bags (grasp:
start of "move"; push: start of "push" and of "return") and is labelled as such in the output.
It is never used silently: without the segmentation package the script stops and says so.

Per goal: /bridge/reset (robot posture + objects), /bridge/set_scene (object at its start, the
other object parked), /executor/execute toward the goal, then the object's final pose is judged:
grasp = stick >= 0.10 m above the table and within 0.03 m (3-D) of its goal; push = box within
0.03 m (horizontal) of its target. Time ratio = executed time / mean demonstrated duration of the
learned segments (same span). Starts its own roslaunch (reproduce.launch + learner
[+ segmentation]) on a private master port, or with --attach uses the nodes already running at
ROS_MASTER_URI (launch/learn.launch for --learn-only, launch/reproduce.launch for --no-learn: the
headless pipeline's stages). Writes JSON (also after an error or Ctrl-C, with what was done) and
prints a table. A task whose learning fails is reported with its error; the other tasks still run.

Segment names are given to the learner only when the segmentation yields the task's expected
number of segments; otherwise the library's segments are named segment_<i> and the executor
refuses it with a clear error (its goal rules need the expected segments). Boundaries are never
made up.
"""
import argparse
import glob
import json
import math
import os
import socket
import subprocess
import sys
import tempfile
import time

import rosbag
import rospkg
import yaml

TASK_OBJECT = {"grasp": "stick", "push": "box"}
GT_CHANGEPOINT_PHASES = {"grasp": ["move"], "push": ["push", "return"]}
SEGMENT_NAMES = {"grasp": ["approach", "move"], "push": ["approach", "push", "return"]}


def free_port():
    s = socket.socket()
    s.bind(("", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def ground_truth_changepoints(bag_path, task):
    """Bag times of the first /lfd/phase message of each phase that starts a new segment."""
    firsts = {}
    with rosbag.Bag(bag_path) as bag:
        for _, msg, t in bag.read_messages(topics=["/lfd/phase"]):
            stamp = msg.header.stamp.to_sec() if msg.header.stamp.to_sec() > 0 else t.to_sec()
            firsts.setdefault(msg.name, stamp)
    missing = [p for p in GT_CHANGEPOINT_PHASES[task] if p not in firsts]
    if missing:
        raise RuntimeError("%s: no /lfd/phase message for phase(s) %s" % (bag_path, missing))
    return [firsts[p] for p in GT_CHANGEPOINT_PHASES[task]]


def yaw_quaternion(yaw):
    from geometry_msgs.msg import Quaternion
    return Quaternion(w=math.cos(yaw / 2), x=0.0, y=0.0, z=math.sin(yaw / 2))


def pose_of(entry):
    from geometry_msgs.msg import Pose, Point
    return Pose(position=Point(*entry[:3]), orientation=yaw_quaternion(entry[3]))


def yaw_of(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def wrap(a, period):
    return (a + period / 2) % period - period / 2


def mean_demo_duration(library_path):
    with open(library_path) as f:
        lib = json.load(f)
    spans = {}
    for seg in lib["segments"]:
        for d in seg["demos"]:
            lo, hi = spans.get(d["demo_id"], (float("inf"), -float("inf")))
            spans[d["demo_id"]] = (min(lo, d["start_time"]), max(hi, d["end_time"]))
    full = [hi - lo for lo, hi in spans.values()]
    return sum(full) / len(full), len(full), len(lib["segments"])


class Session:
    """The ROS side: either a private roslaunch (reproduce.launch + learner [+ segmentation]) or,
    with attach, the graph already running at ROS_MASTER_URI; and a rospy node."""

    def __init__(self, library_dir, with_segmentation, log_path, attach=False, learning=True,
                 executing=True):
        self.proc = None
        self.log = None
        import rosgraph
        if not attach:
            self.port = free_port()
            os.environ["ROS_MASTER_URI"] = "http://localhost:%d" % self.port
            launch = tempfile.NamedTemporaryFile("w", suffix=".launch", delete=False)
            seg = ""
            if with_segmentation:
                seg = ('<node pkg="lfd_segmentation" type="segmentation_node" name="segmentation">'
                       '<rosparam command="load" file="$(find lfd_config)/segmentation.yaml"/></node>')
            launch.write('<launch><include file="$(find lfd_launch)/reproduce.launch">'
                         '<arg name="library_dir" value="%s"/></include>'
                         '<node pkg="lfd_dmp" type="learner_node" name="learner"/>%s</launch>'
                         % (library_dir, seg))
            launch.close()
            self.log = open(log_path, "w")
            self.proc = subprocess.Popen(["roslaunch", "-p", str(self.port), launch.name],
                                         stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.time() + 120
        while not rosgraph.is_master_online():  # roslaunch starts the master first
            if time.time() > deadline or (self.proc and self.proc.poll() is not None):
                raise RuntimeError("no ROS master at %s (see %s)"
                                   % (os.environ.get("ROS_MASTER_URI"), log_path))
            time.sleep(0.5)
        if executing:  # rospy reads /use_sim_time once, at init: wait for the launch to set it
            master = rosgraph.Master("/evaluate_reproduction_probe")
            while not master.hasParam("/use_sim_time"):
                if time.time() > deadline:
                    raise RuntimeError("/use_sim_time never set: is the simulation launched?")
                time.sleep(0.2)
        time.sleep(1.0)
        import rospy
        self.rospy = rospy
        # Ctrl-C must raise KeyboardInterrupt here (results so far are written, nothing more is
        # judged), not just shut rospy down and turn the remaining goals into failed calls.
        rospy.init_node("evaluate_reproduction", anonymous=True, disable_signals=True)
        from lfd_msgs.srv import ExecuteTask, LearnSkills, ResetSim, SetScene
        services = {}
        if learning:
            services["/learner/learn"] = LearnSkills
        if executing:
            services.update({"/executor/execute": ExecuteTask, "/bridge/reset": ResetSim,
                             "/bridge/set_scene": SetScene})
        if learning and with_segmentation:
            from lfd_msgs.srv import Segment
            services["/segmentation/segment"] = Segment
        self.srv = {}
        for name, typ in services.items():
            try:
                rospy.wait_for_service(name, timeout=120)
            except rospy.ROSException:
                raise RuntimeError("service %s did not come up within 120 s" % name)
            self.srv[name] = rospy.ServiceProxy(name, typ)
        while executing and rospy.Time.now().is_zero():
            time.sleep(0.05)

    def sleep_sim(self, seconds):
        end = self.rospy.Time.now() + self.rospy.Duration(seconds)
        while self.rospy.Time.now() < end and not self.rospy.is_shutdown():
            time.sleep(0.002)

    def object_pose(self, name):
        from geometry_msgs.msg import PoseStamped
        return self.rospy.wait_for_message("/objects/%s/pose" % name, PoseStamped, timeout=30).pose

    def close(self):
        self.rospy.signal_shutdown("done")
        if self.proc:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        if self.log:
            self.log.close()


def learn(session, task, bags, changepoints, library_path):
    from lfd_msgs.msg import DemoSegmentation
    from lfd_msgs.srv import LearnSkillsRequest
    req = LearnSkillsRequest(task=task, output_path=library_path)
    report = {"changepoint_source": changepoints, "bags": len(bags),
              "expected_segments": len(SEGMENT_NAMES[task]), "warnings": []}
    if changepoints == "segmentation":
        seg = session.srv["/segmentation/segment"](bag_paths=bags)
        if not seg.success:
            raise RuntimeError("segmentation failed: " + seg.error)
        req.segmentations = seg.demos
        req.selected_features = seg.selected_features
        report["selected_features"] = list(seg.selected_features)
        report["segmentation_time"] = seg.elapsed
    else:
        for b in bags:
            req.segmentations.append(DemoSegmentation(
                source=b, changepoint_times=ground_truth_changepoints(b, task)))
    counts = [len(d.changepoint_times) for d in req.segmentations]
    report["changepoint_counts"] = counts
    report["changepoint_times"] = [list(d.changepoint_times) for d in req.segmentations]
    # The learner keeps the majority count (ties: fewer); name the segments only if it is the
    # task's, so a 1-segment library of a 3-segment task is not called "approach".
    majority = min(set(counts), key=lambda c: (-counts.count(c), c)) if counts else 0
    if majority + 1 == len(SEGMENT_NAMES[task]):
        req.segment_names = SEGMENT_NAMES[task]
    else:
        report["warnings"].append(
            "segmentation gives %d segment(s) (majority of changepoint counts %s), the task has %d:"
            " segments left unnamed; the executor will refuse this library"
            % (majority + 1, counts, len(SEGMENT_NAMES[task])))
    res = session.srv["/learner/learn"](req)
    if not res.success:
        raise RuntimeError("learning %s failed: %s" % (task, res.error))
    report.update({"num_segments": res.num_segments, "num_demos": res.num_demos,
                   "learn_time": res.elapsed})
    report["warnings"] += list(res.warnings)
    return report


RECORDED_TOPICS = ["/joint_states", "/ee_pose", "/gripper/state", "/objects/stick/pose",
                   "/objects/box/pose", "/executor/planned_path", "/executor/executed_path",
                   "/executor/segment_markers"]


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
        import signal
        try:
            os.killpg(self.proc.pid, signal.SIGINT)
            self.proc.wait(timeout=20)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        return self.path if os.path.exists(self.path) else None


def reproduce(session, task, entry, tasks_cfg, library, tol, min_lift, duration_scale,
              record_path=None):
    obj = TASK_OBJECT[task]
    other = [o for o in TASK_OBJECT.values() if o != obj][0]
    start = entry["stick"] if task == "grasp" else entry["box"]
    goal = entry["goal"] if task == "grasp" else entry["target"]
    r = session.srv["/bridge/reset"](joint_names=[], positions=[], reset_objects=True)
    if not r.success:
        raise RuntimeError("reset failed: " + r.message)
    s = session.srv["/bridge/set_scene"](object_names=[obj, other],
                                         poses=[pose_of(start), pose_of(tasks_cfg["park"][other])])
    if not s.success:
        raise RuntimeError("set_scene failed: " + s.message)
    session.sleep_sim(0.3)
    recording = BagRecording(record_path) if record_path else None
    started = session.rospy.get_time()
    try:
        res = session.srv["/executor/execute"](library=library, object_pose=pose_of(start),
                                               goal=pose_of(goal), duration_scale=duration_scale,
                                               dry_run=False)
        session.sleep_sim(1.0)  # objects come to rest
    finally:
        bag = recording.stop() if recording else None
    out = {"id": entry["id"], "executed": res.success, "error": res.error,
           "warnings": list(res.warnings), "execution_time": res.execution_time,
           "planned_duration": res.planned_duration,
           "segment_durations": list(res.segment_durations),
           "tcp_final_position_error": res.final_position_error,
           "tcp_final_orientation_error": res.final_orientation_error,
           "planning_time": res.planning_time}
    if bag:
        # Sim times at which each segment's streaming ended (snapshots at the end of each segment).
        ends, t = [], started + max(0.0, res.execution_time - sum(res.segment_durations))
        for d in res.segment_durations:
            t += d
            ends.append(t)
        out.update({"bag": bag, "segment_end_times": ends})
    p = session.object_pose(obj)
    table_top = tasks_cfg["table_top"]
    d = [p.position.x - goal[0], p.position.y - goal[1], p.position.z - goal[2]]
    dist = math.sqrt(sum(v * v for v in d)) if task == "grasp" else math.hypot(d[0], d[1])
    height = p.position.z - table_top
    yaw_err = abs(wrap(yaw_of(p.orientation) - goal[3], math.pi if task == "grasp" else math.pi / 2))
    ok = res.success and dist <= tol and (task != "grasp" or height >= min_lift)
    out.update({"success": ok, "object_position_error": dist, "object_height": height,
                "object_yaw_error": yaw_err,
                "object_final": [p.position.x, p.position.y, p.position.z]})
    return out


def summarize(task, learn_report, library, rows):
    ok = [r for r in rows if r["success"]]
    ex = [r for r in rows if r["executed"]]
    mean = lambda xs: sum(xs) / len(xs) if xs else None  # noqa: E731
    demo_mean, n_demos, n_segments = (mean_demo_duration(library) if os.path.exists(library)
                                      else (None, 0, 0))
    return {"learning": learn_report, "library": library, "demos": n_demos,
            "segments": n_segments, "mean_demo_duration": demo_mean,
            "goals": len(rows), "successes": len(ok),
            "success_rate": len(ok) / len(rows) if rows else None,
            "mean_object_position_error": mean([r["object_position_error"] for r in rows]),
            "mean_object_yaw_error": mean([r["object_yaw_error"] for r in rows]),
            "mean_tcp_final_error": mean([r["tcp_final_position_error"] for r in ex]),
            "mean_time_ratio": mean([r["time_ratio"] for r in ex]),
            "mean_overhead_ratio": mean([r["overhead_ratio"] for r in ex]),
            "runs": rows}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--dataset", required=True)
    ap.add_argument("--tasks", default="grasp,push")
    ap.add_argument("--changepoints", choices=["segmentation", "ground_truth"],
                    default="segmentation")
    ap.add_argument("--library-dir", default=None, help="default: <dataset>/skills_<changepoints>")
    ap.add_argument("--library-name", default="{task}.json",
                    help="library file name in --library-dir ({task}, {mode} are replaced)")
    ap.add_argument("--reuse-libraries", action="store_true", help="skip learning if present")
    ap.add_argument("--learn-only", action="store_true", help="learn the libraries, reproduce nothing")
    ap.add_argument("--no-learn", action="store_true",
                    help="reproduce with the existing libraries (an error if one is missing)")
    ap.add_argument("--attach", action="store_true",
                    help="use the nodes running at ROS_MASTER_URI instead of starting roslaunch")
    ap.add_argument("--goals", default="", help="comma-separated unseen ids (default all)")
    ap.add_argument("--mode", default="sim", help="dataset and unseen goal set (sim | teleop)")
    ap.add_argument("--tolerance", type=float, default=0.03)
    ap.add_argument("--min-lift", type=float, default=0.10)
    ap.add_argument("--duration-scale", type=float, default=1.0)
    ap.add_argument("--record-dir", default=None,
                    help="record the first goal of each task into a bag there (snapshots, rviz)")
    ap.add_argument("--out", default=None, help="default: <library-dir>/reproduction.json")
    args = ap.parse_args()
    if args.learn_only and args.no_learn:
        ap.error("--learn-only and --no-learn exclude each other")

    config_dir = rospkg.RosPack().get_path("lfd_config")
    with open(os.path.join(config_dir, "tasks.yaml")) as f:
        tasks_cfg = yaml.safe_load(f)
    dataset = os.path.abspath(args.dataset)
    lib_dir = os.path.abspath(args.library_dir or os.path.join(dataset, "skills_" + args.changepoints))
    os.makedirs(lib_dir, exist_ok=True)
    with_seg = args.changepoints == "segmentation" and not args.no_learn
    if with_seg:
        try:
            rospkg.RosPack().get_path("lfd_segmentation")
        except rospkg.ResourceNotFound:
            sys.exit("lfd_segmentation is not built: cannot segment the demos. Pass "
                     "--changepoints ground_truth to use the demonstrator's phase boundaries "
                     "(reported as such).")
    tasks = [t for t in args.tasks.split(",") if t]
    unknown = [t for t in tasks if t not in TASK_OBJECT]
    if unknown:
        ap.error("unknown task(s) %s (grasp | push)" % ",".join(unknown))
    wanted = {int(g) for g in args.goals.split(",") if g}
    out = args.out or os.path.join(lib_dir, "reproduction.json")
    results = {"changepoint_source": args.changepoints, "tolerance": args.tolerance,
               "min_lift": args.min_lift, "dataset": dataset, "mode": args.mode, "tasks": {},
               "complete": False}
    session = None
    status = 0
    try:
        session = Session(lib_dir, with_seg, os.path.join(lib_dir, "evaluate_reproduction.log"),
                          attach=args.attach, learning=not args.no_learn,
                          executing=not args.learn_only)
        for task in tasks:
            library = os.path.join(lib_dir, args.library_name.format(task=task, mode=args.mode))
            entry = results["tasks"][task] = summarize(task, {}, library, [])
            learn_report = {"reused": True}
            try:
                if args.no_learn:
                    if not os.path.exists(library):
                        raise RuntimeError("no skill library %s: learn it first" % library)
                elif not (args.reuse_libraries and os.path.exists(library)):
                    bags = sorted(glob.glob(os.path.join(dataset, "%s_%s" % (args.mode, task),
                                                         "*.bag")))
                    if not bags:
                        raise RuntimeError("no bags in %s/%s_%s" % (dataset, args.mode, task))
                    learn_report = learn(session, task, bags, args.changepoints, library)
                    for w in learn_report["warnings"]:
                        print("%-5s learn: warning: %s" % (task, w), flush=True)
                    print("%-5s learn: %d segment(s) x %d demo(s), changepoints per demo %s -> %s"
                          % (task, learn_report["num_segments"], learn_report["num_demos"],
                             learn_report["changepoint_counts"], library), flush=True)
            except RuntimeError as exc:
                print("%-5s: ERROR %s" % (task, exc), flush=True)
                entry.update({"error": str(exc), "learning": learn_report})
                status = 1
                continue
            entry.update(summarize(task, learn_report, library, []))
            if args.learn_only:
                continue
            demo_mean = entry["mean_demo_duration"]
            goals = [e for e in tasks_cfg[task]["unseen"][args.mode]
                     if not wanted or e["id"] in wanted]
            rows = []
            for n, goal_entry in enumerate(goals, 1):
                try:
                    record = (os.path.join(args.record_dir, "%s_%s_%d.bag"
                                           % (task, args.mode, goal_entry["id"]))
                              if args.record_dir and n == 1 else None)
                    r = reproduce(session, task, goal_entry, tasks_cfg, library, args.tolerance,
                                  args.min_lift, args.duration_scale, record)
                except (RuntimeError, session.rospy.ServiceException) as exc:
                    if session.rospy.is_shutdown():
                        raise
                    # The bridge (or executor) failed on this goal: record it, try the next.
                    r = {"id": goal_entry["id"], "executed": False, "success": False,
                         "error": str(exc), "warnings": [], "execution_time": 0.0,
                         "planned_duration": 0.0, "segment_durations": [],
                         "tcp_final_position_error": None, "tcp_final_orientation_error": None,
                         "planning_time": None, "object_position_error": float("nan"),
                         "object_height": float("nan"), "object_yaw_error": float("nan")}
                r["time_ratio"] = r["execution_time"] / demo_mean if r["executed"] else None
                r["overhead_ratio"] = (r["execution_time"] / r["planned_duration"]
                                       if r["executed"] and r["planned_duration"] > 0 else None)
                rows.append(r)
                entry.update(summarize(task, learn_report, library, rows))
                print("%-5s goal %3d (%d/%d): %-7s obj err %5.1f mm  h %5.1f cm  yaw err %.3f  "
                      "time %.2f s (x%.2f) %s" % (
                          task, r["id"], n, len(goals), "OK" if r["success"] else "FAILED",
                          r["object_position_error"] * 1e3, r["object_height"] * 100,
                          r["object_yaw_error"], r["execution_time"], r["time_ratio"] or 0.0,
                          r["error"]), flush=True)
            if not rows or entry["successes"] < len(rows):
                status = status or 1
        results["complete"] = True
    finally:
        if session:
            session.close()
        with open(out, "w") as f:
            json.dump(results, f, indent=2)

    if args.learn_only:
        print("JSON: %s" % out)
        return status
    print("\nReproduction on unseen goals (changepoints: %s%s), tolerance %.0f mm"
          % (args.changepoints, " -- GROUND TRUTH phase boundaries, not segmentation"
             if args.changepoints == "ground_truth" else "", args.tolerance * 1e3))
    print("%-6s %6s %6s %9s %12s %10s %10s %10s %10s" % (
        "task", "demos", "segs", "success", "obj err mm", "yaw err", "tcp err mm", "time/demo",
        "time/plan"))
    for task, r in results["tasks"].items():
        fmt = lambda v, s=1.0: "-" if v is None else "%.2f" % (v * s)  # noqa: E731
        print("%-6s %6d %6d %5d/%-3d %12s %10s %10s %10s %10s" % (
            task, r["demos"], r["segments"], r["successes"], r["goals"],
            fmt(r["mean_object_position_error"], 1e3), fmt(r["mean_object_yaw_error"]),
            fmt(r["mean_tcp_final_error"], 1e3), fmt(r["mean_time_ratio"]),
            fmt(r["mean_overhead_ratio"])))
    print("JSON: %s" % out)
    return status


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print("interrupted: the results so far are written (\"complete\": false)", file=sys.stderr)
        sys.exit(130)
