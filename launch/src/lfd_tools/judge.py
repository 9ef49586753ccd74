"""The one judge of lfd's results: segmentation success against the ground truth, and physical
success of an object's final pose. Pure Python (no ROS): the criteria come in as the dicts of
config/evaluation.yaml (lfd_tools.config), the times and poses as plain numbers.

Segmentation (the paper's rule): a demo is correct when it has exactly one changepoint per expected
transition, in order, each inside its transition's window widened by the tolerance. Also TSSB's
Covering and margin F1, and the time error of each transition.
Physical: the object ends within `tolerance_m` of its goal (3-D for distance xyz, horizontal for
xy) and, when `min_lift_m` is given, at least that far above the table top.
"""
import math

# ---- segmentation --------------------------------------------------------------------------------


def expected_windows(phases, expected, tolerance):
    """Windows [t0 - tol, t1 + tol] from ground-truth phases [(name, start)]: t0 = when phase
    `from` ends, t1 = when phase `to` begins (the grasp phase between approach and move)."""
    windows = []
    for spec in expected:
        ends = [i for i, (name, _) in enumerate(phases) if name == spec["from"]]
        starts = [i for i, (name, _) in enumerate(phases) if name == spec["to"]]
        if not ends or not starts or ends[-1] + 1 >= len(phases):
            raise RuntimeError("ground truth lacks phase %s or %s" % (spec["from"], spec["to"]))
        t0 = phases[ends[-1] + 1][1]  # first time after `from`
        t1 = phases[starts[0]][1]
        windows.append((min(t0, t1) - tolerance, max(t0, t1) + tolerance))
    return windows


def segmentation_correct(changepoint_times, windows):
    """(correct, why): exactly one changepoint per window, in order."""
    cps = sorted(changepoint_times)
    if len(cps) != len(windows):
        return False, "expected %d changepoints, got %d" % (len(windows), len(cps))
    for cp, (lo, hi) in zip(cps, windows):
        if not lo <= cp <= hi:
            return False, "changepoint %.2f s outside [%.2f, %.2f]" % (cp, lo, hi)
    return True, "ok"


def segments(points, start, end):
    edges = [start] + sorted(p for p in points if start < p < end) + [end]
    return list(zip(edges[:-1], edges[1:]))


def covering(true_points, found_points, start, end):
    """TSSB Covering (van den Burg & Williams): sum over true segments of |A| / N max_B J(A, B)."""
    truth, found = segments(true_points, start, end), segments(found_points, start, end)
    total = 0.0
    for a0, a1 in truth:
        best = 0.0
        for b0, b1 in found:
            inter = max(0.0, min(a1, b1) - max(a0, b0))
            union = max(a1, b1) - min(a0, b0)
            best = max(best, inter / union if union > 0 else 0.0)
        total += (a1 - a0) * best
    return total / (end - start) if end > start else 0.0


def margin_f1(true_points, found_points, start, end, margin):
    """TSSB's F1 with a margin: the first and last sample count as changepoints of both sides."""
    truth = [start] + sorted(true_points) + [end]
    found = [start] + sorted(p for p in found_points if start < p < end) + [end]
    used, tp = set(), 0
    for t in truth:
        for i, f in enumerate(found):
            if i not in used and abs(f - t) <= margin:
                used.add(i)
                tp += 1
                break
    precision, recall = tp / float(len(found)), tp / float(len(truth))
    return 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0


def time_errors(windows, found):
    """Distance from the nearest changepoint to each true transition window (0 inside; None when
    nothing was found)."""
    if not found:
        return [None] * len(windows)
    return [min(0.0 if lo <= c <= hi else min(abs(c - lo), abs(c - hi)) for c in found)
            for lo, hi in windows]


def percentile(values, q):
    if not values:
        return float("nan")
    v = sorted(values)
    k = (len(v) - 1) * q
    lo = int(k)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def score_demo(found, true_windows, start, end, tolerance):
    """One demo's changepoints against its true transitions, each a window (lo, hi) in seconds
    (lo == hi for an instant), over the demo's span [start, end]."""
    windows = [(lo - tolerance, hi + tolerance) for lo, hi in true_windows]
    ok, why = segmentation_correct(found, windows)
    points = [0.5 * (lo + hi) for lo, hi in true_windows]
    return {"correct": ok, "reason": why, "windows_s": windows,
            "covering": covering(points, found, start, end),
            "f1": margin_f1(points, found, start, end, tolerance),
            "time_errors_s": time_errors(true_windows, found)}


def summarize_scores(scores, tolerance):
    """A dataset's figures from the per-demo scores of score_demo."""
    n = float(len(scores))
    errors = [e for s in scores for e in s["time_errors_s"] if e is not None]
    correct = sum(s["correct"] for s in scores)
    return {"demos": len(scores), "correct": correct, "success_rate": correct / n, "tolerance_s": tolerance,
            "covering": sum(s["covering"] for s in scores) / n, "f1": sum(s["f1"] for s in scores) / n,
            "time_error_median_s": percentile(errors, 0.5), "time_error_p95_s": percentile(errors, 0.95),
            "transitions_without_changepoint": sum(e is None for s in scores for e in s["time_errors_s"])}


# ---- physical success ----------------------------------------------------------------------------


def wrap(angle, period):
    return (angle + period / 2) % period - period / 2


def physical_outcome(criteria, object_position, goal_position, table_top, object_yaw=None, goal_yaw=None):
    """Judges an object's final pose against its goal with a task's criteria (evaluation.yaml
    `reproduction.<task>`). Returns success, distance_m, height_m (above the table top),
    yaw_error_rad (None without both yaws; modulo the object's symmetry) and a reason."""
    d = [a - b for a, b in zip(object_position[:3], goal_position[:3])]
    horizontal = criteria["distance"] == "xy"
    distance = math.hypot(d[0], d[1]) if horizontal else math.sqrt(sum(v * v for v in d))
    height = object_position[2] - table_top
    tolerance, min_lift = criteria["tolerance_m"], criteria.get("min_lift_m")
    success = distance <= tolerance and (min_lift is None or height >= min_lift)
    reason = "%s %.1f cm from its goal (%s, need <= %.1f)" % (
        criteria["object"], 100 * distance, "horizontal" if horizontal else "3-D", 100 * tolerance)
    if min_lift is not None:
        reason += ", %.1f cm above the table (need >= %.1f)" % (100 * height, 100 * min_lift)
    yaw_error = None
    if object_yaw is not None and goal_yaw is not None:
        yaw_error = abs(wrap(object_yaw - goal_yaw, 2 * math.pi / criteria.get("yaw_symmetry", 1)))
    return {"success": success, "distance_m": distance, "height_m": height,
            "yaw_error_rad": yaw_error, "reason": reason}


def describe_criteria(task, criteria):
    """One line for reports: what success means for a task."""
    text = "%s: the %s ends within %.0f cm of its goal (%s)" % (
        task, criteria["object"], 100 * criteria["tolerance_m"],
        "horizontal distance" if criteria["distance"] == "xy" else "3-D")
    if criteria.get("min_lift_m") is not None:
        text += ", >= %.0f cm above the table" % (100 * criteria["min_lift_m"])
    return text
