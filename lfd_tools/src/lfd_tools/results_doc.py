"""docs/results.md's generated sections, rewritten from what the pipeline and the benchmarks write:
the pipeline's report.json and each benchmark's JSON. Only the text between a section's two marker
lines is rewritten; the hand-written text around the sections stays as it is:

  <!-- generated: pipeline-segmentation -->
  ...
  <!-- end generated -->

A source (SOURCES) is a kind of JSON output and the sections made from it:
  pipeline              report.json of `./lfd pipeline`: pipeline-run (stage times, what ran),
                        pipeline-segmentation, pipeline-learning, pipeline-reproduction
  signal-classes        bench/segmentation/bench_signal_classes.py --out: bench-signal-classes
  faults                bench/monitoring/bench_faults.py: bench-faults
  pr2-signature         bench/monitoring/bench_pr2_signature.py --out: bench-pr2-signature
  bench-pipeline        bench/pipeline/bench_pipeline.py --json: bench-pipeline
  profile-demo          bench/pipeline/profile_demo.py --json: profile-demo
  profile-reproduction  bench/pipeline/profile_reproduction.py --json: profile-reproduction
The pipeline and each of those benchmarks take --update-docs, which renders their result into the
file after the run; without it nothing in the checkout is written. Saved outputs by hand:

  python3 -m lfd_tools.results_doc pipeline=DIR/report.json signal-classes=result.json ...

Every section a source makes must exist in the file (a missing or unclosed marker is an error
naming it, and nothing is written). The pipeline's tables are report.md's (lfd_tools.report_tables);
a benchmark's rows are those it prints (the *_cells / *_rows functions below, which it calls)."""
import argparse
import collections
import datetime
import json
import os
import re
import subprocess
import sys

from lfd_tools import config, report_tables as tables
from lfd_tools.report import reproduction_key

BEGIN = "<!-- generated: %s -->"
END = "<!-- end generated -->"
BEGIN_LINE = re.compile(r"^<!-- generated: ([\w.-]+) -->[ \t]*$", re.M)
END_LINE = re.compile(r"^<!-- end generated -->[ \t]*$", re.M)
num = lambda fmt, v: "-" if v is None else fmt % v


class SectionError(RuntimeError):
    """docs/results.md lacks a section a source makes, or its markers are broken."""


def default_doc():
    """docs/results.md of the source tree this lfd_tools belongs to (next to config/)."""
    return os.path.join(os.path.dirname(config.config_dir()), "docs", "results.md")


# ---- the sections in a text ---------------------------------------------------------------------

def section_spans(text, where="the text"):
    """{name: (start, end)} of the inside of every generated section (between the end of its begin
    line and the start of its end line). Raises SectionError for an unclosed or repeated section."""
    spans, begins = {}, list(BEGIN_LINE.finditer(text))
    line_of = lambda pos: text.count("\n", 0, pos) + 1
    for i, m in enumerate(begins):
        name = m.group(1)
        end = END_LINE.search(text, m.end())
        limit = begins[i + 1].start() if i + 1 < len(begins) else len(text)
        if end is None or end.start() > limit:
            raise SectionError("%s: section %r (line %d) has no %r line before the next section "
                               "or the end" % (where, name, line_of(m.start()), END))
        if name in spans:
            raise SectionError("%s: section %r appears twice (the second at line %d)"
                               % (where, name, line_of(m.start())))
        spans[name] = (m.end(), end.start())
    return spans


def replace_sections(text, sections, where="the text"):
    """`text` with the inside of each named section replaced by its Markdown (a blank line on each
    side); everything else unchanged. Raises SectionError naming every section it lacks."""
    spans = section_spans(text, where)
    missing = [name for name in sections if name not in spans]
    if len(missing) == 1:
        raise SectionError("%s has no generated section %r: add the lines %s and %s where it goes"
                           % (where, missing[0], BEGIN % missing[0], END))
    if missing:
        raise SectionError("%s has no generated sections %s: add for each the lines %s and %s "
                           "where it goes" % (where, ", ".join(repr(n) for n in missing),
                                              BEGIN % "NAME", END))
    for name in sorted(sections, key=lambda n: -spans[n][0]):  # from the end: spans stay valid
        start, end = spans[name]
        text = text[:start] + "\n\n" + sections[name].strip("\n") + "\n\n" + text[end:]
    return text


