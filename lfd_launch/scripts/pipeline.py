#!/usr/bin/python3
"""The headless lfd pipeline: README's first command (`./lfd pipeline --out DIR`).

Stages (`--stages`, default all, in this order), each through roslaunch on a private ROS master of
its own (so one stage's /use_sim_time never leaks into the next):
  datasets   generate the demonstration datasets (resumes: existing bags are kept)
  segment    segment every dataset through the segmentation service, for all four combination
             methods, and score it against the demonstrator's ground truth
  learn      lfd_launch/learn.launch + lfd_dmp/scripts/learn_skills.py: per dataset, segment its
             bags (/segmentation/segment, the paper's method of config/segmentation.yaml; never
             the ground truth) and learn the skill library from the validated changepoints
             (/learner/learn) -> DIR/skills/<task>_<mode>.json
  reproduce  lfd_launch/reproduce.launch + lfd_dmp/scripts/reproduce_goals.py: per learned library,
             reproduce every unseen goal of the task's file (`unseen.<mode>`) in MuJoCo through
             the /executor/execute action, the simulation stepped in lockstep on sim time, and
             judge it with the task file's success criterion (lfd_tools.judge)
             -> DIR/reproduction/<task>_<mode>.json
  figures    no master: the paper's figures per dataset (skill map, correlation matrix, relevance
             histograms, ClaSP profile with the Kaiser filter, segmentation with its zones; from
             the first demonstration), the success-rate bars per method and dataset, and MuJoCo
             snapshots (OSMesa) of the first demonstration at the end of each phase and of the
             first reproduction of each task (recorded by the reproduce stage) at the end of each
             segment -> DIR/figures

Writes DIR/report.json and DIR/report.md, and prints the time of each stage. report.json holds the
records of lfd_tools.report as the tools wrote them (their fields are documented there):
  datasets.<dataset>.demos
  segmentation.<dataset>                 success_rate (paper's method), methods.<method> (rate),
                                         results.<method> (every figure, per-demo details)
  learning.<dataset>                     segments (expected_segments beside), changepoint_counts,
                                         warnings, error (if any)
  reproduction.<task>                    sim library on the sim unseen goals: success_rate,
                                         execution_time_ratio, goals[] (id, success,
                                         object_position_error_m, object_yaw_error_rad,
                                         tcp_position_error_m, time_ratio, error, ...)
  reproduction_teleop.<task>             the same for the teleop library on the teleop goals
                                         (with --reproduce-modes sim,teleop; default sim only)
  figures.<dataset|success_rates>        PNG paths relative to DIR
  timings.<stage>_s                      wall time of the stage's last run (datasets_s, segment_s,
                                         learn_s, reproduce_s; total_s their sum; a stage with
                                         nothing to redo keeps its previous time)
  stage_errors.<stage>                   this run's error of a stage that failed (also in
                                         `problems`)
  problems                               everything above that did not work, one line each
A stage that fails (any exception, or a tool that exits non-zero) is recorded with its error under
`stage_errors` and `problems` and ends the run with exit status 1. Every process a stage starts
carries LFD_PIPELINE_TAG=<pid>:<stage> in its environment; whatever still runs when the stage ends
(however it ends) is killed, roslaunch's nodes included.
A task that cannot be learned or reproduced (e.g. push while its segmentation finds another number
of changepoints than the task has transitions) is recorded with its error and listed under
`problems`; the other tasks go on. <dataset> is <mode>_<task>, for every task file
(config/tasks/*.yaml) and both modes by default (sim_grasp, ..., teleop_wipe).

Resumable: the datasets stage keeps existing bags, learn keeps existing libraries and reproduce
keeps results newer than their library for the same goals; `--force` redoes learn and reproduce.
`--stages learn,reproduce` reruns stages alone on an existing output folder. Ctrl-C stops cleanly,
keeping everything recorded so far (reproduction results include the goals done).
Reduced runs (CI): `--demos N` records N configurations per dataset (spread over the task's list;
later stages use the bags present), `--goals N` reproduces N unseen goals per task (spread).
`--update-docs`: after a run without problems, the generated pipeline sections of docs/results.md
are rewritten from the report (lfd_tools.results_doc). Only when asked: a run writes into its --out
folder, never into the checkout, so CI, fresh roots and reduced runs leave the measured figures be.
"""
import argparse
import contextlib
import json
import os
import signal
import subprocess
import sys
import time

