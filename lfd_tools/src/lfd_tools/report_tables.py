"""The tables of a pipeline report, written once: report.md (lfd_launch/scripts/pipeline.py) and the
generated sections of docs/results.md (lfd_tools.results_doc) are made of them. Each function
takes report.json's dict (lfd_tools.report documents its records) and returns Markdown lines."""
import os

from lfd_tools import judge, tasks
from lfd_tools.report import PAPER_METHOD, monitor_summary, ridges_note

mm = lambda v: "-" if v is None else "%.1f mm" % (v * 1e3)
sec = lambda v: "-" if v is None else "%.2f s" % v


def markdown_table(header, rows):
    """A Markdown table: a header row, its rule and one line per row (cells as given)."""
    line = lambda cells: "| %s |" % " | ".join(str(c) for c in cells)
    return [line(header), line(["---"] * len(header))] + [line(r) for r in rows]


def datasets_table(report):
    """Demonstrations per dataset."""
    return markdown_table(["dataset", "demos"],
                          [(n, "%d" % d["demos"]) for n, d in sorted(report["datasets"].items())])


def segmentation_table(report):
    """Each dataset's success rate per combination method, the paper method's selected features,
    then the tolerance in a sentence."""
    methods = sorted({m for e in report["segmentation"].values() for m in e["methods"]})
    rows = []
    for name, e in sorted(report["segmentation"].items()):
        cells = ["%.0f%%" % (100 * e["methods"][m]) if e["methods"].get(m) is not None
                 else "error" for m in methods]
        rows.append([name] + cells + [", ".join(e["selected_features"])])
    tol = next(iter(report["segmentation"].values()))["tolerance_s"]
    return (markdown_table(["dataset"] + methods + ["selected features (%s)" % PAPER_METHOD], rows)
            + ["", "A changepoint counts when it lies within %.2f s of its ground-truth "
                   "transition." % tol])


def learning_table(report):
    """Each skill library: segments learned against the task's, demos, changepoints, warnings."""
    rows = []
    for name, e in sorted(report["learning"].items()):
        notes = e.get("error") or ("%d warning(s)" % len(e["warnings"])
                                   if e.get("warnings") else "")
        rows.append((name, "%s (%s)" % (e.get("segments"), e.get("expected_segments")),
                     e.get("demos_used"), " ".join(str(c) for c in e.get("changepoint_counts", [])),
                     notes))
    return markdown_table(["dataset", "segments (task's)", "demos used", "changepoints per demo",
                           "warnings / error"], rows)


def segment_goals_table(report):
    """A sentence, then each learned segment's goal frames and their spread over the demos."""
    rows = []
    for name, e in sorted(report["learning"].items()):
        for g in e.get("segment_goals", []):
            if g.get("position_frame") is None:
                continue
            rows.append((name, g["segment"],
                         "%s (%.1f mm)" % (g["position_frame"], 1e3 * g["position_spread_m"]),
                         "%s (%.3f rad)" % (g["orientation_frame"], g["orientation_spread_rad"]),
                         g.get("motion_frame") or "-"))
    return (["Segment goals learned from the demos' scenes: the frame in which each segment's end "
             "varies least, and that spread (RMS across the demos).", ""]
            + markdown_table(["dataset", "segment", "position frame (spread)",
                              "orientation frame (spread)", "generalized along"], rows))


def reproduction_table(report, key):
    """A mode's reproductions (report.json section `key`, lfd_tools.report.reproduction_key), one
    row per task, then the success criteria and the time ratio in a sentence."""
    rows = []
    for task, e in sorted(report[key].items()):
        goals = e.get("goals", [])
        rows.append((task, "%d/%d" % (sum(g["success"] for g in goals), len(goals)) if goals
                     else "-",
                     "-" if e.get("execution_time_ratio") is None
                     else "%.2f" % e["execution_time_ratio"],
                     mm(e.get("mean_object_position_error_m")),
                     mm(e.get("mean_tcp_position_error_m")), monitor_summary(goals),
                     (e.get("error") or "").replace("|", "/")))
    return (markdown_table(["task", "success", "time ratio", "mean object error",
                            "mean TCP error", "monitor alarms", "note"], rows)
            + ["", "Success (the task files): " + "; ".join(
                judge.describe_criteria(t, tasks.success_criterion(t)) for t in sorted(report[key]))
               + ". Time ratio: executed / mean demonstrated duration."])


def goal_tables(report, key):
    """Per task of a mode, a table of its goals (each followed by an empty line)."""
    lines = []
    for task, e in sorted(report[key].items()):
        if not e.get("goals"):
            continue
        rows = [("%d" % g["id"], "ok" if g["success"] else "FAILED",
                 mm(g["object_position_error_m"]),
                 "-" if g["object_yaw_error_rad"] is None
                 else "%.3f rad" % g["object_yaw_error_rad"],
                 mm(g["tcp_position_error_m"]),
                 "-" if g["time_ratio"] is None else "%.3f" % g["time_ratio"],
                 sec(g.get("planning_time_s")), sec(g.get("wall_time_s")),
                 "%.2f" % g["max_anomaly_score"] if g.get("monitored") else "-")
                for g in e["goals"]]
        lines += (["%s, per goal%s:" % (task, ridges_note(e["goals"])), ""]
                  + markdown_table(["goal", "result", "object error", "yaw error", "TCP error",
                                    "time ratio", "planning", "wall", "anomaly score"], rows)
                  + [""])
    return lines


def figure_list(report):
    """Per figure set, a heading and its images (paths relative to the report)."""
    lines = []
    for name, paths in sorted(report["figures"].items()):
        lines += ["### %s" % name, ""] + ["![%s](%s)" % (os.path.basename(p), p)
                                          for p in paths] + [""]
    return lines


def timings_list(report):
    """Each stage's wall time, a list item each."""
    return ["- %s: %.1f s" % (k, v) for k, v in sorted(report["timings"].items())]
