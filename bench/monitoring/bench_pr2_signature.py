#!/usr/bin/env python3
"""Offline execution monitoring on the PR2 IKEA runs (docs/results.md, "PR2 offline scoring"): each
failed run should score above every successful one on the segment where it failed.

Protocol (nothing learned from the run being scored): for each pair of successful runs, the
`signature` CLI learns the sensory signature of the four labelled phases from that pair and scores
the held-out successful run and the three failed runs. The boundaries are the labels' part starts
(labels.json boundaries_rel). The channels are the topics file's sensor features (the gripper's
opening and command, the arm's tracking error), nothing chosen per run.

Where each failed run failed (the dataset's readme): neg_1 misses the hole (insert_leg), neg_2
misses the grasp (pickup_leg), neg_3 misses the hole and bumps the table (insert_leg).

  bench_pr2_signature.py [--data ../shared/data/pr2_ikea] [--cli PATH] [--out result.json]
                         [--update-docs]

--update-docs: rewrite docs/results.md's section bench-pr2-signature from the result
(lfd_tools.results_doc; run with devel/setup.bash sourced).
"""
import argparse
import itertools
import json
import os
import subprocess
import sys

from lfd_tools import results_doc

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
ERROR = "/l_arm_controller_loose/state/error/positions/l_%s_joint"
SENSORS = (["/l_gripper_controller/state/process_value", "/l_gripper_controller/state/command"] +
           [ERROR % j for j in ("shoulder_pan", "shoulder_lift", "upper_arm_roll", "elbow_flex",
                                "forearm_roll", "wrist_flex", "wrist_roll")])
OBJECT = ["/ar_world_model/objects/id=0/pose/pose/position/" + a for a in "xyz"]
FAILED_SEGMENT = {"neg_1": "insert_leg", "neg_2": "pickup_leg", "neg_3": "insert_leg"}


def demo_arguments(kind, data, run, labels):
    parts = ",".join(os.path.join(data, p["file"]) for p in labels["runs"][run]["parts"])
    bounds = ",".join("%.3f" % b for b in labels["runs"][run]["boundaries_rel"])
    return [kind, parts, "--boundaries", bounds]


def score(cli, topics, channels, data, labels, train, runs):
    cmd = [cli, "--topics", topics] + (["--channels", channels] if channels else [])
    for r in train:
        cmd += demo_arguments("--demo", data, r, labels)
    for r in runs:
        cmd += demo_arguments("--run", data, r, labels)
    out = subprocess.run(cmd, capture_output=True, text=True)
    result = json.loads(out.stdout)
    if not result.get("success"):
        sys.exit("signature failed: %s" % result.get("error"))
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=os.path.normpath(os.path.join(ROOT, "..", "shared",
                                                                    "data", "pr2_ikea")))
    ap.add_argument("--cli", default=os.path.join(ROOT, "devel", "lib", "lfd_segmentation",
                                                  "signature"))
    ap.add_argument("--topics", default=os.path.join(ROOT, "config", "topics_pr2_ikea.yaml"))
    ap.add_argument("--channels",
                    help="comma-separated features to monitor (default: the topics' sensors)")
    ap.add_argument("--with-object", action="store_true",
                    help="monitor the leg marker's position too (the AR world model, a camera)")
    ap.add_argument("--out")
    ap.add_argument("--update-docs", action="store_true",
                    help="rewrite docs/results.md's section bench-pr2-signature from the result")
    a = ap.parse_args()
    if a.update_docs:
        try:
            results_doc.check("pr2-signature")
        except RuntimeError as exc:
            ap.error(str(exc))
    labels = json.load(open(os.path.join(a.data, "labels.json")))
    if a.with_object:
        a.channels = ",".join(SENSORS + OBJECT)
    phases = labels["phases"]
    positives = sorted(r for r, v in labels["runs"].items() if v["outcome"] == "success")
    negatives = sorted(FAILED_SEGMENT)
    rows, ok, total = [], 0, 0
    print("%-14s %-8s %-12s %8s %8s  worst channel at the failed segment"
          % ("learned from", "run", "segment", "score", "pos max"))
    for train in itertools.combinations(positives, 2):
        held = [r for r in positives if r not in train]
        result = score(a.cli, a.topics, a.channels, a.data, labels, train, held + negatives)
        by_run = dict(zip(held + negatives, result["runs"]))
        for neg in negatives:
            s = phases.index(FAILED_SEGMENT[neg])
            pos_scores = [max(by_run[p]["segments"][s]["scores"]) for p in held]
            neg_score = max(by_run[neg]["segments"][s]["scores"])
            worst = by_run[neg]["segments"][s]["worst"]
            total += 1
            ok += neg_score > max(pos_scores)
            rows.append({"train": train, "run": neg, "segment": FAILED_SEGMENT[neg],
                         "score": neg_score, "positive_max": max(pos_scores), "worst": worst})
            print("%-14s %-8s %-12s %8s %8s  %s" % results_doc.pr2_case_cells(rows[-1]))
        for p in held:
            rows.append({"train": train, "run": p,
                         "alarms": [max(seg["scores"]) > 1 for seg in by_run[p]["segments"]],
                         "scores": [max(seg["scores"]) for seg in by_run[p]["segments"]]})
            print("%-14s %-8s nominal, per segment: %s" % ("+".join(train), p,
                  " ".join("%.2f" % max(seg["scores"]) for seg in by_run[p]["segments"])))
            for seg in by_run[p]["segments"]:
                if max(seg["scores"]) > 1:
                    w = seg["worst"]
                    print("    false alarm: %s t=%.1f s phase %.2f expected %.3g measured %.3g" % (
                        w["channel"], w["time"], w["phase"], w["expected"], w["measured"]))
    print("failed runs above every held-out successful run on their failed segment: %d of %d"
          % (ok, total))
    result = {"rows": rows, "separated": ok, "cases": total}
    if a.out:
        json.dump(result, open(a.out, "w"), indent=1)
    if a.update_docs:
        results_doc.report_update("pr2-signature", result)


if __name__ == "__main__":
    main()
