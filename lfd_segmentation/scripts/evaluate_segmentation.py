#!/usr/bin/python3
"""Score the segmentation of recorded datasets against the demonstrator's ground truth.

For every dataset folder (one bag per demonstration) and every combination method, calls the
segmentation service (lfd_msgs/Segment) on all the dataset's bags at once, then compares each demo's
validated changepoints with the ground-truth phase transitions recorded on /lfd/phase (which the
segmenter never reads). The protocol and its tolerance come from config/evaluation.yaml.

  evaluate_segmentation.py --datasets DIR [--names sim_grasp,sim_push] [--methods ...] --out result.json
                           [--cli PATH/TO/segment [--config YAML] [--no-sensors]]

With --cli the master-free `segment` CLI is run instead of the service (same config and result);
--no-sensors drops every sensor topic (pose-only input). Prints one table row per dataset and
method, and writes every per-demo detail to --out.

Metrics, per dataset and method:
  rate       the paper's success rate: exactly one changepoint per expected transition window
  covering   TSSB's Covering: for every true segment the best Jaccard overlap with a found segment,
             weighted by its length (1 = same segmentation)
  f1         TSSB's margin F1: a true changepoint (and the series' first and last sample, as TSSB
             counts them) is found when a changepoint lies within the tolerance of it
  err_med/p95  time error of each true transition (distance from the nearest changepoint to its
             window, 0 inside), median and 95th percentile over the demos that found one
A transition's point for Covering and F1 is the middle of its window (the grasp phase of a grasp,
a single instant for the push contact and release).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
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


def transition_points(phases, expected):
    """(lo, hi) of each true transition without tolerance."""
    return [(lo, hi) for lo, hi in expected_windows(phases, expected, 0.0)]


def segments(points, start, end):
    edges = [start] + sorted(p for p in points if start < p < end) + [end]
    return list(zip(edges[:-1], edges[1:]))


def covering(true_points, found_points, start, end):
    """TSSB Covering (van den Burg & Williams): sum over true segments of |A| / N max_B J(A, B)."""
    truth, found = segments(true_points, start, end), segments(found_points, start, end)
    total = 0.0
    for a0, a1 in truth:
        best = 0.0
        for b0, b1 in found:
            inter = max(0.0, min(a1, b1) - max(a0, b0))
            union = max(a1, b1) - min(a0, b0)
            best = max(best, inter / union if union > 0 else 0.0)
        total += (a1 - a0) * best
    return total / (end - start) if end > start else 0.0


def margin_f1(true_points, found_points, start, end, margin):
    """TSSB's F1 with a margin: the first and last sample count as changepoints of both sides."""
    truth = [start] + sorted(true_points) + [end]
    found = [start] + sorted(p for p in found_points if start < p < end) + [end]
    used, tp = set(), 0
    for t in truth:
        for i, f in enumerate(found):
            if i not in used and abs(f - t) <= margin:
                used.add(i)
                tp += 1
                break
    precision, recall = tp / float(len(found)), tp / float(len(truth))
    return 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0


def time_errors(windows, found):
    """Distance from the nearest changepoint to each true transition window (0 inside)."""
    errors = []
    for lo, hi in windows:
        if not found:
            errors.append(None)
            continue
        errors.append(min(0.0 if lo <= c <= hi else min(abs(c - lo), abs(c - hi)) for c in found))
    return errors


def percentile(values, q):
    if not values:
        return float("nan")
    v = sorted(values)
    k = (len(v) - 1) * q
    lo = int(k)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def bag_span(bag_path):
    with rosbag.Bag(bag_path) as bag:
        return bag.get_start_time(), bag.get_end_time()


class CliSegmenter(object):
    """Runs the `segment` CLI on the bags of one dataset; returns a service-like result."""

    def __init__(self, cli, config, no_sensors):
        self.cli, self.config, self.no_sensors = cli, config, no_sensors

    def _config(self):
        if not self.no_sensors:
            return self.config
        with open(self.config) as f:
            cfg = yaml.safe_load(f)
        cfg["topics"] = [t for t in cfg["topics"] if t.get("role", "state") != "sensor"]
        cfg["validate_with_sensors"] = False
        tmp = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
        yaml.safe_dump(cfg, tmp)
        tmp.close()
        return tmp.name

    def __call__(self, bags, method):
        cmd = [self.cli, "--config", self._config(), "--no-profiles", "--combination", method] + bags
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        if not proc.stdout.strip():
            raise RuntimeError("segment CLI printed nothing: %s" % proc.stderr.strip()[-300:])
        out = json.loads(proc.stdout)
        if not out.get("success"):
            raise RuntimeError("segmentation failed: %s" % out.get("error"))
        demos = []
        for d in out["demos"]:
            t0 = d.get("start_time", 0.0)
            demos.append({"changepoint_times": d["changepoint_times"], "rejected_times": d.get("rejected_times", []),
                          "pruned_times": d.get("pruned_times", []),
                          "zones": [(z["begin_time"], z["end_time"]) for z in d.get("zones", [])]})
        return {"demos": demos, "selected_features": out["selected_features"],
                "selected_weights": out["feature_weights"], "warnings": out["warnings"]}


