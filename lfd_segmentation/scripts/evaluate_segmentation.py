#!/usr/bin/python3
"""Score the segmentation of recorded datasets against the demonstrator's ground truth.

For every dataset folder (one bag per demonstration) and every combination method, calls the
segmentation service (lfd_msgs/Segment) on all the dataset's bags at once, then compares each demo's
validated changepoints with the ground-truth phase transitions recorded on /lfd/phase (which the
segmenter never reads). The protocol and its tolerance come from config/evaluation.yaml.

  evaluate_segmentation.py --datasets DIR [--names sim_grasp,sim_push] [--methods ...] --out result.json

Prints one table row per dataset and method, and writes every per-demo detail to --out.
"""
import argparse
import json
import os
import sys
import time

import rosbag
import rospy
import yaml
from lfd_msgs.srv import Segment, SegmentRequest

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_CONFIG = os.path.join(HERE, "..", "..", "config", "evaluation.yaml")


def phase_transitions(bag_path):
    """Return (task, [(name, start_time)]) from the ground-truth phase topic, in order."""
    task, phases = None, []
    with rosbag.Bag(bag_path) as bag:
        for _, msg, t in bag.read_messages(topics=["/lfd/phase"]):
            stamp = msg.header.stamp.to_sec() if msg.header.stamp.to_sec() > 0 else t.to_sec()
            task = task or msg.task
            if not phases or phases[-1][0] != msg.name:
                phases.append((msg.name, stamp))
    if not phases:
        raise RuntimeError("%s has no /lfd/phase ground truth" % bag_path)
    return task, phases


def expected_windows(phases, expected, tolerance):
    """Windows [t0 - tol, t1 + tol]: t0 = when phase `from` ends, t1 = when phase `to` begins."""
    windows = []
    for spec in expected:
        ends = [i for i, (name, _) in enumerate(phases) if name == spec["from"]]
        starts = [i for i, (name, _) in enumerate(phases) if name == spec["to"]]
        if not ends or not starts:
            raise RuntimeError("ground truth lacks phase %s or %s" % (spec["from"], spec["to"]))
        t0 = phases[ends[-1] + 1][1]  # first time after `from`
        t1 = phases[starts[0]][1]
        windows.append((min(t0, t1) - tolerance, max(t0, t1) + tolerance))
    return windows


def judge(changepoint_times, windows):
    """Correct = exactly one changepoint per expected window, in order."""
    cps = sorted(changepoint_times)
    if len(cps) != len(windows):
        return False, "expected %d changepoints, got %d" % (len(windows), len(cps))
    for cp, (lo, hi) in zip(cps, windows):
        if not lo <= cp <= hi:
            return False, "changepoint %.2f s outside [%.2f, %.2f]" % (cp, lo, hi)
    return True, "ok"


def list_bags(folder):
    bags = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".bag"))
    if not bags:
        raise RuntimeError("no .bag files in %s" % folder)
    return bags


def evaluate_dataset(segment, folder, method, config):
    bags = list_bags(folder)
    truth = [phase_transitions(b) for b in bags]
    task = truth[0][0]
    expected = config["segmentation"]["expected"][task]
    tolerance = float(config["segmentation"]["tolerance_s"])
    req = SegmentRequest(bag_paths=bags, combination=method)
    start = time.time()
    res = segment(req)
    elapsed = time.time() - start
    if not res.success:
        raise RuntimeError("segmentation failed: %s" % res.error)
    demos, correct = [], 0
    for bag, (_, phases), demo in zip(bags, truth, res.demos):
        windows = expected_windows(phases, expected, tolerance)
        ok, why = judge(list(demo.changepoint_times), windows)
        correct += ok
        demos.append({"bag": os.path.basename(bag), "correct": ok, "reason": why,
                      "changepoints_s": list(demo.changepoint_times),
                      "rejected_s": list(demo.rejected_times),
                      "pruned_s": list(demo.pruned_times),
                      "windows_s": windows,
                      "zones_s": [(z.begin_time, z.end_time) for z in demo.zones]})
    return {"task": task, "method": method, "demos": len(bags), "correct": correct,
            "success_rate": correct / float(len(bags)), "tolerance_s": tolerance,
            "selected_features": list(res.selected_features),
            "selected_weights": list(res.selected_weights),
            "warnings": list(res.warnings), "service_time_s": elapsed, "details": demos}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--datasets", required=True, help="folder holding one sub-folder per dataset")
    ap.add_argument("--names", default="sim_grasp,sim_push,teleop_grasp,teleop_push")
    ap.add_argument("--methods", default="", help="comma list; default: all in evaluation.yaml")
    ap.add_argument("--config", default=DEFAULT_CONFIG)
    ap.add_argument("--service", default="/segmentation/segment")
    ap.add_argument("--out", default="", help="write the full result as JSON here")
    args = ap.parse_args(rospy.myargv()[1:])

    with open(args.config) as f:
        config = yaml.safe_load(f)
    methods = [m for m in args.methods.split(",") if m] or config["segmentation"]["methods"]
    try:
        rospy.wait_for_service(args.service, timeout=30.0)
    except rospy.ROSException:
        print("error: segmentation service %s is not available" % args.service, file=sys.stderr)
        return 2
    segment = rospy.ServiceProxy(args.service, Segment)

    results, failures = {}, 0
    print("%-14s %-18s %8s %6s %8s  %s" % ("dataset", "method", "correct", "rate", "time_s", "features"))
    for name in [n for n in args.names.split(",") if n]:
        folder = os.path.join(args.datasets, name)
        results[name] = {}
        for method in methods:
            try:
                r = evaluate_dataset(segment, folder, method, config)
            except (RuntimeError, rospy.ServiceException, OSError) as exc:
                print("%-14s %-18s error: %s" % (name, method, exc))
                results[name][method] = {"error": str(exc)}
                failures += 1
                continue
            results[name][method] = r
            print("%-14s %-18s %4d/%-3d %5.0f%% %8.2f  %s" % (
                name, method, r["correct"], r["demos"], 100 * r["success_rate"], r["service_time_s"],
                ",".join(r["selected_features"])))
    tol = config["segmentation"]["tolerance_s"]
    print("tolerance: a changepoint counts when within %.2f s of its ground-truth transition" % tol)
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"tolerance_s": tol, "results": results}, f, indent=1)
    return 1 if failures else 0


if __name__ == "__main__":
    rospy.init_node("evaluate_segmentation", anonymous=True, disable_signals=True)
    sys.exit(main())