from lfd_tools import config, report as records, report_tables as tables, results_doc, tasks
from lfd_tools.jobs import run_parallel, run_tool, split, workers
from lfd_tools.master import background_launch, private_master
from lfd_tools.processes import TAG_VAR, kill_tagged

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
LEARN_SKILLS = os.path.join(ROOT, "lfd_dmp", "scripts", "learn_skills.py")
REPRODUCE_GOALS = os.path.join(ROOT, "lfd_dmp", "scripts", "reproduce_goals.py")


def say(msg):
    print("[pipeline] %s" % msg, flush=True)


def failed(what, rc, tail):
    """A stage error that carries the tool's own last words (e.g. its Python exception)."""
    return RuntimeError("%s (exit %d)%s"
                        % (what, rc, (": " + tail.replace("\n", " / ")) if tail else ""))


def roots_arg(folder):
    """The services of a stage may read and write only inside the run (config.run_roots)."""
    return "allowed_roots:=[%s]" % ",".join(json.dumps(r) for r in config.run_roots(folder))


def count_bags(folder):
    if not os.path.isdir(folder):
        return 0
    return len([f for f in os.listdir(folder) if f.endswith(".bag")])


def stage_datasets(out, args, report):
    """The datasets dealt over the workers, each worker a simulation on a master of its own."""
    data = os.path.join(out, "datasets")
    groups = split(args.datasets, workers(args.jobs))

    def generate(names):
        cmd = ["/usr/bin/python3",
               os.path.join(ROOT, "lfd_sim_bridge", "scripts", "generate_datasets.py"),
               "--out", data, "--datasets", ",".join(names), "--demos", str(args.demos)]
        with private_master() as env:
            return run_tool(cmd, env, label="+".join(names) if len(groups) > 1 else None)

    results = run_parallel([lambda g=g: generate(g) for g in groups], args.jobs)
    report["datasets"] = {n: {"demos": count_bags(os.path.join(data, n)),
                              "path": os.path.join(data, n)}
                          for n in args.datasets}
    bad = [(rc, tail) for rc, tail in results if rc != 0]
    if bad:
        raise failed("dataset generation failed; see the table above", *bad[0])


def require_bags(data, names):
    if not os.path.isdir(data):
        raise RuntimeError("no dataset folder %s: run the datasets stage first" % data)
    missing = [n for n in names if count_bags(os.path.join(data, n)) == 0]
    if missing:
        raise RuntimeError("no bags for %s under %s: run the datasets stage first"
                           % (",".join(missing), data))


def stage_segment(out, args, report):
    data = os.path.join(out, "datasets")
    require_bags(data, args.datasets)
    result = os.path.join(out, "segmentation.json")
    with private_master() as env:
        with background_launch(["roslaunch", "lfd_launch", "segment.launch", roots_arg(out)], env):
            rc, tail = run_tool(["/usr/bin/python3",
                                 os.path.join(ROOT, "lfd_segmentation", "scripts",
                                              "evaluate_segmentation.py"),
                                 "--datasets", data, "--names", ",".join(args.datasets),
                                 "--out", result], env)
    if not os.path.exists(result):
        raise failed("segmentation evaluation produced no result", rc, tail)
    report["segmentation"] = load_json(result)["segmentation"]  # the records, as written
    if rc != 0:
        raise failed("segmentation evaluation reported errors", rc, tail)


def by_mode(datasets):
    """{"sim": ["grasp", "push"], ...} from dataset names <mode>_<task>, in a stable order."""
    modes = {}
    for name in datasets:
        mode, task = name.split("_", 1)
        modes.setdefault(mode, []).append(task)
    return modes


def load_json(path):
    with contextlib.suppress(OSError, ValueError):
        with open(path) as f:
            return json.load(f)
    return None


