#!/usr/bin/python3
"""Where the wall time of recording demonstrations goes, between the simulated steps.

  profile_demo.py [--dataset sim_wipe] [--demos 2] [--out DIR] [--json FILE] [--update-docs]

Records `--demos` demonstrations of one dataset with generate_datasets.py (one launch: bridge,
recorder, demonstrator, robot_state_publisher, as the datasets stage runs them) and breaks the wall
time down from three sources:
  * the demonstrator's per-demo summary (`wall`, `wall_parts`): its /bridge/step round trips, the
    waits for fresh sensors, the fixed settle sleeps, the recorder's start/stop calls, the scene
    resets and the IK planning;
  * the bridge's log line at each reset: of its time, physics (mj_step and the workcell's control
    layer) and publishing (/clock, sensors, tf; serialization and the sockets);
  * the CPU time of every process of the run (user and system, sampled from /proc).
What a demo's step round trips cost beyond the bridge's own work is the lockstep handshake (the
service's sockets and the demonstrator's wake-up). Time outside the demos is process start-up,
the graph coming up, and judging the bags.

Run after `./lfd build` with devel/setup.bash sourced; needs no running master. --update-docs
rewrites docs/results.md's section profile-demo from the figures (lfd_tools.results_doc).
"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import yaml

from lfd_tools import results_doc
from lfd_tools.processes import CpuSampler

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
GENERATE = os.path.join(ROOT, "lfd_sim_bridge", "scripts", "generate_datasets.py")
BRIDGE_LINE = re.compile(r"wall time since the last reset, (\d+) steps: (\{.*\})")
ROS_STAMP = re.compile(r"^\[ *\w+\] \[(\d+\.\d+)(?:, (\d+\.\d+))?\]: (.*)$")


def demo_summaries(out):
    demos = []
    for path in glob.glob(os.path.join(out, "*", "demonstrator_summary_*.yaml")):
        with open(path) as f:
            demos += [d for d in (yaml.safe_load(f) or {}).get("demos", []) if d.get("recorded")]
    return demos


def log_facts(out):
    """The bridge's per-reset breakdowns and the wall stamps of the demonstrator's milestones."""
    bridge, stamps = [], {}
    for path in glob.glob(os.path.join(out, "logs", "*.log")):
        with open(path, errors="replace") as f:
            for line in f:
                m = BRIDGE_LINE.search(line)
                if m and int(m.group(1)) > 0:
                    bridge.append(json.loads(m.group(2)))
                s = ROS_STAMP.match(line.strip())
                if not s:
                    continue
                wall, text = float(s.group(1)), s.group(3)
                if text.startswith("demonstrator: waiting for the bridge"):
                    stamps.setdefault("demonstrator_up", wall)
                elif ("speed" in text and text.startswith("demonstrator: ")
                      and "configuration" in text):
                    stamps.setdefault("first_demo", wall)
                elif "recorded," in text and text.startswith("demonstrator: configuration"):
                    stamps["last_demo_end"] = wall
    return bridge, stamps


def summed(dicts):
    total = {}
    for d in dicts:
        for k, v in d.items():
            total[k] = total.get(k, 0.0) + v
    return total


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", default="sim_wipe")
    parser.add_argument("--demos", type=int, default=2)
    parser.add_argument("--out", help="keep the run here (default: a temporary folder, removed)")
    parser.add_argument("--json", help="also write the figures to this file")
    parser.add_argument("--update-docs", action="store_true",
                        help="rewrite docs/results.md's section profile-demo from the figures")
    args = parser.parse_args()
    if args.update_docs:
        try:
            results_doc.check("profile-demo")
        except RuntimeError as exc:
            parser.error(str(exc))
    out = args.out or tempfile.mkdtemp(prefix="lfd_profile_demo_")
    start = time.time()
    proc = subprocess.Popen(["/usr/bin/python3", GENERATE, "--out", out, "--datasets", args.dataset,
                             "--demos", str(args.demos), "--force"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    sampler = CpuSampler(proc.pid)
    sampler.start()
    output = proc.communicate()[0]
    wall = time.time() - start
    sampler.stop()
    if proc.returncode != 0:
        print(output[-3000:])
        sys.exit("generate_datasets.py failed (exit %d)" % proc.returncode)

    demos = demo_summaries(out)
    bridge, stamps = log_facts(out)
    sim_s = sum(d["duration"] for d in demos)
    demo_wall = sum(d["wall"] for d in demos)
    parts = summed(d.get("wall_parts", {}) for d in demos)
    counts = summed(d.get("wall_counts", {}) for d in demos)
    bridge_parts = summed(bridge)
    step_kinds = results_doc.DEMO_STEP_KINDS
    handshake = sum(parts.get(k, 0.0) for k in step_kinds) - sum(bridge_parts.values())
    result = {
        "dataset": args.dataset, "demos": len(demos), "sim_s": sim_s, "wall_s": wall,
        "demos_wall_s": demo_wall,
        "before_first_demo_s": stamps["first_demo"] - start if "first_demo" in stamps else None,
        "graph_up_s": stamps["demonstrator_up"] - start if "demonstrator_up" in stamps else None,
        "after_last_demo_s": (start + wall - stamps["last_demo_end"] if "last_demo_end" in stamps
                              else None),
        "demonstrator_parts_s": parts,
        "demonstrator_counts": counts,
        "demonstrator_other_s": demo_wall - sum(parts.values()),
        "bridge_parts_s": bridge_parts,
        "step_handshake_s": handshake,
        "cpu_s": {name: {"user": round(u, 2), "system": round(s, 2)}
                  for name, (u, s) in sampler.by_name().items()},
    }
    print(results_doc.demo_profile_summary(result))
    for key in ("graph_up_s", "before_first_demo_s", "after_last_demo_s"):
        if result[key] is not None:
            print("  %-34s %6.2f s" % (key, result[key]))
    calls = int(sum(counts.get(k, 0) for k in step_kinds))
    print("  within the demos (%.2f s; %.2f ms per step round trip beyond the bridge's work):"
          % (demo_wall, 1000.0 * handshake / max(calls, 1)))
    for name, seconds in results_doc.demo_profile_rows(result):
        print("    %-48s %6.2f s  %5.1f%%"
              % (name, seconds, 100.0 * seconds / max(demo_wall, 1e-9)))
    print("  CPU by process (user + system):")
    for name, cpu in result["cpu_s"].items():
        if cpu["user"] + cpu["system"] >= 0.05:
            print("    %-24s %6.2f + %6.2f s" % (name, cpu["user"], cpu["system"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    if args.update_docs:
        results_doc.report_update("profile-demo", result)
    if not args.out:
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    main()