def call_service(segment, bags, method):
    res = segment(SegmentRequest(bag_paths=bags, combination=method))
    if not res.success:
        raise RuntimeError("segmentation failed: %s" % res.error)
    return {"demos": [{"changepoint_times": list(d.changepoint_times), "rejected_times": list(d.rejected_times),
                       "pruned_times": list(d.pruned_times),
                       "zones": [(z.begin_time, z.end_time) for z in d.zones]} for d in res.demos],
            "selected_features": list(res.selected_features), "selected_weights": list(res.selected_weights),
            "warnings": list(res.warnings)}


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
    start = time.time()
    res = segment(bags, method)
    elapsed = time.time() - start
    demos, correct, coverings, f1s, errors, missed = [], 0, [], [], [], 0
    for bag, (_, phases), demo in zip(bags, truth, res["demos"]):
        windows = expected_windows(phases, expected, tolerance)
        found = list(demo["changepoint_times"])
        ok, why = judge(found, windows)
        correct += ok
        t_start, t_end = bag_span(bag)
        true_windows = transition_points(phases, expected)
        points = [0.5 * (lo + hi) for lo, hi in true_windows]
        cov = covering(points, found, t_start, t_end)
        f1 = margin_f1(points, found, t_start, t_end, tolerance)
        errs = time_errors(true_windows, found)
        coverings.append(cov)
        f1s.append(f1)
        errors += [e for e in errs if e is not None]
        missed += sum(e is None for e in errs)
        demos.append({"bag": os.path.basename(bag), "correct": ok, "reason": why,
                      "changepoints_s": found, "rejected_s": demo["rejected_times"],
                      "pruned_s": demo["pruned_times"], "windows_s": windows, "zones_s": demo["zones"],
                      "covering": cov, "f1": f1, "time_errors_s": errs})
    n = float(len(bags))
    return {"task": task, "method": method, "demos": len(bags), "correct": correct,
            "success_rate": correct / n, "tolerance_s": tolerance,
            "covering": sum(coverings) / n, "f1": sum(f1s) / n,
            "time_error_median_s": percentile(errors, 0.5), "time_error_p95_s": percentile(errors, 0.95),
            "transitions_without_changepoint": missed,
            "selected_features": res["selected_features"], "selected_weights": res["selected_weights"],
            "warnings": res["warnings"], "service_time_s": elapsed, "details": demos}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--datasets", required=True, help="folder holding one sub-folder per dataset")
    ap.add_argument("--names", default="sim_grasp,sim_push,teleop_grasp,teleop_push")
    ap.add_argument("--methods", default="", help="comma list; default: all in evaluation.yaml")
    ap.add_argument("--config", default=DEFAULT_CONFIG)
    ap.add_argument("--service", default="/segmentation/segment")
    ap.add_argument("--out", default="", help="write the full result as JSON here")
    ap.add_argument("--cli", default="", help="run this `segment` CLI instead of the service")
    ap.add_argument("--seg-config", default=os.path.join(HERE, "..", "..", "config", "segmentation.yaml"),
                    help="segmentation parameters for --cli")
    ap.add_argument("--no-sensors", action="store_true", help="with --cli: drop the sensor topics")
    args = ap.parse_args(rospy.myargv()[1:])

    with open(args.config) as f:
        config = yaml.safe_load(f)
    methods = [m for m in args.methods.split(",") if m] or config["segmentation"]["methods"]
    if args.cli:
        segment = CliSegmenter(args.cli, args.seg_config, args.no_sensors)
    else:
        try:
            rospy.wait_for_service(args.service, timeout=30.0)
        except rospy.ROSException:
            print("error: segmentation service %s is not available" % args.service, file=sys.stderr)
            return 2
        proxy = rospy.ServiceProxy(args.service, Segment)
        segment = lambda bags, method: call_service(proxy, bags, method)  # noqa: E731

    results, failures = {}, 0
    print("%-14s %-18s %8s %6s %6s %6s %7s %7s %8s  %s" % (
        "dataset", "method", "correct", "rate", "cover", "f1", "err_med", "err_p95", "time_s", "features"))
    for name in [n for n in args.names.split(",") if n]:
        folder = os.path.join(args.datasets, name)
        results[name] = {}
        for method in methods:
            try:
                r = evaluate_dataset(segment, folder, method, config)
            except (RuntimeError, rospy.ServiceException, OSError, ValueError) as exc:
                print("%-14s %-18s error: %s" % (name, method, exc))
                results[name][method] = {"error": str(exc)}
                failures += 1
                continue
            results[name][method] = r
            print("%-14s %-18s %4d/%-3d %5.0f%% %6.3f %6.3f %7.3f %7.3f %8.2f  %s" % (
                name, method, r["correct"], r["demos"], 100 * r["success_rate"], r["covering"], r["f1"],
                r["time_error_median_s"], r["time_error_p95_s"], r["service_time_s"],
                ",".join(r["selected_features"])))
    tol = config["segmentation"]["tolerance_s"]
    print("tolerance: a changepoint counts when within %.2f s of its ground-truth transition" % tol)
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"tolerance_s": tol, "results": results}, f, indent=1)
    return 1 if failures else 0


if __name__ == "__main__":
    if "--cli" not in sys.argv:
        rospy.init_node("evaluate_segmentation", anonymous=True, disable_signals=True)
    sys.exit(main())