def stage_learn(out, args, report):
    data = os.path.join(out, "datasets")
    require_bags(data, args.datasets)
    skills = os.path.join(out, "skills")
    os.makedirs(skills, exist_ok=True)
    learning = report.setdefault("learning", {})
    todo = {}
    for mode, mode_tasks in by_mode(args.datasets).items():
        for task in mode_tasks:
            library = os.path.join(skills, "%s_%s.json" % (task, mode))
            record = os.path.join(skills, "%s_%s.learning.json" % (task, mode))
            done = load_json(record)
            if not args.force and done is not None and os.path.exists(library):
                say("learn %s_%s: library exists, kept (--force relearns)" % (mode, task))
                learning["%s_%s" % (mode, task)] = done
                continue
            for stale in (library, record):  # never reproduce an old library after a failure
                with contextlib.suppress(FileNotFoundError):
                    os.remove(stale)
            todo.setdefault(mode, []).append(task)
    if not todo:
        return "skipped"
    with private_master() as env:
        with background_launch(["roslaunch", "lfd_launch", "learn.launch", "output:=log",
                                roots_arg(out)], env):
            for mode, mode_tasks in todo.items():
                result = os.path.join(skills, "learning_%s.json" % mode)
                with contextlib.suppress(FileNotFoundError):
                    os.remove(result)
                rc, tail = run_tool(["/usr/bin/python3", LEARN_SKILLS, "--attach", "--dataset",
                                     data, "--mode", mode, "--tasks", ",".join(mode_tasks),
                                     "--library-dir", skills, "--out", result], env)
                res = load_json(result)
                if res is None:
                    raise failed("learning %s produced no result" % mode, rc, tail)
                for task in mode_tasks:
                    key = "%s_%s" % (mode, task)
                    entry = res["learning"].get(key, {"error": "not reached (interrupted?)"})
                    learning[key] = entry
                    if entry.get("error") is None and os.path.exists(entry.get("library") or ""):
                        record = os.path.join(skills, "%s_%s.learning.json" % (task, mode))
                        with open(record, "w") as f:
                            json.dump(entry, f, indent=1, sort_keys=True)
    return None


def goal_ids(task, mode, n):
    return [e["id"] for e in tasks.spread(tasks.unseen_scenes(task, mode), n)]


def task_record(result_path, mode, task):
    """A task's reproduction record from a reproduce_goals.py result file (None if absent)."""
    return ((load_json(result_path) or {}).get(records.reproduction_key(mode)) or {}).get(task)


def stage_reproduce(out, args, report):
    skills = os.path.join(out, "skills")
    results = os.path.join(out, "reproduction")
    os.makedirs(results, exist_ok=True)
    todo = {}
    for mode, mode_tasks in by_mode(args.datasets).items():
        if mode not in args.reproduce_modes:
            continue
        section = report.setdefault(records.reproduction_key(mode), {})
        for task in mode_tasks:
            library = os.path.join(skills, "%s_%s.json" % (task, mode))
            path = os.path.join(results, "%s_%s.json" % (task, mode))
            ids = goal_ids(task, mode, args.goals)
            if not os.path.exists(library):
                err = (report.get("learning", {}).get("%s_%s" % (mode, task), {}).get("error")
                       or "no skill library %s: run the learn stage" % library)
                section[task] = records.reproduction_record(library, (None, 0, 0), [],
                                                            "not reproduced: " + err)
                say("reproduce %s_%s: %s" % (mode, task, section[task]["error"]))
                continue
            done = task_record(path, mode, task)
            if (not args.force and done and load_json(path).get("complete")
                    and [g["id"] for g in done["goals"]] == ids
                    and os.path.getmtime(path) > os.path.getmtime(library)):
                say("reproduce %s_%s: results newer than the library kept (--force reruns)"
                    % (mode, task))
                section[task] = done
                continue
            todo.setdefault(mode, []).append((task, ids))
    if not todo:
        return "skipped"
    items = [(mode, task, ids) for mode, mode_tasks in todo.items() for task, ids in mode_tasks]
    groups = split(items, workers(args.jobs))

    def reproduce(group):  # one simulation and executor for the worker's libraries
        with private_master() as env:
            with background_launch(["roslaunch", "lfd_launch", "reproduce.launch",
                                    "library_dir:=" + skills, roots_arg(out)], env):
                for mode, task, ids in group:
                    reproduce_one(results, skills, mode, task, ids, report, env,
                                  "%s_%s" % (mode, task) if len(groups) > 1 else None)

    run_parallel([lambda g=g: reproduce(g) for g in groups], args.jobs)
    return None