def update_file(path, sections):
    """Rewrites the named sections of the file at `path` (atomically, and only when something
    changed); the names whose content changed."""
    with open(path) as f:
        text = f.read()
    new = replace_sections(text, sections, path)
    spans, old_spans = section_spans(new), section_spans(text)
    changed = [n for n in sections
               if new[slice(*spans[n])] != text[slice(*old_spans[n])]]
    if new != text:
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            f.write(new)
        os.chmod(tmp, os.stat(path).st_mode)
        os.replace(tmp, path)
    return changed


# ---- the sources ---------------------------------------------------------------------------------

def commit_of(doc):
    """The checkout's commit, "-dirty" when a tracked file other than `doc` has changes (the
    sections written before are no change of the code), or "unknown" outside a git checkout."""
    git = lambda *a: subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(doc))] + list(a),
                                    capture_output=True, text=True)
    try:
        head, top = git("rev-parse", "--short=7", "HEAD"), git("rev-parse", "--show-toplevel")
        if head.returncode or top.returncode:
            return "unknown"
        doc_in_repo = os.path.relpath(os.path.realpath(doc), os.path.realpath(top.stdout.strip()))
        dirty = git("diff", "--quiet", "HEAD", "--", ":/", ":(top,exclude)" + doc_in_repo)
    except OSError:
        return "unknown"
    return head.stdout.strip() + ("-dirty" if dirty.returncode else "")


def origin(doc, when=None, what=""):
    """The line that opens a generated section: what made it, on which date, at which commit."""
    day = (when or datetime.datetime.now()).strftime("%Y-%m-%d")
    return ("*Generated from %s, %s; checkout at commit %s.*"
            % (what or "its JSON", day, commit_of(doc)))


STAGE_TIMES = ("datasets_s", "segment_s", "learn_s", "reproduce_s", "figures_s")  # run order


def pipeline_sections(report, made_by):
    """report.json of `./lfd pipeline` -> its four sections."""
    timings = report.get("timings", {})
    demos = sum(d.get("demos", 0) for d in report.get("datasets", {}).values())
    goals = {key: sum(len(e.get("goals", [])) for e in report.get(key, {}).values())
             for key in (reproduction_key("sim"), reproduction_key("teleop"))}
    ran = ("robot %s; %d datasets, %d demonstrations; %d sim and %d teleop goals reproduced"
           % (report.get("robot", "?"), len(report.get("datasets", {})), demos,
              goals["reproduction"], goals["reproduction_teleop"]))
    problems = report.get("problems") or []
    run = ([made_by, "", ran + ("; problems: " + "; ".join(problems) if problems
                                else "; no problems") + ".", ""]
           + tables.markdown_table(["stage", "wall time"],
                                   [(k[:-2], "%.1f s" % timings[k]) for k in STAGE_TIMES
                                    if k in timings]
                                   + [("**total**", "**%.1f s**" % timings.get("total_s", 0))]))
    none = lambda what: ["(no %s in this report)" % what]
    reproduction = []
    for key, title in ((reproduction_key("sim"), "sim"), (reproduction_key("teleop"), "teleop")):
        if report.get(key):
            reproduction += (["**%s libraries, %s unseen goals:**" % (title, title), ""]
                             + tables.reproduction_table(report, key) + [""])
    return {
        "pipeline-run": run,
        "pipeline-segmentation": [made_by, ""] + (tables.segmentation_table(report)
                                                  if report.get("segmentation")
                                                  else none("segmentation")),
        "pipeline-learning": [made_by, ""] + (tables.learning_table(report)
                                              if report.get("learning") else none("learning")),
        "pipeline-reproduction": [made_by, ""] + (reproduction or none("reproduction")),
    }


SIGNAL_CLASS_HEADER = ("class", "demos", "ok@0.5", "rate", "ok@1.0", "rate", "cover", "f1@0.5",
                       "err_med", "err_p95", "none", "cps/truth", "time_s")


def signal_class_cells(name, r):
    """One class of bench_signal_classes.py's result: the cells of SIGNAL_CLASS_HEADER."""
    a, b = r["at"]["0.5"], r["at"]["1.0"]
    per_seed = lambda tol: ",".join(str(s["correct"][tol]) for s in r["seeds"])
    return (name, "%d" % a["demos"], per_seed("0.5"), "%.2f" % a["success_rate"], per_seed("1.0"),
            "%.2f" % b["success_rate"], "%.3f" % a["covering"], "%.3f" % a["f1"],
            num("%.2f", a["time_error_median_s"]), num("%.2f", a["time_error_p95_s"]),
            "%d" % a["transitions_without_changepoint"],
            "%.1f/%.1f" % (r["changepoints_per_demo"], r["boundaries_per_demo"]),
            "%.1f" % sum(s["seconds"] for s in r["seeds"]))


