#!/usr/bin/python3
"""Generate the demonstration datasets of every task (sim and teleop-like), then summarise them.

  generate_datasets.py --out DIR [--datasets sim_grasp,teleop_wipe,...] [--seed N]
                       [--tasks-dir DIR] [--demos N] [--timeout S] [--force]

Each dataset <DIR>/<mode>_<task> gets one bag per configuration of the task's file
(config/tasks/<task>.yaml, or --tasks-dir). One `roslaunch lfd_launch demonstrate.launch` (bridge as
fast as possible + recorder + demonstrator) records every dataset in turn, and a second one the
demos that failed; logs/<dataset>.log holds the launch's output while that dataset was recorded.
The datasets default to every task in both modes. A dataset whose every bag is a physically
successful demonstration is skipped, and the demonstrator skips bags that exist, so a rerun resumes
where an interrupted one stopped. A bag that is no such demonstration (cut off when a node crashed,
unreadable, or failed by the task's criterion) is set aside as <bag>.failed and recorded again;
a crashed recording's *.bag.active is kept and reindexed by the recorder (.crashed, .recovered).
--demos N records N configurations per dataset, spread over the task's list.
Uses the ROS master of ROS_MASTER_URI when one is running, else starts a private one.
Prints a table: dataset, demos, mean duration, physical successes (the task file's criterion,
judged from each bag by lfd_tools.judge), recorded topics.
Exit status 0 only if every dataset is complete, every demo succeeded physically and no node of
the launch crashed (a crash is reported even when the retry recorded the missing demos).
"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time

import yaml

from lfd_tools import redo, tasks
from lfd_tools.master import master_for_this_process, stop_group

STOP_TIMEOUT_S = 30.0  # for a launch to stop its nodes on SIGINT before it is killed


def configurations(task, mode, demos=0):
    return [s["id"] for s in tasks.spread(tasks.scenes(task, mode), demos)]


def bag_name(out, task, mode, config):
    return os.path.join(out, "%s_%s_%02d.bag" % (task, mode, config))


def demo_errors(out):
    """{configuration: error} of the demos the demonstrator could not record (its summary)."""
    errors = {}
    for summary in glob.glob(os.path.join(out, "demonstrator_summary_*.yaml")):
        with open(summary) as f:
            for demo in (yaml.safe_load(f) or {}).get("demos", []):
                if demo.get("error"):
                    errors[demo["configuration"]] = demo["error"]
    return errors


# roslaunch's line for a node that ended by a signal: "[recorder-3] process has died [pid 42,
# exit code -6, cmd ... __name:=recorder ...", or for a required node (the bridge, the
# demonstrator) "process has died [pid 42, exit code -11, cmd ... __name:=bridge ..." after a line
# "REQUIRED process [bridge-1] has died!". A negative code is the signal number (6 SIGABRT,
# 11 SIGSEGV).
CRASH_LINE = re.compile(r"(?:\[([\w-]+)\] )?process has died \[pid (\d+), exit code (-\d+)"
                        r"(?:, cmd [^\]]*?__name:=([\w-]+))?")


def crashes_in(log_text):
    """[(process, pid, signal)] of every node of the launch that died by a signal."""
    return [(m.group(1) or m.group(4) or "?", int(m.group(2)), -int(m.group(3)))
            for m in CRASH_LINE.finditer(log_text)]


# The demonstrator's line as it starts a dataset (demonstrator_node.cpp): where the launch's
# output is split into per-dataset logs.
DATASET_LINE = re.compile(r"demonstrator: dataset (\S+): ")


def generate(names, out_root, args, log_dir, crashes, outcomes):
    """Records the missing demos of the datasets `names` with one launch (one simulation records
    them in turn); the demos that failed are tried once more in a second launch (a fresh scene),
    as a demonstrator redoes a botched demonstration."""
    for attempt in (1, 2):
        jobs = [missing_demos(n, out_root, args, attempt, outcomes) for n in names]
        jobs = [job for job in jobs if job]
        if not jobs:
            break
        record(jobs, args, log_dir, attempt, crashes)


def missing_demos(name, out_root, args, attempt, outcomes):
    """The demonstrator's job for the demos of `name` to record (no bag, or a bag set aside as no
    usable demonstration), or None when it is complete."""
    mode, task = name.split("_", 1)
    out = os.path.join(out_root, name)
    ids = configurations(task, mode, args.demos)
    os.makedirs(out, exist_ok=True)
    missing, aside = redo.demos_to_record({i: bag_name(out, task, mode, i) for i in ids}, outcomes)
    for i, path, reason in aside:
        print("[datasets] %s: configuration %d is no usable demonstration (%s): kept as %s, "
              "recorded again" % (name, i, reason, path), flush=True)
    if not missing:
        if attempt == 1:
            print("[datasets] %s: complete (%d bags), skipped" % (name, len(ids)), flush=True)
        return None
    if attempt > 1:
        errors = demo_errors(out)
        for i in missing:
            print("[datasets] %s: configuration %d was not recorded (%s); trying again"
                  % (name, i, errors.get(i, "no error reported")), flush=True)
    print("[datasets] %s: recording %d of %d demos" % (name, len(missing), len(ids)), flush=True)
    return {"task": task, "mode": mode, "output_dir": out, "configurations": missing,
            "tasks_dir": os.path.dirname(tasks.task_file(task))}


def record(jobs, args, log_dir, attempt, crashes):
    """One demonstrate.launch for every job; its output goes to the log of the dataset being
    recorded (split_output), so each log, its wall time and its crashes are the dataset's."""
    names = ["%s_%s" % (j["mode"], j["task"]) for j in jobs]
    # The recorder writes only inside allowed roots: these datasets' folders, wherever they are.
    roots = [f(j["output_dir"]) for j in jobs for f in (os.path.abspath, os.path.realpath)]
    cmd = ["roslaunch", "lfd_launch", "demonstrate.launch", "mode:=" + jobs[0]["mode"],
           "seed:=%d" % args.seed, "datasets:=" + json.dumps(jobs),
           "allowed_roots:=" + json.dumps(list(dict.fromkeys(roots)))]
    timeout = args.timeout * len(jobs)
    # Line-buffered: a log shows how far its dataset is (tail -f) while the launch runs.
    logs = {n: open(os.path.join(log_dir, n + ".log"), "w" if attempt == 1 else "a", buffering=1)
            for n in names}
    for log in logs.values():
        log.write("# attempt %d, one launch for %s\n" % (attempt, ", ".join(names)))
    launch_start = time.time()
    # Line-buffered node output: a pipe is block-buffered, and a dataset's lines (its start line
    # included) arrived when the buffer filled, in the next dataset's log and wall time.
    env = dict(os.environ, ROSCONSOLE_STDOUT_LINE_BUFFERED="1", PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env,
                            start_new_session=True, universal_newlines=True, errors="replace")
    timed_out = threading.Event()

    def expire():  # SIGINT first: roslaunch stops its nodes, which would otherwise hold the pipe
        timed_out.set()
        stop_group(proc, STOP_TIMEOUT_S)

    timer = threading.Timer(timeout, expire)
    timer.daemon = True
    timer.start()
    try:
        split_output(proc.stdout, logs, names[0], crashes)
        proc.wait()
    except KeyboardInterrupt:  # the launch has a session of its own: stop it cleanly first
        stop_group(proc, STOP_TIMEOUT_S)
        raise
    finally:
        timer.cancel()
        for log in logs.values():
            log.close()
    if timed_out.is_set():
        print("[datasets] %s: timed out after %.0f s (%.0f s per dataset; logs in %s)"
              % ("+".join(names), timeout, args.timeout, log_dir), file=sys.stderr)
    if len(names) > 1:
        print("[datasets] one launch for %s: %.1f s wall"
              % ("+".join(names), time.time() - launch_start), flush=True)


