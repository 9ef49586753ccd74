#!/usr/bin/python3
"""The segmentation per real-world signal class: for every class of
lfd_tools/signal_classes.py (make_signal_classes.py documents them) and every seed, generates the
class's task, runs the `segment` CLI once on all its demos with the shipped configuration (no
per-class option: only the class's state and sensor columns) and scores each demo against its
truth with the project's scorer (lfd_tools.segmentation_scoring / lfd_tools.judge):

  ok@T      demos correct at tolerance T per seed: exactly one changepoint per true boundary,
            each within T s of it, in order, and no other (the paper's success rate)
  rate@T    correct demos / demos over all seeds
  cover     TSSB Covering;  f1@T: TSSB margin F1 with margin T
  err_med, err_p95  distance from each true boundary to its nearest changepoint (s), over the
            boundaries of demos with any changepoint; `none` counts boundaries of demos without
  cps       changepoints per demo (mean) against the truth's boundaries per demo

  bench_signal_classes.py [--seeds 0,1,2] [--classes a,b] [--demos N] [--cli PATH]
                          [--config YAML] [--procedure NAME] [--out result.json]
                          [--min-success X] [--keep DIR] [--update-docs]

Run with devel/setup.bash sourced (lfd_tools). A failed CLI run scores its demos with no
changepoint and prints its error. --min-success X (0-1): exit 1 when any class's rate at 0.5 s
is below X (for CI). --update-docs: rewrite docs/results.md's section bench-signal-classes from
the result (lfd_tools.results_doc). --demos N: every task with its first N demos (default: the
count each seed draws, 6-8, fewer for long demos): how the segmentation holds up when a user
records only a few.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
from lfd_tools import judge, results_doc, segmentation_scoring, signal_classes

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DEFAULT_CLI = os.path.join(ROOT, "devel", "lib", "lfd_segmentation", "segment")
TOLERANCES = (0.5, 1.0)


def segment(args, folder, truth):
    """(answer as lfd_tools.segmentation_scoring takes it, error or "", seconds) of one CLI run
    on every demo of a class's folder."""
    out = os.path.join(folder, "segment.json")
    cmd = [args.cli, "--no-profiles", "--output", out, "--state-columns",
           ",".join(truth["state_columns"])]
    cmd += ["--sensor-columns",
            ",".join(truth["sensor_columns"])] if truth["sensor_columns"] else []
    cmd += ["--config", args.config] if args.config else []
    cmd += ["--procedure", args.procedure] if args.procedure else []
    cmd += [os.path.join(folder, d["file"]) for d in truth["demos"]]
    if os.path.exists(out):  # never score an earlier run's answer
        os.remove(out)
    start = time.time()
    try:
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              universal_newlines=True)
    except OSError as e:  # e.g. a CLI being rebuilt
        return (no_answer(len(truth["demos"]), str(e)), "cannot run the CLI: %s" % e,
                time.time() - start)
    elapsed = time.time() - start
    try:
        with open(out) as f:
            res = json.load(f)
    except (OSError, ValueError):
        res = {"success": False,
               "error": "no result (exit %d): %s" % (proc.returncode, proc.stderr.strip()[-300:])}
    if not res.get("success"):
        return no_answer(len(truth["demos"]),
                         res.get("error", "")), res.get("error", "failed"), elapsed
    demos = [{"changepoint_times": d["changepoint_times"],
              "rejected_times": d.get("rejected_times", []),
              "pruned_times": d.get("pruned_times", []),
              "zones": [(z["begin_time"], z["end_time"])
                        for z in d.get("zones", [])]} for d in res["demos"]]
    # One demo (a long task at a high rate) has no feature selection: no weights.
    return ({"demos": demos, "selected_features": res["selected_features"],
             "selected_weights": res.get("feature_weights", []), "warnings": res["warnings"]},
            "", elapsed)


def no_answer(n, error):
    """A failed run: every demo without changepoints."""
    return {"demos": [{"changepoint_times": [], "rejected_times": [], "pruned_times": [],
                       "zones": []}] * n,
            "selected_features": [], "selected_weights": [], "warnings": [error]}


def score_seed(args, name, seed, work):
    """{tolerance: scores} of one class and seed (lfd_tools.segmentation_scoring.score_answer),
    plus the run's error and time."""
    truth = signal_classes.write_class(name, seed, os.path.join(work, "seed%d" % seed),
                                       args.demos)
    folder = os.path.join(work, "seed%d" % seed, name)
    inputs = [os.path.join(folder, d["file"]) for d in truth["demos"]]
    clocks = [np.loadtxt(p, delimiter=",", skiprows=1, usecols=0) for p in inputs]
    spans = [(c[0], c[-1]) for c in clocks]
    windows = [[(c[0] + b, c[0] + b) for b in d["boundaries_s"]]
               for c, d in zip(clocks, truth["demos"])]
    answer, error, elapsed = segment(args, folder, truth)
    scores = {tol: segmentation_scoring.score_answer(answer, args.procedure or "default", inputs,
                                                     windows, spans, tol,
                                                     elapsed) for tol in TOLERANCES}
    for s in scores.values():
        for d, t in zip(s["details"], truth["demos"]):
            d.update({"seed": seed, "truth_s": t["boundaries_s"]})
    return scores, error, elapsed