def reproduce_one(results, skills, mode, task, ids, report, env, label):
    path = os.path.join(results, "%s_%s.json" % (task, mode))
    with contextlib.suppress(FileNotFoundError):
        os.remove(path)
    say("reproduce %s_%s: %d unseen goals %s" % (mode, task, len(ids), ids))
    section = report[records.reproduction_key(mode)]
    try:
        rc, tail = run_tool(["/usr/bin/python3", REPRODUCE_GOALS, "--attach", "--library-dir",
                             skills, "--mode", mode, "--tasks", task, "--goals",
                             ",".join(map(str, ids)), "--record-dir", results, "--out",
                             path], env, label)
    except KeyboardInterrupt:  # report the goals done; a rerun redoes the task
        entry = task_record(path, mode, task)
        if entry:
            section[task] = dict(entry, interrupted=True)
        raise
    entry = task_record(path, mode, task)
    if entry is None:
        raise failed("reproduction %s_%s produced no result" % (mode, task), rc, tail)
    section[task] = entry
    say("reproduce %s_%s: %d/%d goals reached, time ratio %s" % (
        mode, task, entry["successes"], len(ids),
        "-" if entry["execution_time_ratio"] is None else "%.2f" % entry["execution_time_ratio"]))


def run_quiet(cmd, env=None):
    """Runs a figure tool; returns its stdout lines (PNG paths) or raises with its last words."""
    proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          universal_newlines=True)
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["no message"])[-1]
        raise RuntimeError("%s failed (exit %d): %s" % (" ".join(cmd[:3]), proc.returncode, last))
    return [line.split()[-1] for line in proc.stdout.splitlines() if line.strip().endswith(".png")]


def snapshots(report, key, bag, figs, times=None):
    """MuJoCo snapshots of a bag into figs/snapshots/<key> (default times: the end of each of its
    ground-truth phases). They need OSMesa, the plots do not: a failure is a reported problem."""
    cmd = ["rosrun", "lfd_sim_bridge", "snapshot", "--bag", bag,
           "--model", os.path.join(config.robot_dir(), "models", "workcell.xml"),
           "--out", os.path.join(figs, "snapshots", key)]
    if times:
        cmd += ["--times", ",".join("%.3f" % t for t in times)]
    try:
        return run_quiet(cmd)
    except (RuntimeError, OSError) as exc:
        report.setdefault("figure_problems", []).append("%s snapshots: %s" % (key, exc))
        return []


def stage_figures(out, args, report):
    """The paper's figures per dataset (Fig. 3, 4, 5, 7, 8), the success bars (Fig. 9) and MuJoCo
    snapshots of the first demonstration of each dataset at the end of each of its phases."""
    data, figs = os.path.join(out, "datasets"), os.path.join(out, "figures")
    require_bags(data, args.datasets)
    report["figure_problems"] = []  # this run's
    os.makedirs(figs, exist_ok=True)
    plot = os.path.join(ROOT, "lfd_segmentation", "scripts", "plot_segmentation.py")

    def dataset_figures(name):
        say("figures %s ..." % name)
        paths = run_quiet(["/usr/bin/python3", plot, "--dataset", os.path.join(data, name),
                           "--config", os.path.join(ROOT, "config", "segmentation.yaml"),
                           "--out", figs, "--prefix", name + "_", "--demo", "0"])
        bags = sorted(b for b in os.listdir(os.path.join(data, name)) if b.endswith(".bag"))
        return paths + snapshots(report, name, os.path.join(data, name, bags[0]), figs)

    made = dict(zip(args.datasets, run_parallel(
        [lambda n=n: dataset_figures(n) for n in args.datasets], args.jobs)))
    # The first reproduction of each task was recorded: snapshots at the end of each segment.
    for mode in ("sim", "teleop"):
        for task, entry in sorted(report.get(records.reproduction_key(mode), {}).items()):
            for goal in entry.get("goals", []):
                if goal.get("bag") and goal.get("segment_end_times_s"):
                    name = "reproduction_%s_%s" % (task, mode)
                    made[name] = snapshots(report, name, goal["bag"], figs,
                                           goal["segment_end_times_s"])
    write_report(out, report)  # the bars read this run's rates from report.json
    if report.get("segmentation"):
        made["success_rates"] = run_quiet(["/usr/bin/python3", plot, "--report",
                                           os.path.join(out, "report.json"), "--out", figs])
    report["figures"] = {k: [os.path.relpath(p, out) for p in v] for k, v in made.items()}
    for problem in report.get("figure_problems", []):
        say("figures: " + problem)