def signal_classes_sections(result, made_by):
    rows = [signal_class_cells(n, r) for n, r in result["classes"].items()]
    errors = ["%s seed %d: %s" % (n, s["seed"], s["error"]) for n, r in result["classes"].items()
              for s in r["seeds"] if s["error"]]
    return {"bench-signal-classes": [
        made_by, "", "Seeds %s, procedure %s, configuration %s."
        % (",".join(str(s) for s in result["seeds"]), result.get("procedure") or "(the config's)",
           result.get("config") or "(shipped)"), ""]
        + tables.markdown_table(SIGNAL_CLASS_HEADER, rows)
        + (["", "Errors: " + "; ".join(errors)] if errors else [])}


def faults_sections(result, made_by):
    s = result.get("summary")
    if not s:
        return {"bench-faults": [made_by, "", "(the run ended before its summary: %d runs)"
                                 % len(result.get("runs", []))]}
    rows = [(f, "%d" % v["runs"], "%d" % v["detected"], num("%.2f s", v["median_delay_s"]))
            for f, v in s["per_fault"].items()]
    rate = s["detection_rate"]
    rows.append(("**all**", "**%d**" % s["faulty_runs"],
                 "**%d (%s)**" % (s["detected"], "-" if rate is None else "%.0f%%" % (100 * rate)),
                 num("%.2f s", s["median_delay_s"])))
    return {"bench-faults": [made_by, ""]
            + tables.markdown_table(["fault", "runs counted", "detected", "median delay"], rows)
            + ["", "Nominal runs: %d, false alarms %d, task failures %d. Faults the task survived: "
               "%d, alarmed %d. ROC AUC of the anomaly score, faulty vs nominal: %s."
               % (s["nominal_runs"], s["false_alarms"], s["nominal_task_failures"],
                  s["harmless_faults"], s["harmless_faults_alarmed"], num("%.2f", s["roc_auc"]))]
            + following_table(s.get("following") or {})
            + recovery_table(s.get("recovery") or {})
            + ([] if result.get("complete", True) else ["", "(interrupted: incomplete run)"])}


def case_table(title, columns, cases, cells):
    """A bench_faults.py summary of cases ({case: counts}) as a titled table, a row per case."""
    if not cases:
        return []
    rows = [(case,) + cells(v) for case, v in sorted(cases.items())]
    return ["", title, ""] + tables.markdown_table(["case"] + columns, rows)


def following_table(following):
    """Goals whose objects the executor followed (bench_faults.py FOLLOWED_CASES), and their
    reference (REFERENCE_CASES)."""
    return case_table(
        "Goals whose objects are followed (the goal gives each object's pose in its own tf "
        "frame); moved_from_start, not followed, has the object where object_moved shoves it "
        "from the start:",
        ["runs", "task succeeded", "replanned", "alarms", "failed tasks"], following,
        lambda v: ("%d" % v["runs"], "%d" % v["task_succeeded"], "%d" % v["replanned_runs"],
                   "%d" % v["alarms"], ", ".join(v["failed_tasks"]) or "-"))


def recovery_table(recovery):
    """Goals whose grasp was lost (bench_faults.py RECOVERY_CASES)."""
    return case_table(
        "Recovery after a lost grasp (objects followed; executor.yaml recovery/*):",
        ["runs", "task succeeded", "recovered runs", "recoveries", "failed tasks"], recovery,
        lambda v: ("%d" % v["runs"], "%d" % v["task_succeeded"], "%d" % v["recovered_runs"],
                   "%d" % v["recoveries"], ", ".join(v["failed_tasks"]) or "-"))


def pr2_case_cells(row):
    """A failed run scored by bench_pr2_signature.py: learned from, run, segment, its score, the
    held-out successful run's, the worst channel."""
    w = row["worst"]
    return ("+".join(row["train"]), row["run"], row["segment"], "%.2f" % row["score"],
            "%.2f" % row["positive_max"],
            "%s t=%.1f s expected %.3g measured %.3g" % (w["channel"], w["time"], w["expected"],
                                                         w["measured"]))


