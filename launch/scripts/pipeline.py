#!/usr/bin/python3
"""The headless lfd pipeline: README's first command (`./lfd pipeline --out DIR`).

Stages, each through roslaunch on a private ROS master of its own (so one stage's /use_sim_time
never leaks into the next):
  datasets  generate the four demonstration datasets (resumes: existing bags are kept)
  segment   segment every dataset through the segmentation service, for all four combination
            methods, and score it against the demonstrator's ground truth

Writes DIR/report.json (stable keys: datasets.<name>.demos, segmentation.<name>.success_rate,
segmentation.<name>.methods.<method>, timings.<stage>_s) and DIR/report.md, and prints the time of
each stage. Ctrl-C stops cleanly; a rerun picks up the datasets that already exist.
"""
import argparse
import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
DATASETS = ("sim_grasp", "sim_push", "teleop_grasp", "teleop_push")
PAPER_METHOD = "weighted_product"


def say(msg):
    print("[pipeline] %s" % msg, flush=True)


def stop_group(proc, timeout):
    """SIGINT a process group (roslaunch/roscore shut down cleanly on it), SIGKILL if it hangs."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def private_master():
    """A roscore on a free port for one stage; stopped (with all it started) on exit."""
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port)
    core = subprocess.Popen(["roscore", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 30
    while time.time() < deadline:
        with socket.socket() as s:
            if s.connect_ex(("localhost", port)) == 0:
                break
        if core.poll() is not None:
            raise RuntimeError("roscore exited at start (port %d)" % port)
        time.sleep(0.2)
    else:
        stop_group(core, 15)
        raise RuntimeError("roscore did not come up on port %d" % port)
    time.sleep(1.0)  # the parameter server answers a little after the port opens
    try:
        yield env
    finally:
        stop_group(core, 15)


def run(cmd, env=None):
    say("$ " + " ".join(cmd))
    proc = subprocess.Popen(cmd, env=env, start_new_session=True)
    try:
        return proc.wait()
    except KeyboardInterrupt:
        stop_group(proc, 30)
        raise


@contextlib.contextmanager
def background_launch(cmd, env):
    """roslaunch in the background for the duration of a stage."""
    say("$ " + " ".join(cmd) + " &")
    proc = subprocess.Popen(cmd, env=env, start_new_session=True, stdout=subprocess.DEVNULL)
    try:
        yield proc
    finally:
        stop_group(proc, 20)


def count_bags(folder):
    if not os.path.isdir(folder):
        return 0
    return len([f for f in os.listdir(folder) if f.endswith(".bag")])


def stage_datasets(out, args, report):
    data = os.path.join(out, "datasets")
    cmd = ["/usr/bin/python3", os.path.join(ROOT, "lfd_sim_bridge", "scripts", "generate_datasets.py"),
           "--out", data, "--datasets", ",".join(args.datasets)]
    with private_master() as env:
        rc = run(cmd, env)
    report["datasets"] = {n: {"demos": count_bags(os.path.join(data, n)), "path": os.path.join(data, n)}
                          for n in args.datasets}
    if rc != 0:
        raise RuntimeError("dataset generation failed (exit %d); see the table above" % rc)


def stage_segment(out, args, report):
    data = os.path.join(out, "datasets")
    missing = [n for n in args.datasets if count_bags(os.path.join(data, n)) == 0]
    if missing:
        raise RuntimeError("no bags for %s under %s: run the datasets stage first" % (",".join(missing), data))
    result = os.path.join(out, "segmentation.json")
    with private_master() as env:
        with background_launch(["roslaunch", "lfd_launch", "segment.launch"], env):
            rc = run(["/usr/bin/python3", os.path.join(ROOT, "lfd_segmentation", "scripts",
                                                        "evaluate_segmentation.py"),
                      "--datasets", data, "--names", ",".join(args.datasets), "--out", result], env)
    if not os.path.exists(result):
        raise RuntimeError("segmentation evaluation produced no result (exit %d)" % rc)
    with open(result) as f:
        seg = json.load(f)
    report["segmentation"] = {}
    for name, methods in seg["results"].items():
        entry = {"methods": {m: r.get("success_rate") for m, r in methods.items()},
                 "tolerance_s": seg["tolerance_s"]}
        paper = methods.get(PAPER_METHOD, {})
        entry["success_rate"] = paper.get("success_rate")
        entry["selected_features"] = paper.get("selected_features", [])
        report["segmentation"][name] = entry
    if rc != 0:
        raise RuntimeError("segmentation evaluation reported errors (exit %d)" % rc)


STAGES = {"datasets": stage_datasets, "segment": stage_segment}


def write_report(out, report):
    with open(os.path.join(out, "report.json"), "w") as f:
        json.dump(report, f, indent=1, sort_keys=True)
    lines = ["# lfd pipeline report", ""]
    if "datasets" in report:
        lines += ["## Datasets", "", "| dataset | demos |", "| --- | --- |"]
        lines += ["| %s | %d |" % (n, d["demos"]) for n, d in sorted(report["datasets"].items())]
        lines.append("")
    if "segmentation" in report:
        methods = sorted({m for e in report["segmentation"].values() for m in e["methods"]})
        lines += ["## Segmentation success rate", "",
                  "| dataset | " + " | ".join(methods) + " | selected features (%s) |" % PAPER_METHOD,
                  "| --- " * (len(methods) + 2) + "|"]
        for name, e in sorted(report["segmentation"].items()):
            cells = ["%.0f%%" % (100 * e["methods"][m]) if e["methods"].get(m) is not None else "error"
                     for m in methods]
            lines.append("| %s | %s | %s |" % (name, " | ".join(cells), ", ".join(e["selected_features"])))
        tol = next(iter(report["segmentation"].values()))["tolerance_s"]
        lines += ["", "A changepoint counts when it lies within %.2f s of its ground-truth transition." % tol, ""]
    lines += ["## Timings", ""] + ["- %s: %.1f s" % (k, v) for k, v in sorted(report["timings"].items())]
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "lfd_output"), help="report and data folder")
    ap.add_argument("--stages", default=",".join(STAGES), help="comma list of " + ",".join(STAGES))
    ap.add_argument("--datasets", default=",".join(DATASETS), type=lambda s: [x for x in s.split(",") if x])
    args = ap.parse_args()

    out = os.path.abspath(args.out)
    try:
        os.makedirs(out, exist_ok=True)
        probe = os.path.join(out, ".write_test")
        with open(probe, "w") as f:
            f.write("ok")
        os.remove(probe)
    except OSError as exc:
        say("error: output folder %s is not writable: %s" % (out, exc.strerror or exc))
        return 2
    stages = [s for s in args.stages.split(",") if s]
    unknown = [s for s in stages if s not in STAGES]
    if unknown:
        say("error: unknown stage(s) %s; known: %s" % (",".join(unknown), ",".join(STAGES)))
        return 2

    report_path = os.path.join(out, "report.json")
    report = {}
    if os.path.exists(report_path):
        with contextlib.suppress(ValueError, OSError):
            report = json.load(open(report_path))
    report.setdefault("timings", {})
    status = 0
    try:
        for stage in stages:
            say("stage %s ..." % stage)
            start = time.time()
            try:
                STAGES[stage](out, args, report)
            except RuntimeError as exc:
                say("error in stage %s: %s" % (stage, exc))
                status = 1
            report["timings"]["%s_s" % stage] = round(time.time() - start, 2)
            say("stage %s took %.1f s" % (stage, report["timings"]["%s_s" % stage]))
            if status:
                break
    except KeyboardInterrupt:
        say("interrupted: everything recorded so far is kept; rerun to resume")
        status = 130
    report["timings"]["total_s"] = round(sum(v for k, v in report["timings"].items() if k != "total_s"), 2)
    print(write_report(out, report))
    say("report: %s and %s" % (report_path, os.path.join(out, "report.md")))
    return status


if __name__ == "__main__":
    sys.exit(main())