STAGES = {"datasets": stage_datasets, "segment": stage_segment, "learn": stage_learn,
          "reproduce": stage_reproduce, "figures": stage_figures}


def problems(report):
    """Human-readable list of what did not work (failed stages, learning errors, failed
    reproductions)."""
    out = ["stage %s failed: %s" % (stage, error)
           for stage, error in report.get("stage_errors", {}).items()]
    for name, e in sorted(report.get("learning", {}).items()):
        if e.get("error"):
            out.append("learn %s: %s" % (name, e["error"]))
        elif e.get("expected_segments") and e.get("segments") != e["expected_segments"]:
            out.append("learn %s: %s segment(s) learned, the task has %d (changepoints per demo %s)"
                       % (name, e.get("segments"), e["expected_segments"],
                          e.get("changepoint_counts")))
    for key in ("reproduction", "reproduction_teleop"):
        for task, e in sorted(report.get(key, {}).items()):
            if e.get("error"):
                out.append("%s %s: %s" % (key, task, e["error"]))
            if e.get("interrupted"):
                out.append("%s %s: interrupted after %d goal(s); rerun to complete"
                           % (key, task, len(e.get("goals", []))))
    return out


def write_report(out, report):
    lines = ["# lfd pipeline report", ""]
    if "robot" in report:
        lines += ["Robot: %s (package %s_description)" % (report["robot"], report["robot"]), ""]
    if "datasets" in report:
        lines += ["## Datasets", ""] + tables.datasets_table(report) + [""]
    if "segmentation" in report:
        lines += ["## Segmentation success rate", ""] + tables.segmentation_table(report) + [""]
    if report.get("learning"):
        lines += (["## Learning (skill libraries from the validated changepoints)", ""]
                  + tables.learning_table(report) + [""] + tables.segment_goals_table(report)
                  + [""])
    for key, title in (("reproduction", "sim"), ("reproduction_teleop", "teleop")):
        if not report.get(key):
            continue
        lines += (["## Reproduction toward unseen goals (%s)" % title, ""]
                  + tables.reproduction_table(report, key) + [""] + tables.goal_tables(report, key))
    if report.get("figures"):
        lines += ["## Figures", ""] + tables.figure_list(report)
    report["problems"] = problems(report) + report.get("figure_problems", [])
    if report["problems"]:
        lines += ["## Problems", ""] + ["- " + p for p in report["problems"]] + [""]
    with open(os.path.join(out, "report.json"), "w") as f:
        json.dump(report, f, indent=1, sort_keys=True)
    lines += ["## Timings", ""] + tables.timings_list(report)
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "lfd_output"),
                    help="report and data folder")
    ap.add_argument("--stages", default=",".join(STAGES), help="comma list of " + ",".join(STAGES))
    datasets = tasks.datasets()
    ap.add_argument("--datasets", default=",".join(datasets),
                    type=lambda s: [x for x in s.split(",") if x],
                    help="comma list of " + ",".join(datasets))
    ap.add_argument("--demos", type=int, default=0,
                    help="datasets stage: record N configurations per dataset "
                         "(0 = all of the task file)")
    ap.add_argument("--goals", type=int, default=0,
                    help="reproduce stage: N unseen goals per task (0 = all of the task file)")
    ap.add_argument("--reproduce-modes", default="sim",
                    type=lambda s: [x for x in s.split(",") if x],
                    help="reproduce stage: libraries of these modes (sim, teleop); the paper "
                         "reproduces the simulated tasks; teleop adds ~3.5 min")
    ap.add_argument("--force", action="store_true",
                    help="learn and reproduce again even where results exist")
    ap.add_argument("--robot", default=config.robot_name(),
                    help="the robot, a <robot>_description package (default $LFD_ROBOT or %s); "
                         "every stage's launch files and tools use it" % config.DEFAULT_ROBOT)
    ap.add_argument("--jobs", type=int, default=0,
                    help="independent simulations / figure jobs at once (0 = one per core)")
    ap.add_argument("--update-docs", action="store_true",
                    help="after a run without problems, rewrite the generated pipeline sections "
                         "of docs/results.md from its report (never by default: a CI, fresh-root "
                         "or reduced run must not change the checkout's measured figures)")
    # roslaunch (lfd_launch/pipeline.launch) appends __name:= / __log:= remappings: not ours.
    args = ap.parse_args([a for a in sys.argv[1:] if not a.startswith("__")])
    # SIGTERM (kill, CI timeouts) and a SIGINT ignored by a non-interactive parent shell stop the
    # run like Ctrl-C: masters and launches are torn down, the report is written.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, lambda *_: signal.default_int_handler(signal.SIGINT, None))
    bad = [d for d in args.datasets if d not in datasets]
    if bad:
        say("error: unknown dataset(s) %s; known: %s" % (",".join(bad), ",".join(datasets)))
        return 2

    try:
        config.robot_dir(args.robot)
    except RuntimeError as exc:
        say("error: %s" % exc)
        return 2
    os.environ["LFD_ROBOT"] = args.robot  # every launch file and tool started from here reads it

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
    stages = [s for s in STAGES if s in stages]  # always in data-flow order
    if args.update_docs:
        try:  # before the work: a file without the sections is said now, not after the run
            results_doc.check("pipeline")
        except RuntimeError as exc:
            say("error: --update-docs: %s" % exc)
            return 2

    report_path = os.path.join(out, "report.json")
    report = {}
    if os.path.exists(report_path):
        with contextlib.suppress(ValueError, OSError):
            report = json.load(open(report_path))
    if report.get("robot", args.robot) != args.robot:
        say("error: %s holds results of robot %s, not %s: choose another --out"
            % (out, report["robot"], args.robot))
        return 2
    report["robot"] = args.robot
    report.setdefault("timings", {})
    report["stage_errors"] = {}  # this run's
    status = 0
    try:
        for stage in stages:
            say("stage %s ..." % stage)
            start = time.time()
            outcome = None
            os.environ[TAG_VAR] = "%d:%s" % (os.getpid(), stage)
            try:
                outcome = STAGES[stage](out, args, report)
            except KeyboardInterrupt:
                report["stage_errors"][stage] = "interrupted; rerun to resume"
                raise
            except Exception as exc:  # noqa: BLE001 (any failure is the stage's, and is reported)
                error = (str(exc) if isinstance(exc, RuntimeError)
                         else "%s: %s" % (type(exc).__name__, exc))
                say("error in stage %s: %s" % (stage, error))
                report["stage_errors"][stage] = error
                status = 1
            finally:
                left = kill_tagged(os.environ.pop(TAG_VAR))
                if left:
                    say("stage %s left %d process(es) running (%s): killed"
                        % (stage, len(left), ", ".join(sorted(set(left)))))
            if outcome == "skipped":  # everything was already there: keep the measured time
                say("stage %s: nothing to do (--force redoes it)" % stage)
                continue
            report["timings"]["%s_s" % stage] = round(time.time() - start, 2)
            say("stage %s took %.1f s" % (stage, report["timings"]["%s_s" % stage]))
            if status:
                break
    except KeyboardInterrupt:
        say("interrupted: everything recorded so far is kept; rerun to resume")
        status = 130
    finally:
        kill_tagged("%d:" % os.getpid())
    report["timings"]["total_s"] = round(sum(v for k, v in report["timings"].items()
                                             if k != "total_s"), 2)
    print(write_report(out, report))
    for p in report["problems"]:
        say("problem: " + p)
    say("report: %s and %s" % (report_path, os.path.join(out, "report.md")))
    if args.update_docs:
        if status or report["problems"]:
            say("docs/results.md not updated: the run had problems")
        else:
            try:
                results_doc.report_update("pipeline", report)
            except (OSError, RuntimeError) as exc:  # the run is done and reported; the doc is not
                say("error: docs/results.md not updated: %s" % exc)
                status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
