#!/usr/bin/python3
"""Score the segmentation of recorded datasets against the demonstrator's ground truth.

For every dataset folder (one bag per demonstration) and every combination method, calls the
segmentation service (lfd_msgs/Segment) on all the dataset's bags at once, then compares each demo's
validated changepoints with the ground-truth phase transitions recorded on /lfd/phase (which the
segmenter never reads). The protocol and its tolerance come from config/evaluation.yaml.

  evaluate_segmentation.py --datasets DIR [--names sim_grasp,sim_push] [--methods ...] --out result.json
                           [--cli PATH/TO/segment [--seg-config YAML] [--topics YAML] [--no-sensors]]
  evaluate_segmentation.py --truth truth.yaml ...        (demos whose truth is not on /lfd/phase)
  evaluate_segmentation.py --labels pr2_ikea/labels.json [--runs pos_1,neg_1] [--write-truth t.yaml] ...

Ground-truth file (--truth; YAML or JSON), for recordings without /lfd/phase:
  demos:
    - name: pos_1                               # optional, for the report
      bags: [pos_1/part1.bag, pos_1/part2.bag]  # one demo, parts in order (relative to this file)
      changepoints_s: [11.94]                   # true changepoints, s from the first bag's start
The first bag's start is its first message's record time (`rosbag info` start); the demo's span
ends at the last bag's end. Each changepoint is an instant, scored with the same tolerance.
--labels converts a labels.json of phase-split runs (../shared/data/pr2_ikea format: runs.<name>.
parts[].file in order, boundaries_rel = start of each next part from the run start) into that file.
--tolerance overrides evaluation.yaml's tolerance_s.

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

    def __init__(self, cli, config, no_sensors, topics=""):
        self.cli, self.config, self.no_sensors, self.topics = cli, config, no_sensors, topics

    def _config(self):
        if not self.no_sensors:
            return self.config
        with open(self.config) as f:
            cfg = yaml.safe_load(f)
        if self.topics:  # what `segment --topics` does, so that --no-sensors can filter them
            with open(self.topics) as f:
                cfg["topics"] = yaml.safe_load(f)["topics"]
        if self.no_sensors:
            cfg["topics"] = [t for t in cfg["topics"] if t.get("role", "state") != "sensor"]
            cfg["validate_with_sensors"] = False
        tmp = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
        yaml.safe_dump(cfg, tmp)
        tmp.close()
        return tmp.name

    def __call__(self, bags, method):
        cmd = [self.cli, "--config", self._config(), "--no-profiles", "--combination", method]
        if self.topics and not self.no_sensors:
            cmd += ["--topics", self.topics]
        cmd += bags
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        if not proc.stdout.strip():
            raise RuntimeError("segment CLI printed nothing: %s" % proc.stderr.strip()[-300:])
        out = json.loads(proc.stdout)
        if not out.get("success"):
            raise RuntimeError("segmentation failed: %s" % out.get("error"))
        demos = []
        for d in out["demos"]:
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


def score_demo(found, true_windows, start, end, tolerance):
    """Score one demo's changepoints against its true transitions, each a window (lo, hi) in seconds
    (lo == hi for an instant). One scorer for both ground-truth sources."""
    windows = [(lo - tolerance, hi + tolerance) for lo, hi in true_windows]
    ok, why = judge(found, windows)
    points = [0.5 * (lo + hi) for lo, hi in true_windows]
    return {"correct": ok, "reason": why, "windows_s": windows,
            "covering": covering(points, found, start, end),
            "f1": margin_f1(points, found, start, end, tolerance),
            "time_errors_s": time_errors(true_windows, found)}


def summarize(scores, tolerance):
    """Dataset figures from the per-demo scores of score_demo."""
    n = float(len(scores))
    errors = [e for s in scores for e in s["time_errors_s"] if e is not None]
    correct = sum(s["correct"] for s in scores)
    return {"demos": len(scores), "correct": correct, "success_rate": correct / n, "tolerance_s": tolerance,
            "covering": sum(s["covering"] for s in scores) / n, "f1": sum(s["f1"] for s in scores) / n,
            "time_error_median_s": percentile(errors, 0.5), "time_error_p95_s": percentile(errors, 0.95),
            "transitions_without_changepoint": sum(e is None for s in scores for e in s["time_errors_s"])}


def run_and_score(segment, method, inputs, truths, spans, tolerance):
    """Segment all demos at once (inputs: one path each, parts comma-joined), score each against
    its true windows (absolute seconds) over its span (first, last stamp)."""
    start = time.time()
    res = segment(inputs, method)
    elapsed = time.time() - start
    if len(res["demos"]) != len(inputs):
        raise RuntimeError("segmenter returned %d demos for %d inputs" % (len(res["demos"]), len(inputs)))
    scores = []
    for path, true_windows, (t_start, t_end), demo in zip(inputs, truths, spans, res["demos"]):
        found = list(demo["changepoint_times"])
        s = score_demo(found, true_windows, t_start, t_end, tolerance)
        s.update({"bag": ",".join(os.path.basename(p) for p in path.split(",")), "changepoints_s": found,
                  "changepoints_rel_s": [c - t_start for c in found],
                  "rejected_s": demo["rejected_times"], "pruned_s": demo["pruned_times"],
                  "zones_s": demo["zones"]})
        scores.append(s)
    out = summarize(scores, tolerance)
    out.update({"method": method, "selected_features": res["selected_features"],
                "selected_weights": res["selected_weights"], "warnings": res["warnings"],
                "service_time_s": elapsed, "details": scores})
    return out


def evaluate_dataset(segment, folder, method, config, tolerance):
    """A dataset folder whose bags carry /lfd/phase ground truth."""
    bags = list_bags(folder)
    truth = [phase_transitions(b) for b in bags]
    task = truth[0][0]
    expected = config["segmentation"]["expected"][task]
    windows = [transition_points(phases, expected) for _, phases in truth]
    out = run_and_score(segment, method, bags, windows, [bag_span(b) for b in bags], tolerance)
    out["task"] = task
    return out


def load_truth_file(path):
    """Read a ground-truth file (YAML or JSON, format in the module docstring) into
    [(name, [bag paths], [changepoint seconds from the first bag's start])]."""
    with open(path) as f:
        return parse_truth(yaml.safe_load(f), os.path.dirname(os.path.abspath(path)), path)


def parse_truth(data, base, path):
    """A ground-truth file's content; relative bag paths are taken from `base`."""
    if not isinstance(data, dict) or not isinstance(data.get("demos"), list) or not data["demos"]:
        raise RuntimeError("%s: expected a 'demos:' list (see evaluate_segmentation.py --help)" % path)
    demos = []
    for i, d in enumerate(data["demos"]):
        if not isinstance(d, dict) or not d.get("bags") or "changepoints_s" not in d:
            raise RuntimeError("%s: demo %d needs 'bags' and 'changepoints_s'" % (path, i))
        bags = d["bags"] if isinstance(d["bags"], list) else [d["bags"]]
        bags = [b if os.path.isabs(b) else os.path.join(base, b) for b in bags]
        demos.append((str(d.get("name", i)), bags, sorted(float(t) for t in d["changepoints_s"])))
    return demos


def truth_from_labels(path, runs=None):
    """Convert a labels.json of phase-split runs (the pr2_ikea format: runs.<name>.parts[].file in
    order, boundaries_rel = each next part's start from the run's first stamp) into a ground-truth
    file's content. Without `runs`, every run split into two parts or more, in the file's order (a
    single-part run has no labelled boundary: pr2_ikea's standard_demo)."""
    with open(path) as f:
        labels = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    names = runs or [n for n, r in labels["runs"].items() if len(r["parts"]) > 1]
    demos = []
    for name in names:
        run = labels["runs"][name]
        demos.append({"name": name, "bags": [os.path.join(base, p["file"]) for p in run["parts"]],
                      "changepoints_s": list(run["boundaries_rel"])})
    return {"demos": demos}


def evaluate_truth_file(segment, demos, method, tolerance):
    """Demos listed in a ground-truth file: times are relative to the first bag's start."""
    spans = []
    for _, bags, _ in demos:
        first, last = bag_span(bags[0]), bag_span(bags[-1])
        spans.append((first[0], last[1]))
    truths = [[(s[0] + t, s[0] + t) for t in cps] for (_, _, cps), s in zip(demos, spans)]
    out = run_and_score(segment, method, [",".join(bags) for _, bags, _ in demos], truths, spans, tolerance)
    for d, (name, _, cps) in zip(out["details"], demos):
        d.update({"name": name, "truth_rel_s": cps})
    out["task"] = "truth_file"
    return out


def make_segmenter(args):
    if args.cli:
        return CliSegmenter(args.cli, args.seg_config, args.no_sensors, args.topics)
    try:
        rospy.wait_for_service(args.service, timeout=30.0)
    except rospy.ROSException:
        raise RuntimeError("segmentation service %s is not available" % args.service)
    proxy = rospy.ServiceProxy(args.service, Segment)
    return lambda bags, method: call_service(proxy, bags, method)


def datasets_to_run(args, config):
    """[(row name, evaluate(segment, method, tolerance))] from --truth/--labels or --datasets."""
    if args.truth or args.labels:
        if args.labels:
            content = truth_from_labels(args.labels, [r for r in args.runs.split(",") if r] or None)
            if args.write_truth:
                with open(args.write_truth, "w") as f:
                    yaml.safe_dump(content, f, sort_keys=False)
            demos = parse_truth(content, os.path.dirname(os.path.abspath(args.labels)), args.labels)
        else:
            demos = load_truth_file(args.truth)
        # a labels.json is named by its folder (pr2_ikea), a truth file by itself
        name = (os.path.basename(os.path.dirname(os.path.abspath(args.labels))) if args.labels
                else os.path.splitext(os.path.basename(args.truth))[0])
        return [(name, lambda seg, m, tol: evaluate_truth_file(seg, demos, m, tol))]
    if not args.datasets:
        raise RuntimeError("give --datasets, --truth or --labels")
    return [(n, lambda seg, m, tol, n=n: evaluate_dataset(seg, os.path.join(args.datasets, n), m, config, tol))
            for n in args.names.split(",") if n]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--datasets", default="", help="folder holding one sub-folder per dataset")
    ap.add_argument("--names", default="sim_grasp,sim_push,teleop_grasp,teleop_push")
    ap.add_argument("--truth", default="", help="ground-truth file (demos, their bags, changepoint times)")
    ap.add_argument("--labels", default="", help="labels.json of phase-split runs (pr2_ikea format)")
    ap.add_argument("--runs", default="", help="with --labels: comma list of runs (default: all)")
    ap.add_argument("--write-truth", default="", help="with --labels: also save the ground-truth file here")
    ap.add_argument("--tolerance", type=float, default=None, help="seconds (default: evaluation.yaml)")
    ap.add_argument("--methods", default="", help="comma list; default: all in evaluation.yaml")
    ap.add_argument("--config", default=DEFAULT_CONFIG)
    ap.add_argument("--service", default="/segmentation/segment")
    ap.add_argument("--out", default="", help="write the full result as JSON here")
    ap.add_argument("--cli", default="", help="run this `segment` CLI instead of the service")
    ap.add_argument("--seg-config", default=os.path.join(HERE, "..", "..", "config", "segmentation.yaml"),
                    help="segmentation parameters for --cli")
    ap.add_argument("--topics", default="", help="with --cli: topics file passed to `segment --topics`")
    ap.add_argument("--no-sensors", action="store_true", help="with --cli: drop the sensor topics")
    args = ap.parse_args(rospy.myargv()[1:])

    with open(args.config) as f:
        config = yaml.safe_load(f)
    methods = [m for m in args.methods.split(",") if m] or config["segmentation"]["methods"]
    tol = args.tolerance if args.tolerance is not None else float(config["segmentation"]["tolerance_s"])
    try:
        segment = make_segmenter(args)
        rows = datasets_to_run(args, config)
    except (RuntimeError, OSError, KeyError, ValueError, yaml.YAMLError) as exc:
        print("error: %s" % exc, file=sys.stderr)
        return 2

    results, failures = {}, 0
    print("%-14s %-18s %8s %6s %6s %6s %7s %7s %8s  %s" % (
        "dataset", "method", "correct", "rate", "cover", "f1", "err_med", "err_p95", "time_s", "features"))
    for name, evaluate in rows:
        results[name] = {}
        for method in methods:
            try:
                r = evaluate(segment, method, tol)
            except (RuntimeError, rospy.ServiceException, rosbag.ROSBagException, OSError, ValueError) as exc:
                # stderr: the pipeline quotes a failed tool's last stderr lines in its report
                print("%-14s %-18s error: %s" % (name, method, exc), file=sys.stderr)
                results[name][method] = {"error": str(exc)}
                failures += 1
                continue
            results[name][method] = r
            print("%-14s %-18s %4d/%-3d %5.0f%% %6.3f %6.3f %7.3f %7.3f %8.2f  %s" % (
                name, method, r["correct"], r["demos"], 100 * r["success_rate"], r["covering"], r["f1"],
                r["time_error_median_s"], r["time_error_p95_s"], r["service_time_s"],
                ",".join(r["selected_features"])))
    print("tolerance: a changepoint counts when within %.2f s of its ground-truth transition" % tol)
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"tolerance_s": tol, "results": results}, f, indent=1)
    return 1 if failures else 0


if __name__ == "__main__":
    if "--cli" not in sys.argv:
        rospy.init_node("evaluate_segmentation", anonymous=True, disable_signals=True)
    sys.exit(main())
