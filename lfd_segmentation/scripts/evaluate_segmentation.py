#!/usr/bin/python3
"""Score the segmentation of recorded datasets against the demonstrator's ground truth.

For every dataset folder (one bag per demonstration) and every combination method, calls the
segmentation service (lfd_msgs/Segment) on all the dataset's bags at once, then compares each demo's
validated changepoints with the ground-truth phase transitions recorded on /lfd/phase (which the
segmenter never reads). The protocol and its tolerance come from config/evaluation.yaml.

  evaluate_segmentation.py --datasets DIR [--names sim_grasp,sim_push] [--methods ...]
                           --out result.json
                           [--cli PATH/TO/segment [--seg-config YAML] [--topics YAML] [--no-sensors]
                            [--procedure paper]]
  evaluate_segmentation.py --truth truth.yaml ...        (demos whose truth is not on /lfd/phase)
  evaluate_segmentation.py --labels pr2_ikea/labels.json [--runs pos_1,neg_1]
                           [--write-truth t.yaml] ...

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

import rosbag
import rospy
import yaml
from lfd_msgs.srv import Segment, SegmentRequest
from lfd_tools import bags as lfd_bags
from lfd_tools import config as lfd_config
from lfd_tools import report, segmentation_scoring, tasks
from lfd_tools.master import master_online


class CliSegmenter(object):
    """Runs the `segment` CLI on the bags of one dataset; returns a service-like result."""

    def __init__(self, cli, config, no_sensors, topics="", procedure=""):
        self.cli, self.config, self.no_sensors, self.topics = cli, config, no_sensors, topics
        self.procedure = procedure

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

    def _run(self, bags, methods):
        cmd = [self.cli, "--config", self._config(), "--no-profiles", "--combination",
               ",".join(methods)]
        if self.topics and not self.no_sensors:
            cmd += ["--topics", self.topics]
        if self.procedure:
            cmd += ["--procedure", self.procedure]
        cmd += bags
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              universal_newlines=True)
        if not proc.stdout.strip():
            raise RuntimeError("segment CLI printed nothing: %s" % proc.stderr.strip()[-300:])
        out = json.loads(proc.stdout)
        if not out.get("success"):
            raise RuntimeError("segmentation failed: %s" % out.get("error"))
        return out

    def __call__(self, bags, method):
        return self._answer(self._run(bags, [method]))

    def methods(self, bags, methods):
        """Every method from one CLI run: the features are selected once."""
        out = self._run(bags, methods)
        return {m: self._answer(out["methods"][m]) for m in methods}

    @staticmethod
    def _answer(out):
        demos = []
        for d in out["demos"]:
            demos.append({"changepoint_times": d["changepoint_times"],
                          "rejected_times": d.get("rejected_times", []),
                          "pruned_times": d.get("pruned_times", []),
                          "zones": [(z["begin_time"], z["end_time"]) for z in d.get("zones", [])]})
        return {"demos": demos, "selected_features": out["selected_features"],
                "selected_weights": out["feature_weights"], "warnings": out["warnings"]}


def call_service(segment, bags, method):
    # The service takes absolute paths only (its working directory is not ours); each part of a
    # demo recorded in several bags ("a.bag,b.bag") too.
    bags = [",".join(os.path.abspath(p) for p in b.split(",")) for b in bags]
    res = segment(SegmentRequest(bag_paths=bags, combination=method))
    if not res.success:
        raise RuntimeError("segmentation failed: %s" % res.error)
    return {"demos": [{"changepoint_times": list(d.changepoint_times),
                       "rejected_times": list(d.rejected_times),
                       "pruned_times": list(d.pruned_times),
                       "zones": [(z.begin_time, z.end_time) for z in d.zones]} for d in res.demos],
            "selected_features": list(res.selected_features),
            "selected_weights": list(res.selected_weights), "warnings": list(res.warnings)}


def make_segmenter(args):
    if args.cli:
        return CliSegmenter(args.cli, args.seg_config, args.no_sensors, args.topics, args.procedure)
    # rospy.init_node waits for a master forever: without one, say so (or use --cli).
    if not master_online():
        raise RuntimeError("no ROS master at %s for the segmentation service %s "
                           "(start segment.launch, or use --cli)"
                           % (os.environ.get("ROS_MASTER_URI"), args.service))
    rospy.init_node("evaluate_segmentation", anonymous=True, disable_signals=True)
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
            runs = [r for r in args.runs.split(",") if r] or None
            content = lfd_bags.truth_from_labels(args.labels, runs)
            if args.write_truth:
                with open(args.write_truth, "w") as f:
                    yaml.safe_dump(content, f, sort_keys=False)
            demos = lfd_bags.parse_truth(content, os.path.dirname(os.path.abspath(args.labels)),
                                         args.labels)
        else:
            demos = lfd_bags.load_truth_file(args.truth)
        # a labels.json is named by its folder (pr2_ikea), a truth file by itself
        name = (os.path.basename(os.path.dirname(os.path.abspath(args.labels))) if args.labels
                else os.path.splitext(os.path.basename(args.truth))[0])
        return [(name, lambda seg, ms, tol: segmentation_scoring.evaluate_truth_file_methods(
            seg, demos, ms, tol))]
    if not args.datasets:
        raise RuntimeError("give --datasets, --truth or --labels")
    names = [n for n in (args.names.split(",") if args.names else tasks.datasets()) if n]
    folders = [os.path.join(args.datasets, n) for n in names]
    phases = segmentation_scoring.dataset_phases(folders)  # every bag's truth, all cores
    return [(n, lambda seg, ms, tol, f=f: segmentation_scoring.evaluate_dataset_methods(
        seg, f, ms, config, tol, phases[f])) for n, f in zip(names, folders)]


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--datasets", default="", help="folder holding one sub-folder per dataset")
    ap.add_argument("--names", default="",
                    help="comma list of <mode>_<task> (default: every task's, both modes)")
    ap.add_argument("--truth", default="",
                    help="ground-truth file (demos, their bags, changepoint times)")
    ap.add_argument("--labels", default="",
                    help="labels.json of phase-split runs (pr2_ikea format)")
    ap.add_argument("--runs", default="", help="with --labels: comma list of runs (default: all)")
    ap.add_argument("--write-truth", default="",
                    help="with --labels: also save the ground-truth file here")
    ap.add_argument("--tolerance", type=float, default=None,
                    help="seconds (default: evaluation.yaml)")
    ap.add_argument("--methods", default="", help="comma list; default: all in evaluation.yaml")
    ap.add_argument("--config", default="",
                    help="evaluation protocol (default: config/evaluation.yaml)")
    ap.add_argument("--service", default="/segmentation/segment")
    ap.add_argument("--out", default="", help="write the full result as JSON here")
    ap.add_argument("--cli", default="", help="run this `segment` CLI instead of the service")
    ap.add_argument("--seg-config", default="",
                    help="segmentation parameters for --cli (default: config/segmentation.yaml)")
    ap.add_argument("--topics", default="",
                    help="with --cli: topics file passed to `segment --topics`")
    ap.add_argument("--no-sensors", action="store_true", help="with --cli: drop the sensor topics")
    ap.add_argument("--procedure", default="",
                    help="with --cli: zone_search or paper (segment --procedure)")
    args = ap.parse_args(rospy.myargv()[1:])

    try:
        args.seg_config = args.seg_config or lfd_config.config_path("segmentation.yaml")
        config = lfd_config.load_evaluation(args.config or None)
        methods = [m for m in args.methods.split(",") if m] or config["segmentation"]["methods"]
        tol = (args.tolerance if args.tolerance is not None
               else float(config["segmentation"]["tolerance_s"]))
        rows = datasets_to_run(args, config)  # first: it forks readers, rospy starts threads
        segment = make_segmenter(args)
    except (RuntimeError, OSError, KeyError, ValueError, yaml.YAMLError) as exc:
        print("error: %s" % exc, file=sys.stderr)
        return 2

    results, failures = {}, 0
    print("%-14s %-18s %8s %6s %6s %6s %7s %7s %8s  %s" % (
        "dataset", "method", "correct", "rate", "cover", "f1", "err_med", "err_p95",
        "time_s", "features"))
    for name, evaluate in rows:
        results[name] = {}
        try:
            answers = evaluate(segment, methods, tol)
        except (RuntimeError, rospy.ServiceException, rosbag.ROSBagException,
                OSError, ValueError) as exc:
            print("%-14s %-18s error: %s" % (name, ",".join(methods), exc))
            # also where a caller (the pipeline) looks for a tool's last words
            print("error: %s %s: %s" % (name, ",".join(methods), exc), file=sys.stderr)
            results[name] = {m: {"error": str(exc)} for m in methods}
            failures += 1
            continue
        for method in methods:
            r = results[name][method] = answers[method]
            print("%-14s %-18s %4d/%-3d %5.0f%% %6.3f %6.3f %7.3f %7.3f %8.2f  %s" % (
                name, method, r["correct"], r["demos"], 100 * r["success_rate"], r["covering"],
                r["f1"], r["time_error_median_s"], r["time_error_p95_s"], r["service_time_s"],
                ",".join(r["selected_features"])))
    print("tolerance: a changepoint counts when within %.2f s of its ground-truth transition" % tol)
    if args.out:
        with open(args.out, "w") as f:
            scored = {name: report.segmentation_record(r, tol) for name, r in results.items()}
            json.dump({"tolerance_s": tol, "segmentation": scored}, f, indent=1)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