def split_output(lines, logs, first, crashes):
    """Writes the launch's `lines` to logs[<dataset being recorded>] (the lines before the first
    start line to `first`), prints each dataset's wall time and reports every crash under it."""
    current, started = first, time.time()
    for line in lines:
        m = DATASET_LINE.search(line)
        if m and m.group(1) in logs and m.group(1) != current:
            print("[datasets] %s: %.1f s wall" % (current, time.time() - started), flush=True)
            current, started = m.group(1), time.time()
        logs[current].write(line)
        for process, pid, signum in crashes_in(line):
            # A crash is a bug even when the retry records the missing demos: never hide it.
            print("[datasets] %s: CRASH: %s (pid %d) was killed by signal %d (see %s)"
                  % (current, process, pid, signum, logs[current].name),
                  file=sys.stderr, flush=True)
            crashes.append((current, process, signum))
    print("[datasets] %s: %.1f s wall" % (current, time.time() - started), flush=True)


def summarize(out_root, names, args, outcomes):
    rows, all_ok, all_topics = [], True, set()
    for name in names:
        mode, task = name.split("_", 1)
        ids = configurations(task, mode, args.demos)
        bags = [bag_name(os.path.join(out_root, name), task, mode, i) for i in ids]
        results = [outcomes(b) for b in bags if os.path.exists(b)]
        ok = sum(bool(r["success"]) for r in results)
        durations = [r["duration"] for r in results if "duration" in r]
        topics = sorted({t for r in results for t in r.get("topics", {})})
        all_topics.update(topics)
        all_ok &= len(results) == len(ids) and ok == len(ids)
        rows.append((name, "%d/%d" % (len(results), len(ids)),
                     "%.1f" % (sum(durations) / len(durations)) if durations else "-",
                     "%d/%d" % (ok, len(results)), len(topics)))
        for r in results:
            if not r["success"]:
                print("[datasets]   FAIL %s: %s" % (r["bag"], r["reason"]))
    header = ("dataset", "demos", "mean duration [s]", "physical success", "topics")
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    line = "  ".join("%-*s" % (w, h) for w, h in zip(widths, header))
    print(line)
    print("-" * len(line))
    for row in rows:
        print("  ".join("%-*s" % (w, str(c)) for w, c in zip(widths, row)))
    print("topics recorded: %s" % " ".join(sorted(all_topics)))
    return all_ok


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True, help="folder receiving one subfolder per dataset")
    parser.add_argument("--datasets", default="",
                        help="comma-separated <mode>_<task> (default: every task, both modes)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--tasks-dir", default=None,
                        help="also find task files here (searched first; $%s)"
                             % tasks.TASKS_PATH_VAR)
    parser.add_argument("--demos", type=int, default=0,
                        help="configurations per dataset, spread (0 = all)")
    parser.add_argument("--timeout", type=float, default=600.0,
                        help="s per dataset (a launch of N datasets gets N times this)")
    parser.add_argument("--force", action="store_true", help="delete and regenerate")
    args = parser.parse_args()
    if args.tasks_dir:
        os.environ[tasks.TASKS_PATH_VAR] = ":".join(
            [os.path.abspath(args.tasks_dir)]
            + [d for d in os.environ.get(tasks.TASKS_PATH_VAR, "").split(":") if d])
    try:
        known = tasks.datasets()
        names = [n.strip() for n in args.datasets.split(",") if n.strip()] or known
        for n in names:
            if n not in known:
                parser.error("unknown dataset '%s' (choose from %s)" % (n, ", ".join(known)))
            tasks.scenes(n.split("_", 1)[1], n.split("_", 1)[0])  # the task file is valid
    except RuntimeError as exc:
        print("error: %s" % exc, file=sys.stderr)
        return 2
    out_root = os.path.abspath(args.out)
    log_dir = os.path.join(out_root, "logs")
    os.makedirs(log_dir, exist_ok=True)
    if args.force:
        for n in names:
            shutil.rmtree(os.path.join(out_root, n), ignore_errors=True)
    start = time.time()
    crashes, outcomes = [], redo.Outcomes()
    with master_for_this_process():
        generate(names, out_root, args, log_dir, crashes, outcomes)
    total = time.time() - start
    print("[datasets] generation took %.1f s wall in total (logs in %s)" % (total, log_dir))
    ok = summarize(out_root, names, args, outcomes)
    if crashes:
        print("[datasets] %d node crash(es) during generation: %s" % (len(crashes), ", ".join(
            "%s/%s signal %d" % c for c in crashes)))
    return 0 if ok and not crashes else 1


if __name__ == "__main__":
    sys.exit(main())
