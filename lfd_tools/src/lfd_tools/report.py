"""The result records of a run, defined once. The producers write them as they are
(evaluate_segmentation.py, learn_skills.py, reproduce_goals.py) and the pipeline's report.json
holds them unchanged:

  report.json
    segmentation.<dataset>        segmentation_record: success_rate (the paper's method),
                                  methods.<method> (its rate), results.<method> (every figure and
                                  the per-demo details), selected_features, tolerance_s
    learning.<dataset>            learning_record
    reproduction.<task>           reproduction_record (sim libraries on the sim goals), its
    reproduction_teleop.<task>    goals[] goal_records; teleop libraries on the teleop goals
Lengths in metres, angles in radians, times in seconds (the key says which).
"""
import contextlib
import json
import math
import signal
import sys

PAPER_METHOD = "weighted_product"


def mean(values):
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    return sum(values) / len(values) if values else None


def segmentation_record(results, tolerance):
    """A dataset's segmentation: results = {method: evaluation of that method, or {"error"}}."""
    paper = results.get(PAPER_METHOD, {})
    return {"tolerance_s": tolerance, "paper_method": PAPER_METHOD,
            "success_rate": paper.get("success_rate"),
            "selected_features": paper.get("selected_features", []),
            "methods": {m: r.get("success_rate") for m, r in results.items()},
            "results": results}


def learning_record(task, expected_segments, bags, changepoint_source):
    """A skill library being learned; learn_skills.py fills in the learner's answer."""
    return {"task": task, "library": None, "segments": 0, "expected_segments": expected_segments,
            "demos_used": None, "bags": len(bags), "changepoint_source": changepoint_source,
            "changepoint_counts": [], "changepoint_times": [], "selected_features": [],
            "warnings": []}


def goal_record(goal_id, response=None, outcome=None, error="", demo_duration=None, wall_time=None):
    """One unseen goal: the executor's result (lfd_msgs/ExecuteTaskResult; None when it never
    answered), the physical outcome of lfd_tools.judge.physical_outcome (None when the object was
    not judged) and the goal's wall time (planning, stepping, judging)."""
    executed = bool(response is not None and response.success)
    outcome = outcome or {}
    g = {"id": goal_id, "executed": executed, "success": bool(executed and outcome.get("success")),
         "error": error or (response.error if response is not None else ""),
         "warnings": list(response.warnings) if response is not None else [],
         "object_position_error_m": outcome.get("distance_m"),
         "object_height_m": outcome.get("height_m"),
         "object_yaw_error_rad": outcome.get("yaw_error_rad"),
         "judged": outcome.get("reason", ""),
         "tcp_position_error_m": response.final_position_error if executed else None,
         "tcp_orientation_error_rad": response.final_orientation_error if executed else None,
         "execution_time_s": response.execution_time if executed else None,
         "planned_duration_s": response.planned_duration if executed else None,
         "planning_time_s": response.planning_time if executed else None,
         "segment_durations_s": list(response.segment_durations) if executed else [],
         "segment_frames": list(response.segment_frames) if response is not None else [],
         "segment_slope_ridges": (list(response.segment_slope_ridges) if response is not None
                                  else []),
         "extrapolation_distance_m": (response.extrapolation_distance if response is not None
                                      else None),
         "extrapolation_angle_rad": response.extrapolation_angle if response is not None else None,
         "outside_demo_range": bool(response.outside_demo_range) if response is not None else None,
         "monitored": bool(response.monitored) if response is not None else False,
         "max_anomaly_score": response.max_anomaly_score if response is not None else None,
         "monitor_alarm": response.monitor_alarm if response is not None else "",
         "wall_time_s": wall_time}
    g["time_ratio"] = g["execution_time_s"] / demo_duration if executed and demo_duration else None
    g["overhead_ratio"] = (g["execution_time_s"] / g["planned_duration_s"]
                           if executed and g["planned_duration_s"] else None)
    return g


def reproduction_record(library, library_summary, goals, error=None):
    """A task's reproduction: library_summary = (mean demo duration s, demos, segments)."""
    demo_duration, demos, segments = library_summary
    successes = sum(g["success"] for g in goals)
    r = {"library": library, "demos": demos, "segments": segments,
         "mean_demo_duration_s": demo_duration, "goals_total": len(goals), "successes": successes,
         "success_rate": successes / len(goals) if goals else None,
         "execution_time_ratio": mean([g["time_ratio"] for g in goals]),
         "mean_overhead_ratio": mean([g["overhead_ratio"] for g in goals]),
         "mean_object_position_error_m": mean([g["object_position_error_m"] for g in goals]),
         "mean_object_yaw_error_rad": mean([g["object_yaw_error_rad"] for g in goals]),
         "mean_tcp_position_error_m": mean([g["tcp_position_error_m"] for g in goals]),
         "mean_planning_time_s": mean([g["planning_time_s"] for g in goals]),
         "mean_wall_time_s": mean([g.get("wall_time_s") for g in goals]), "goals": goals}
    errors = sorted({g["error"] for g in goals if g["error"]})
    if error or (errors and not successes):
        r["error"] = error or "; ".join(errors)
    return r


def monitor_summary(goals):
    """The execution monitor over a task's goals: "alarms/monitored (max score)", "-" when no goal
    was monitored (monitoring off, or a library without a sensory signature)."""
    monitored = [g for g in goals if g.get("monitored")]
    if not monitored:
        return "-"
    return "%d/%d (max %.2f)" % (sum(bool(g.get("monitor_alarm")) for g in monitored),
                                 len(monitored),
                                 max(g.get("max_anomaly_score", 0.0) for g in monitored))


def reproduction_key(mode):
    """report.json's section of a mode's reproductions."""
    return "reproduction" if mode == "sim" else "reproduction_%s" % mode


@contextlib.contextmanager
def written_on_exit(path, results):
    """Yields `results` (a dict the block fills in) and writes it as JSON to `path` however the
    block ends (an error, Ctrl-C): "complete" is true only when it ended normally."""
    results["complete"] = False
    try:
        yield results
        results["complete"] = True
    finally:
        with open(path, "w") as f:
            json.dump(results, f, indent=1)
        print("JSON: %s" % path, flush=True)


def run_client(main):
    """Runs a client's main(): its exit status; 1 with a one-line error for a RuntimeError; 130
    after Ctrl-C or SIGTERM (what was done is written by written_on_exit)."""
    signal.signal(signal.SIGTERM, lambda *_: signal.default_int_handler(signal.SIGINT, None))
    try:
        return main()
    # no master, a service that never came up, a bad config: said plainly
    except RuntimeError as exc:
        print("error: %s" % exc, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted: the results so far are written (\"complete\": false)", file=sys.stderr)
        return 130


def ridges_note(goals):
    """The ridge of each segment's local linear fit, as the executor chose it by leave-one-out
    (-1: kernel average), over the goals: " (ridge per segment: 0.01, 100 / ...)" or ""."""
    seen = []
    for g in goals:
        ridges = ", ".join("kernel" if r < 0 else "%g" % r
                           for r in g.get("segment_slope_ridges") or [])
        if ridges and ridges not in seen:
            seen.append(ridges)
    return " (ridge per segment: %s)" % " / ".join(seen) if seen else ""
