#!/usr/bin/python3
"""Run every catkin test target (each gtest binary, each rostest file) on a pool of workers.

`make run_tests` runs the targets one after another, although most of a rostest's time is spent
waiting (on sim time, timeouts, process start-up) and every rostest starts its own master on a
free port. This runner runs the leaf `_run_tests_*` targets of an already built tree (`./lfd build
tests`) with N at a time, longest first, so the two slow halves of the suite overlap.

Each target's output is captured and printed whole when it ends, so the log stays readable. Its
wall time goes to `test_durations.json` in the build folder; the next run schedules from it
(and from the committed `test/durations.json` on a fresh tree). The run closes with the slowest
ten targets.

Usage: run_suites.py BUILD_DIR [--jobs N] [--only SUBSTRING]
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

COMMITTED_DURATIONS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "durations.json")
# A per-target limit well above the slowest target's quiet time (about 10 min), so one hung
# target cannot eat CI's 90 minutes; rostest's own time limits normally end a hang first.
TARGET_TIMEOUT_S = 1500


def leaf_targets(build_dir):
    """{target: its build.make} for every `_run_tests_<pkg>_<kind>_<name>` target that runs one
    gtest binary or rostest file (aggregate targets have no command of their own). Only the
    targets of the current configuration: a removed test's folder stays in the build tree."""
    help_text = subprocess.run(["make", "help"], cwd=build_dir, check=True, capture_output=True,
                               text=True).stdout
    current = set(re.findall(r"^\.\.\. (_run_tests_\S+)$", help_text, flags=re.M))
    targets = {}
    for makefile in glob.glob(os.path.join(build_dir, "**", "CMakeFiles", "_run_tests_*.dir", "build.make"),
                              recursive=True):
        name = os.path.basename(os.path.dirname(makefile))[:-len(".dir")]
        with open(makefile) as f:
            if name in current and "run_tests.py" in f.read():
                targets[name] = makefile
    return targets


def load_durations(build_dir):
    durations = {}
    for path in (COMMITTED_DURATIONS, os.path.join(build_dir, "test_durations.json")):
        try:
            with open(path) as f:
                durations.update(json.load(f))
        except (OSError, ValueError):
            pass
    return durations


def schedule(targets, durations):
    """Longest first; a target never timed counts as a rostest-sized one (they dominate)."""
    unknown = max(durations.values(), default=60.0)
    return sorted(targets, key=lambda t: -durations.get(t, unknown if "rostest" in t else 1.0))


def run_target(build_dir, target, makefile, log_dir):
    """Only the target's own command, through its build.make as make's Makefile2 calls it: not
    `make <target>`, which would first check every build dependency and clean the package's
    other results."""
    relative = os.path.relpath(os.path.dirname(makefile), build_dir)
    command = ["make", "-s", "-f", os.path.join(relative, "build.make"), os.path.join(relative, "build")]
    start = time.monotonic()
    log_path = os.path.join(log_dir, target + ".log")
    with open(log_path, "w") as log:
        try:
            rc = subprocess.run(command, cwd=build_dir, stdout=log, stderr=subprocess.STDOUT,
                                timeout=TARGET_TIMEOUT_S).returncode
        except subprocess.TimeoutExpired:
            log.write("\n[tests] %s killed after %d s\n" % (target, TARGET_TIMEOUT_S))
            rc = -1
    return target, rc, time.monotonic() - start, log_path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build_dir")
    parser.add_argument("--jobs", type=int, default=int(os.environ.get("LFD_TEST_JOBS", os.cpu_count() or 1)))
    parser.add_argument("--only", default="", help="run only targets whose name contains this")
    args = parser.parse_args()
    build_dir = os.path.abspath(args.build_dir)
    log_dir = os.path.join(build_dir, "test_logs")
    os.makedirs(log_dir, exist_ok=True)
    durations = load_durations(build_dir)
    makefiles = leaf_targets(build_dir)
    targets = schedule([t for t in makefiles if args.only in t], durations)
    print("[tests] %d targets, %d at a time" % (len(targets), args.jobs), flush=True)
    printing = threading.Lock()
    measured = {}
    start = time.monotonic()

    def report(result):
        target, rc, seconds, log_path = result
        measured[target] = round(seconds, 1)
        with printing, open(log_path, errors="replace") as log:
            sys.stdout.write(log.read())
            print("[tests] %s: %.1f s%s" % (target, seconds, "" if rc == 0 else " (exit %d)" % rc), flush=True)

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for future in [pool.submit(run_target, build_dir, t, makefiles[t], log_dir) for t in targets]:
            future.add_done_callback(lambda f: report(f.result()))
    durations.update(measured)
    with open(os.path.join(build_dir, "test_durations.json"), "w") as f:
        json.dump(durations, f, indent=1, sort_keys=True)
    print("[tests] all targets: %.0f s wall, %.0f s summed" % (time.monotonic() - start, sum(measured.values())))
    print("[tests] slowest ten:")
    for target, seconds in sorted(measured.items(), key=lambda kv: -kv[1])[:10]:
        print("[tests]   %7.1f s  %s" % (seconds, target))
    return 0  # failures are counted from the result files by summarize_results.py


if __name__ == "__main__":
    sys.exit(main())