def pr2_signature_sections(result, made_by):
    cases = [pr2_case_cells(r) for r in result["rows"] if "score" in r]
    nominal = [r for r in result["rows"] if "scores" in r]
    return {"bench-pr2-signature": [made_by, ""]
            + tables.markdown_table(["learned from", "failed run", "segment", "score",
                                     "held-out successful run", "worst channel"], cases)
            + ["", "Failed runs above every held-out successful run on their failed segment: "
               "**%d of %d**. False alarms on the held-out successful runs: %d of %d segments."
               % (result["separated"], result["cases"],
                  sum(sum(r["alarms"]) for r in nominal), sum(len(r["alarms"]) for r in nominal))]}


PIPELINE_FIGURES = STAGE_TIMES + ("wall_s", "per_demo_s", "per_goal_s", "demos", "goals")


def pipeline_figure_text(key, value):
    """One figure of bench_pipeline.py as it prints it."""
    return "-" if value is None else ("%d" % value if key in ("demos", "goals") else "%.1f" % value)


def bench_pipeline_sections(result, made_by):
    runs = result["runs"]
    header = ["figure"] + ["run %d" % (i + 1) for i in range(len(runs))]
    header += ["median"] if result.get("median") else []
    rows = [[key] + [pipeline_figure_text(key, r.get(key)) for r in runs]
            + ([pipeline_figure_text(key, result["median"].get(key))] if result.get("median")
               else []) for key in PIPELINE_FIGURES]
    return {"bench-pipeline": [made_by, "", "Pipeline options: %s."
                               % (" ".join(result.get("pipeline_args") or []) or "(defaults)"), ""]
            + tables.markdown_table(header, rows)}


DEMO_STEP_KINDS = ("step_calls", "contact_step_calls")  # free chunks; short ones awaiting contact


def demo_profile_rows(result):
    """profile_demo.py's breakdown of the demos' wall time: [(what, seconds)]."""
    parts, counts = result["demonstrator_parts_s"], result["demonstrator_counts"]
    bridge = result["bridge_parts_s"]
    calls = int(sum(counts.get(k, 0) for k in DEMO_STEP_KINDS))
    rows = [("bridge: physics", bridge.get("physics", 0.0)),
            ("bridge: publishing", bridge.get("publishing", 0.0)),
            ("%d step round trips beyond the bridge's work" % calls, result["step_handshake_s"])]
    rows += [("demonstrator: %s (%d)" % (k, counts.get(k, 0)), v) for k, v in sorted(parts.items())
             if k not in DEMO_STEP_KINDS]
    rows += [("  of which: all of %s (%d)" % (k, counts.get(k, 0)), parts.get(k, 0.0))
             for k in DEMO_STEP_KINDS]
    rows.append(("demonstrator: the rest (its own code, callbacks)",
                 result["demonstrator_other_s"]))
    return rows


def demo_profile_summary(result):
    return ("%d demos of %s: %.1f s of sim time in %.1f s wall (%.1fx real time overall, "
            "%.1fx within the demos)"
            % (result["demos"], result["dataset"], result["sim_s"], result["wall_s"],
               result["sim_s"] / result["wall_s"],
               result["sim_s"] / max(result["demos_wall_s"], 1e-9)))


def cpu_line(cpu):
    """CPU seconds by process, largest first: {name: [user, system]} or {name: {user, system}}."""
    pairs = {n: (c["user"], c["system"]) if isinstance(c, dict) else tuple(c)
             for n, c in cpu.items()}
    return ", ".join("%s %.1f s" % (n, u + s) for n, (u, s)
                     in sorted(pairs.items(), key=lambda kv: -sum(kv[1])) if u + s >= 0.05)


def profile_demo_sections(result, made_by):
    wall = max(result["demos_wall_s"], 1e-9)
    rows = [(what, "%.2f" % s, "%.1f%%" % (100.0 * s / wall))
            for what, s in demo_profile_rows(result)]
    return {"profile-demo": [made_by, "", demo_profile_summary(result) + ".", ""]
            + tables.markdown_table(["within the demos", "wall s", "share"], rows)
            + ["", "CPU by process (user + system): %s." % cpu_line(result["cpu_s"])]}


REPRODUCTION_PARTS = ("scene_calls", "planning", "motion", "judge_waits", "judging")


