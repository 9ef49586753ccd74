#!/usr/bin/python3
"""Times README command 1 stage by stage: runs the headless pipeline into a fresh folder and prints
each stage's wall time, the wall time per demonstration (datasets stage / demos recorded) and per
reproduced goal (reproduce stage / goals), from the run's report.json.

  bench_pipeline.py [--out DIR] [--keep] [--runs N] [--json FILE] [--update-docs]
                    -- [pipeline.py options, e.g. --datasets ...]

Run it after `./lfd build` with devel/setup.bash sourced. Without --out a temporary folder is used
and removed (--keep keeps it). The stage times include each stage's ROS start-up; the per-demo and
per-goal figures are stage time divided by work done, so start-up cost shows as a higher figure on
small runs. Prints one table per run, then the median of every figure when --runs > 1. --json
writes every figure ({"runs", "median", "pipeline_args"}); --update-docs rewrites docs/results.md's
section bench-pipeline from them (lfd_tools.results_doc).
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from lfd_tools import results_doc

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
PIPELINE = os.path.join(ROOT, "lfd_launch", "scripts", "pipeline.py")
STAGES = ("datasets", "segment", "learn", "reproduce", "figures")


def figures_of(report, wall):
    """{figure: seconds} of one run's report."""
    timings = report.get("timings", {})
    demos = sum(d.get("demos", 0) for d in report.get("datasets", {}).values())
    goals = sum(len(e.get("goals", [])) for key in ("reproduction", "reproduction_teleop")
                for e in report.get(key, {}).values())
    out = {"%s_s" % s: timings.get("%s_s" % s) for s in STAGES}
    out["wall_s"] = wall
    out["per_demo_s"] = timings["datasets_s"] / demos if demos and "datasets_s" in timings else None
    out["per_goal_s"] = (timings["reproduce_s"] / goals if goals and "reproduce_s" in timings
                         else None)
    out["demos"], out["goals"] = demos, goals
    return out


def show(figures):
    for key, value in figures.items():
        print("  %-14s %s" % (key, results_doc.pipeline_figure_text(key, value)))


def one_run(out, pipeline_args):
    start = time.time()
    rc = subprocess.call(["/usr/bin/python3", PIPELINE, "--out", out] + pipeline_args,
                         stdout=subprocess.DEVNULL)
    wall = time.time() - start
    with open(os.path.join(out, "report.json")) as f:
        report = json.load(f)
    if rc != 0:
        print("pipeline exited %d: %s" % (rc, "; ".join(report.get("problems", []))),
              file=sys.stderr)
    return figures_of(report, wall)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None)
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--json", default=None, help="write every figure to this file")
    ap.add_argument("--update-docs", action="store_true",
                    help="rewrite docs/results.md's section bench-pipeline from the figures")
    ap.add_argument("pipeline_args", nargs="*")
    args = ap.parse_args()
    if args.update_docs:
        try:
            results_doc.check("bench-pipeline")
        except RuntimeError as exc:
            ap.error(str(exc))
    runs = []
    for i in range(args.runs):
        out = args.out or tempfile.mkdtemp(prefix="lfd_bench_pipeline_")
        if args.out and args.runs > 1:
            out = os.path.join(args.out, "run%d" % i)
        if os.path.exists(os.path.join(out, "report.json")):
            sys.exit("%s already holds a run: the benchmark needs a fresh folder" % out)
        figures = one_run(out, args.pipeline_args)
        print("run %d (%s):" % (i + 1, out))
        show(figures)
        runs.append(figures)
        if not args.out and not args.keep:
            shutil.rmtree(out, ignore_errors=True)
    median = None
    if len(runs) > 1:
        median = {k: (statistics.median([r[k] for r in runs if r[k] is not None])
                      if any(r[k] is not None for r in runs) else None) for k in runs[0]}
        print("median of %d runs:" % len(runs))
        show(median)
    result = {"runs": runs, "median": median, "pipeline_args": args.pipeline_args}
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    if args.update_docs:
        results_doc.report_update("bench-pipeline", result)


if __name__ == "__main__":
    main()
