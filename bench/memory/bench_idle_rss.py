#!/usr/bin/python3
"""Memory a node gives back after a large request (after one, the probe saw the
segmentation node idle at 264 MB and the executor at 829 MB). Sends one large request to the
segmentation service and one long goal to the executor, and prints each node's VmRSS before it
(idle after start-up), at its peak (VmHWM) and idle after it (IDLE_AFTER_S later).

  bench_idle_rss.py [--out DIR] [--bags N] [--duration-scale S]

The data: a sim_grasp dataset of 4 demos and its skill library, made by the pipeline in DIR
(datasets and learn stages, ~3 min; kept and reused when DIR is given again). The segmentation
request names N bags (default 32, limits/max_bags: the dataset's bags repeated); the goal is an
unseen grasp scene at duration scale S (default 10, limits/max_duration_scale: ten times the
demonstrated pace; extrapolation allowed) run to its end in the simulation, in lockstep. Run after
`./lfd build` with devel/setup.bash sourced.
"""
import argparse
import glob
import os
import shutil
import subprocess
import tempfile
import time
import xmlrpc.client

import rosgraph
from lfd_tools import lockstep, master, tasks

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
PIPELINE = os.path.join(ROOT, "lfd_launch", "scripts", "pipeline.py")
TASK, MODE = "grasp", "sim"
IDLE_AFTER_S = 3.0  # the node trims at the end of the request; this is well after it


def vm(pid, field):
    """A field of /proc/PID/status in MB (VmRSS now, VmHWM its peak)."""
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no %s for pid %d" % (field, pid))


def node_pid(node, timeout=120.0):
    probe = rosgraph.Master("/bench_idle_rss")
    deadline = time.time() + timeout
    while time.time() < deadline:
        try:
            server = xmlrpc.client.ServerProxy(probe.lookupNode(node))
            code, _, pid = server.getPid("/bench_idle_rss")
            if code == 1:
                return pid
        except (OSError, rosgraph.MasterException):
            pass
        time.sleep(0.5)
    raise RuntimeError("node %s did not come up" % node)


def measured(pid, request):
    """{before, peak, idle_after} MB of the process around request()."""
    time.sleep(1.0)
    before = vm(pid, "VmRSS")
    request()
    peak = vm(pid, "VmHWM")
    time.sleep(IDLE_AFTER_S)
    return {"before": before, "peak": peak, "idle_after": vm(pid, "VmRSS")}


def make_data(out):
    """(bags, library) of the sim_grasp dataset in `out`, made by the pipeline if missing."""
    bags = sorted(glob.glob(os.path.join(out, "datasets", "%s_%s" % (MODE, TASK), "*.bag")))
    library = os.path.join(out, "skills", "%s_%s.json" % (TASK, MODE))
    if not bags or not os.path.exists(library):
        subprocess.check_call(["/usr/bin/python3", PIPELINE, "--out", out, "--stages",
                               "datasets,learn", "--datasets", "%s_%s" % (MODE, TASK), "--demos",
                               "4"], stdout=subprocess.DEVNULL)
        bags = sorted(glob.glob(os.path.join(out, "datasets", "%s_%s" % (MODE, TASK), "*.bag")))
    return bags, library


def segmentation_figures(bags, count, env):
    import rospy
    from lfd_msgs.srv import Segment
    with master.background_launch(["roslaunch", "lfd_launch", "segment.launch",
                                   "output:=log"], env):
        pid = node_pid("/segmentation")
        rospy.wait_for_service("/segmentation/segment", timeout=120)
        call = rospy.ServiceProxy("/segmentation/segment", Segment)
        request = [bags[i % len(bags)] for i in range(count)]

        def segment():
            res = call(bag_paths=request)
            if not res.success:
                raise RuntimeError("segmentation failed: %s" % res.error)
        return measured(pid, segment)


def executor_figures(library, duration_scale, env):
    with master.background_launch(["roslaunch", "lfd_launch", "reproduce.launch",
                                   "library_dir:=" + os.path.dirname(library)], env):
        pid = node_pid("/executor")
        cell = lockstep.Cell(node_name="bench_idle_rss")
        scene = tasks.unseen_scenes(TASK, MODE)[0]
        cell.set_scene(dict(tasks.parked(TASK), **scene["objects"]), 0.3, scene.get("joints"))

        def execute():
            # 4 demos span a narrow range: the goal runs anyway (what is measured is its length)
            res, _ = cell.execute(lockstep.execute_goal(library, scene, duration_scale,
                                                        allow_extrapolation=True),
                                  timeout=1800)
            if res is None or not res.success:
                raise RuntimeError("the goal failed: %s" % (res.error if res else "no result"))
            print("executor: goal of %.1f s of motion" % res.planned_duration)
        return measured(pid, execute)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", help="data folder (kept); default: a temporary one, removed")
    ap.add_argument("--bags", type=int, default=32)
    ap.add_argument("--duration-scale", type=float, default=10.0)
    args = ap.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="lfd_bench_rss_")
    try:
        bags, library = make_data(os.path.abspath(out))
        with master.private_master() as env:  # never another run's master
            os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
            import rospy
            rospy.init_node("bench_idle_rss", anonymous=True, disable_signals=True)
            figures = {
                "segmentation (%d bags)" % args.bags: segmentation_figures(bags, args.bags, env),
                "executor (duration scale %g)" % args.duration_scale:
                    executor_figures(library, args.duration_scale, env)}
        print("%-32s %10s %10s %12s" % ("VmRSS, MB", "before", "peak", "idle after"))
        for name, f in figures.items():
            print("%-32s %10.0f %10.0f %12.0f" % (name, f["before"], f["peak"], f["idle_after"]))
    finally:
        if not args.out:
            shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    main()