def score_class(args, name, work):
    """One class over every seed: per tolerance the pooled summary (judge.summarize_scores over
    all seeds' demos), per seed the correct counts, errors and times."""
    runs = [(seed,) + score_seed(args, name, seed, work) for seed in args.seeds]
    out = {"rate_hz": signal_classes.CLASSES[name].rate, "seeds": [], "at": {}}
    for seed, scores, error, elapsed in runs:
        out["seeds"].append({"seed": seed, "error": error, "seconds": elapsed,
                             "warnings": scores[0.5]["warnings"],
                             "selected_features": scores[0.5]["selected_features"],
                             "correct": {str(t): scores[t]["correct"] for t in TOLERANCES},
                             "demos": scores[0.5]["demos"]})
    for tol in TOLERANCES:
        details = [d for _, scores, _, _ in runs for d in scores[tol]["details"]]
        out["at"][str(tol)] = dict(judge.summarize_scores(details, tol), details=details)
    details = out["at"]["0.5"]["details"]
    out["changepoints_per_demo"] = float(np.mean([len(d["changepoints_s"]) for d in details]))
    out["boundaries_per_demo"] = float(np.mean([len(d["truth_s"]) for d in details]))
    return out


COLUMNS = "%-22s %5s %-14s %6s %-14s %6s %6s %6s %7s %7s %5s %9s %7s"
HEADER = COLUMNS % results_doc.SIGNAL_CLASS_HEADER


def row(name, r):
    errors = ["seed %d: %s" % (s["seed"], s["error"]) for s in r["seeds"] if s["error"]]
    return (COLUMNS % results_doc.signal_class_cells(name, r)
            + "".join("\n    error: " + e for e in errors))


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=DEFAULT_CLI, help="the `segment` CLI (default: %(default)s)")
    ap.add_argument("--config", default="",
                    help="passed to the CLI as --config (default: the CLI's own)")
    ap.add_argument("--procedure", default="",
                    help="passed to the CLI as --procedure (default: the config's)")
    ap.add_argument("--classes", default="",
                    help="comma-separated (default: all, rate variants included)")
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--demos", type=int, default=None,
                    help="demos per task (default: the count each seed draws)")
    ap.add_argument("--out", default="", help="write every figure and per-demo detail here (JSON)")
    ap.add_argument("--min-success", type=float, default=None,
                    help="exit 1 when a class's success rate at 0.5 s is below this (0-1)")
    ap.add_argument("--keep", default="", help="generate into this folder and keep it")
    ap.add_argument("--update-docs", action="store_true",
                    help="rewrite docs/results.md's section bench-signal-classes from the result "
                         "(only when asked: CI runs this bench on one seed)")
    args = ap.parse_args()
    args.seeds = [int(s) for s in args.seeds.split(",") if s]
    names = [c for c in args.classes.split(",") if c] or list(signal_classes.CLASSES)
    unknown = [c for c in names if c not in signal_classes.CLASSES]
    if unknown:
        ap.error("unknown class %s; known: %s"
                 % (", ".join(unknown), ", ".join(signal_classes.CLASSES)))
    if args.demos is not None and args.demos < 2:
        ap.error("--demos must be at least 2 (the segmentation compares demos)")
    if args.update_docs and args.demos is not None:
        ap.error("--update-docs records the default demo counts; run without --demos")
    if not os.access(args.cli, os.X_OK):
        ap.error("no `segment` CLI at %s (./lfd build, or --cli)" % args.cli)
    if args.update_docs:
        try:
            results_doc.check("signal-classes")
        except RuntimeError as exc:
            ap.error(str(exc))
    return args, names


def main():
    args, names = parse_args()
    work = args.keep or tempfile.mkdtemp(prefix="signal_classes_")
    results = {}
    print("cli %s, procedure %s, config %s, seeds %s, demos %s"
          % (args.cli, args.procedure or "(config's)", args.config or "(shipped)", args.seeds,
             args.demos or "(drawn)"))
    print(HEADER)
    try:
        for name in names:
            results[name] = score_class(args, name, work)
            print(row(name, results[name]), flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    result = {"cli": args.cli, "config": args.config, "procedure": args.procedure,
              "seeds": args.seeds, "demos": args.demos, "tolerances_s": list(TOLERANCES),
              "classes": results}
    if args.out:
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)
    if args.update_docs:
        results_doc.report_update("signal-classes", result)
    below = [n for n, r in results.items() if args.min_success is not None
             and r["at"]["0.5"]["success_rate"] < args.min_success]
    if below:
        print("below %.2f at 0.5 s: %s" % (args.min_success, ", ".join(below)), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
