#!/usr/bin/python3
"""Where a labelled set's true boundaries lie against the evidence a segmenter can see: runs the
`segment` CLI once (joint procedure) on every demo of a ground-truth file or labels.json (the
formats of evaluate_segmentation.py --truth / --labels), then, per true boundary:

  pause     the rest of the state features it lies in (s from the demo's start), if any
  onset     the nearest motion onset (the end of a pause other than the demo's last), and the
            signed error truth - onset (s)
  event     the nearest sensory event (signed error)
  found     the segmenter's nearest changepoint (signed error)

and the ceiling of each kind of placement at each tolerance T: the demos whose every boundary has
an onset (or an onset or event) within T. A ceiling below a target says that no placement on that
evidence reaches it: the labels mark something the signals do not show (a recording split while
the robot waits).

  truth_vs_evidence.py (--truth FILE | --labels labels.json) [--topics YAML] [--config YAML]
                       [--cli PATH] [--tolerances 0.5,1.0] [--out result.json]

Run with devel/setup.bash sourced (lfd_tools).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from lfd_tools import bags

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DEFAULT_CLI = os.path.join(ROOT, "devel", "lib", "lfd_segmentation", "segment")


def segment(args, demos):
    """The CLI's JSON answer for every demo (each demo's bags joined with commas)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "segment.json")
        cmd = [args.cli, "--no-profiles", "--procedure", "joint", "--output", out]
        cmd += ["--topics", args.topics] if args.topics else []
        cmd += ["--config", args.config] if args.config else []
        cmd += [",".join(paths) for _, paths, _ in demos]
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              universal_newlines=True)
        if proc.returncode != 0:
            sys.exit("segment failed (exit %d): %s" % (proc.returncode, proc.stderr[-2000:]))
        with open(out) as f:
            return json.load(f)


def nearest(times, t):
    """Signed error t - the nearest of `times`, or None without any."""
    return t - min(times, key=lambda x: abs(t - x)) if times else None


def boundary_rows(demo, truth, t0):
    """Per true boundary (s from t0, the first bag's start), where it lies against the
    evidence."""
    pauses = [(p["begin_time"] - t0, p["end_time"] - t0) for p in demo["pauses"]]
    # Where motion resumes: not after the demo's first rest (the motion's start) nor its last.
    onsets = [p["end_time"] - t0 for p in demo["pauses"]
              if p["begin"] > 0 and p["end"] < demo["num_samples"] - 1]
    events = [t - t0 for t in demo["event_times"]]
    found = [t - t0 for t in demo["changepoint_times"]]
    rows = []
    for t in truth:
        inside = [p for p in pauses if p[0] <= t <= p[1]]
        rows.append({"truth_s": t, "pause_s": list(inside[0]) if inside else None,
                     "onset_error_s": nearest(onsets, t),
                     "event_error_s": nearest(events, t),
                     "found_error_s": nearest(found, t)})
    return rows


def within(error, tolerance):
    return error is not None and abs(error) <= tolerance


def ceilings(per_demo, tolerances):
    """Per tolerance: demos whose every boundary has an onset (an onset or an event; the
    segmenter's changepoint) within it."""
    out = {}
    for tol in tolerances:
        out[str(tol)] = {
            "onsets": sum(all(within(r["onset_error_s"], tol) for r in rows) for rows in per_demo),
            "onsets_or_events": sum(
                all(within(r["onset_error_s"], tol) or within(r["event_error_s"], tol)
                    for r in rows) for rows in per_demo),
            "found": sum(all(within(r["found_error_s"], tol) for r in rows) for rows in per_demo),
            "demos": len(per_demo)}
    return out


def fmt(x):
    return "-" if x is None else "%+.2f" % x


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    which = ap.add_mutually_exclusive_group(required=True)
    which.add_argument("--truth", help="ground-truth file (demos: [{name, bags, changepoints_s}])")
    which.add_argument("--labels", help="a labels.json of phase-split runs (pr2_ikea format)")
    ap.add_argument("--topics", default="", help="the segment CLI's --topics")
    ap.add_argument("--config", default="", help="the segment CLI's --config")
    ap.add_argument("--cli", default=DEFAULT_CLI)
    ap.add_argument("--tolerances", default="0.5,1.0")
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    demos = (bags.load_truth_file(args.truth) if args.truth else
             bags.parse_truth(bags.truth_from_labels(args.labels), "", args.labels))
    answer = segment(args, demos)
    # Times from the first bag's start, as evaluate_segmentation.py scores them.
    per_demo = [boundary_rows(d, truth, bags.bag_span(paths[0])[0])
                for d, (_, paths, truth) in zip(answer["demos"], demos)]
    print("%-8s %8s %15s %8s %8s %8s" % ("demo", "truth_s", "in pause (s)", "onset", "event",
                                         "found"))
    for (name, _, _), rows in zip(demos, per_demo):
        for r in rows:
            pause = "%.1f-%.1f" % tuple(r["pause_s"]) if r["pause_s"] else "-"
            print("%-8s %8.2f %15s %8s %8s %8s" % (name, r["truth_s"], pause,
                                                   fmt(r["onset_error_s"]),
                                                   fmt(r["event_error_s"]),
                                                   fmt(r["found_error_s"])))
    tolerances = [float(t) for t in args.tolerances.split(",")]
    result = {"demos": [{"name": name, "boundaries": rows}
                        for (name, _, _), rows in zip(demos, per_demo)],
              "ceilings": ceilings(per_demo, tolerances)}
    for tol, c in result["ceilings"].items():
        print("at %s s: every boundary near an onset %d/%d, near an onset or an event %d/%d; "
              "segmented %d/%d" % (tol, c["onsets"], c["demos"], c["onsets_or_events"],
                                   c["demos"], c["found"], c["demos"]))
    if args.out:
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