def reproduction_profile(goals):
    """profile_reproduction.py's breakdown of its goals' wall time: (summary, [(what, seconds,
    share of the wall time or None)])."""
    wall, sim = sum(r["wall_s"] for r in goals), sum(r["sim_s"] for r in goals)
    parts, calls = collections.Counter(), collections.Counter()
    for r in goals:
        parts.update(r["parts"])
        calls.update(r["calls"])
    share = lambda s: 100 * s / wall if wall else None
    rows = [("%s (%d)" % (n, calls[n]), parts[n], share(parts[n])) for n in REPRODUCTION_PARTS]
    rows += [("of which /bridge/step round trips (%d)" % calls["step_calls"],
              parts["step_calls"], None),
             ("of motion: its step round trips", parts["motion_step_calls"], None),
             ("of motion: the rest (client loop, action traffic)",
              parts["motion"] - parts["motion_step_calls"], None),
             ("outside every measured part", wall - sum(parts[n] for n in REPRODUCTION_PARTS),
              None)]
    return ("%d goals: %.1f s of sim time in %.1f s wall (%.1fx real time)"
            % (len(goals), sim, wall, sim / max(wall, 1e-9)), rows)


def profile_reproduction_sections(result, made_by):
    summary, rows = reproduction_profile(result["goals"])
    return {"profile-reproduction": [made_by, "", summary + ".", ""]
            + tables.markdown_table(["where", "wall s", "share"],
                                    [(w, "%.2f" % s, num("%.1f%%", p)) for w, s, p in rows])
            + ["", "CPU by process (user + system): %s." % cpu_line(result["cpu_s"])]}


# kind -> (the function making its sections, the sections it makes, what makes the JSON)
SOURCES = {
    "pipeline": (pipeline_sections, ("pipeline-run", "pipeline-segmentation", "pipeline-learning",
                                     "pipeline-reproduction"), "`./lfd pipeline`'s report.json"),
    "signal-classes": (signal_classes_sections, ("bench-signal-classes",),
                       "`bench/segmentation/bench_signal_classes.py`"),
    "faults": (faults_sections, ("bench-faults",), "`bench/monitoring/bench_faults.py`"),
    "pr2-signature": (pr2_signature_sections, ("bench-pr2-signature",),
                      "`bench/monitoring/bench_pr2_signature.py`"),
    "bench-pipeline": (bench_pipeline_sections, ("bench-pipeline",),
                       "`bench/pipeline/bench_pipeline.py`"),
    "profile-demo": (profile_demo_sections, ("profile-demo",), "`bench/pipeline/profile_demo.py`"),
    "profile-reproduction": (profile_reproduction_sections, ("profile-reproduction",),
                             "`bench/pipeline/profile_reproduction.py`"),
}


def render(kind, data, made_by):
    """{section: Markdown} of one source's JSON; `made_by` is the line opening each section."""
    make, names, _ = SOURCES[kind]
    sections = {k: "\n".join(v).strip("\n") for k, v in make(data, made_by).items()}
    assert set(sections) == set(names), (kind, sorted(sections))
    return sections


def check(kind, doc=None):
    """Raises SectionError unless `doc` (default: docs/results.md) holds every section of `kind`:
    a run that will update it checks this before its work."""
    doc = doc or default_doc()
    if not os.path.exists(doc):
        raise SectionError("no %s to update" % doc)
    with open(doc) as f:
        replace_sections(f.read(), dict.fromkeys(SOURCES[kind][1], ""), doc)


def update(kind, data, doc=None, when=None, made_by=None):
    """Rewrites `kind`'s sections of `doc` (default docs/results.md) from its JSON `data`; the
    names of the sections that changed."""
    doc = doc or default_doc()
    if made_by is None:
        made_by = origin(doc, when, SOURCES[kind][2])
    return update_file(doc, render(kind, data, made_by))


def report_update(kind, data, doc=None, when=None):
    """update() for a tool's --update-docs, saying what it did (the changed sections) on stdout."""
    doc = doc or default_doc()
    changed = update(kind, data, doc, when)
    print("%s: %s" % (doc, "updated " + ", ".join(changed) if changed else "already current"),
          flush=True)
    return changed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sources", nargs="+", metavar="KIND=FILE",
                    help="a JSON output and its kind: " + ", ".join(SOURCES))
    ap.add_argument("--doc", default=None, help="the file to update (default: docs/results.md)")
    args = ap.parse_args(argv)
    for source in args.sources:
        kind, _, path = source.partition("=")
        if kind not in SOURCES or not path:
            ap.error("%r: expected KIND=FILE, KIND one of %s" % (source, ", ".join(SOURCES)))
    try:
        for source in args.sources:
            kind, _, path = source.partition("=")
            with open(path) as f:
                data = json.load(f)
            when = datetime.datetime.fromtimestamp(os.path.getmtime(path))
            report_update(kind, data, args.doc, when)
    except (OSError, ValueError, SectionError) as exc:
        print("error: %s" % exc, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
