"""The one judge of lfd's results: segmentation success against the ground truth, and physical
success of a demonstration or a reproduction. Pure Python (no ROS): the criteria come in as the
rules of a task file (lfd_tools.tasks.success_criterion), the times and poses as plain numbers.

Segmentation (the paper's rule): a demo is correct when it has exactly one changepoint per expected
transition, in order, each inside its transition's window widened by the tolerance. Also TSSB's
Covering and margin F1, and the time error of each transition.
Physical: every rule of the task's criterion holds (judge_rules). The rule types, each with its
parameters in the task file:
  object_at_goal  {object, distance: xyz | xy, tolerance_m, yaw_symmetry}: the object (or an
                  object's frame, e.g. drawer.handle) ends within tolerance_m of the goal, 3-D or
                  horizontally (yaw_symmetry: how many yaws look alike, for the reported yaw error)
  height          {object, min_m and/or max_m}: its centre ends that high above the table top
                  (lifted; or resting on the table, let go)
  joint           {joint, min and/or max}: an articulated joint's final value (m or rad)
  contact_path    {min_force_n, length_m, tolerance_m, passes, max_gap_s}: one sustained contact
                  (the finger pads' mean force >= min_force_n, breaks up to max_gap_s bridged)
                  during which the TCP covers the goal's stroke (length_m along the goal's x axis,
                  centred on it) end to end `passes` times, each end reached within tolerance_m,
                  never farther than tolerance_m beside it
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
    return {"demos": len(scores), "correct": correct, "success_rate": correct / n,
            "tolerance_s": tolerance, "covering": sum(s["covering"] for s in scores) / n,
            "f1": sum(s["f1"] for s in scores) / n, "time_error_median_s": percentile(errors, 0.5),
            "time_error_p95_s": percentile(errors, 0.95),
            "transitions_without_changepoint": sum(e is None for s in scores
                                                   for e in s["time_errors_s"])}


# ---- physical success ----------------------------------------------------------------------------

RULE_PARAMETERS = {  # rule -> (required, optional)
    "object_at_goal": ({"object", "distance", "tolerance_m"}, {"yaw_symmetry"}),
    "height": ({"object"}, {"min_m", "max_m"}),
    "joint": ({"joint"}, {"min", "max"}),
    "contact_path": ({"min_force_n", "length_m", "tolerance_m", "passes"}, {"max_gap_s"}),
}
DISTANCES = ("xyz", "xy")  # 3-D distance to the goal, or horizontal distance


def check_rule(rule, objects, joints, max_seconds=math.inf):
    """Raises ValueError naming what is wrong with one rule of a criterion; `objects` are the names
    a rule may judge (the task's objects and their frames), `joints` its articulated joints,
    `max_seconds` the longest time (a parameter named *_s) a task file may give."""
    if (not isinstance(rule, dict) or not isinstance(rule.get("rule"), str)
            or rule["rule"] not in RULE_PARAMETERS):
        raise ValueError("expected {rule: %s, ...}" % " | ".join(sorted(RULE_PARAMETERS)))
    required, optional = RULE_PARAMETERS[rule["rule"]]
    keys = set(rule) - {"rule"}
    if required - keys:
        raise ValueError("rule %s lacks %s" % (rule["rule"], ", ".join(sorted(required - keys))))
    if keys - required - optional:
        raise ValueError("rule %s: unknown key(s) %s"
                         % (rule["rule"], ", ".join(sorted(keys - required - optional))))
    if "object" in rule and (not isinstance(rule["object"], str) or rule["object"] not in objects):
        raise ValueError("'%s' is not an object (or object.frame) of the task (%s)"
                         % (rule["object"], ", ".join(sorted(objects)) or "none"))
    if "joint" in rule and rule["joint"] not in joints:
        raise ValueError("'%s' is not a joint of the task's objects (%s)"
                         % (rule["joint"], ", ".join(joints) or "none"))
    if rule["rule"] == "object_at_goal" and rule["distance"] not in DISTANCES:
        raise ValueError("distance is '%s', expected one of %s"
                         % (rule["distance"], ", ".join(DISTANCES)))
    if rule["rule"] in ("height", "joint") and not ({"min_m", "max_m", "min", "max"} & keys):
        raise ValueError("rule %s needs a minimum or a maximum" % rule["rule"])
    for key in keys - {"object", "distance", "joint"}:
        if (not isinstance(rule[key], (int, float)) or isinstance(rule[key], bool)
                or not math.isfinite(rule[key])):
            raise ValueError("%s must be a number" % key)
        if key.endswith("_s") and rule[key] > max_seconds:
            raise ValueError("%s: %g s is over %g s (task_limits/max_step_seconds of the scene "
                             "file)" % (key, rule[key], max_seconds))


def _yaw(q):
    w, x, y, z = q
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _object_at_goal(rule, measured, scene, table_top):
    p = measured["objects"].get(rule["object"])
    if p is None:
        return {"success": False, "reason": "%s was not recorded" % rule["object"]}
    goal = scene["goal"]
    criteria = {"object": rule["object"], "distance": rule["distance"],
                "tolerance_m": rule["tolerance_m"], "yaw_symmetry": rule.get("yaw_symmetry", 1)}
    return physical_outcome(criteria, p["position"], goal["position"], table_top,
                            _yaw(p["orientation"]), _yaw(goal["orientation"]))


def _bounded(value, lo, hi, unit_scale, unit, what):
    ok = (lo is None or value >= lo) and (hi is None or value <= hi)
    need = " and ".join(s for s in (lo is not None and ">= %g" % (lo * unit_scale),
                                    hi is not None and "<= %g" % (hi * unit_scale)) if s)
    return ok, "%s %.3g%s (need %s%s)" % (what, value * unit_scale, (" " + unit) if unit else "",
                                          need, (" " + unit) if unit else "")


def _height(rule, measured, scene, table_top):
    p = measured["objects"].get(rule["object"])
    if p is None:
        return {"success": False, "reason": "%s was not recorded" % rule["object"]}
    height = p["position"][2] - table_top
    ok, why = _bounded(height, rule.get("min_m"), rule.get("max_m"), 100, "cm",
                       "%s above the table" % rule["object"])
    return {"success": ok, "height_m": height, "reason": why}


def _joint(rule, measured, scene, table_top):
    value = measured["joints"].get(rule["joint"])
    if value is None:
        return {"success": False, "reason": "joint %s was not recorded" % rule["joint"]}
    ok, why = _bounded(value, rule.get("min"), rule.get("max"), 1, "",
                       "joint %s ends at" % rule["joint"])
    return {"success": ok, "joint_value": value, "reason": why}


def contact_runs(samples, min_force, max_gap):
    """[(first, last)] index spans of the samples (t, force, position) in contact (force >=
    min_force), breaks up to max_gap seconds bridged."""
    runs = []
    for i, (t, f, _) in enumerate(samples):
        if f < min_force:
            continue
        if runs and t - samples[runs[-1][1]][0] <= max_gap:
            runs[-1][1] = i
        else:
            runs.append([i, i])
    return [tuple(r) for r in runs]


def stroke_passes(along, half, tolerance):
    """End-to-end traversals of a stroke [-half, half] by positions along it: each arrival in one
    end zone (within tolerance of its end) after being in the other counts one."""
    passes, zone = 0, None
    for a in along:
        here = -1 if a <= -half + tolerance else (1 if a >= half - tolerance else None)
        if here is not None and here != zone:
            passes += zone is not None
            zone = here
    return passes


def _contact_path(rule, measured, scene, table_top):
    samples = measured.get("contact") or []
    if not samples:
        return {"success": False, "reason": "no touch and TCP samples were recorded"}
    goal = scene["goal"]
    yaw = _yaw(goal["orientation"])
    u, v = (math.cos(yaw), math.sin(yaw)), (-math.sin(yaw), math.cos(yaw))
    gx, gy = goal["position"][:2]
    best = None
    for lo, hi in contact_runs(samples, rule["min_force_n"], rule.get("max_gap_s", 0.0)):
        rel = [(p[0] - gx, p[1] - gy) for _, _, p in samples[lo:hi + 1]]
        along = [d[0] * u[0] + d[1] * u[1] for d in rel]
        beside = max(abs(d[0] * v[0] + d[1] * v[1]) for d in rel)
        n = stroke_passes(along, rule["length_m"] / 2, rule["tolerance_m"])
        run = (n, samples[hi][0] - samples[lo][0], beside)
        if best is None or run[:2] > best[:2]:
            best = run
    if best is None:
        return {"success": False, "passes": 0,
                "reason": "never in contact (pad force >= %g N)" % rule["min_force_n"]}
    passes, duration, beside = best
    ok = passes >= rule["passes"] and beside <= rule["tolerance_m"]
    return {"success": ok, "passes": passes, "contact_s": duration, "beside_m": beside,
            "reason": "a %.1f s contact (>= %g N) covers the %.0f cm stroke %d time(s) (need %d), "
                      "at most %.1f cm beside it (need <= %.1f)" % (
                          duration, rule["min_force_n"], 100 * rule["length_m"], passes,
                          rule["passes"], 100 * beside, 100 * rule["tolerance_m"])}


RULES = {"object_at_goal": _object_at_goal, "height": _height, "joint": _joint,
         "contact_path": _contact_path}


def judge_rules(criterion, measured, scene, table_top):
    """Physical success of one demonstration or reproduction: every rule of `criterion`
    (tasks.success_criterion) against what was measured at its end, `measured` =
    {"objects": {name: pose}, "joints": {name: value}, "contact": [(t, pad force, TCP world
    position)]} (lfd_tools.bags.measure), for `scene` = {"goal": pose, ...}. Returns success,
    reason (every rule's, joined), rules (each rule's outcome) and, from the object rules,
    distance_m, height_m, yaw_error_rad."""
    outcomes = []
    for rule in criterion["rules"]:
        o = RULES[rule["rule"]](rule, measured, scene, table_top)
        o["rule"] = rule["rule"]
        outcomes.append(o)
    first = lambda key: next((o[key] for o in outcomes if o.get(key) is not None), None)
    return {"success": all(o["success"] for o in outcomes), "rules": outcomes,
            "reason": "; ".join(o["reason"] for o in outcomes),
            "distance_m": first("distance_m"), "height_m": first("height_m"),
            "yaw_error_rad": first("yaw_error_rad")}


def wrap(angle, period):
    return (angle + period / 2) % period - period / 2


def physical_outcome(criteria, object_position, goal_position, table_top, object_yaw=None,
                     goal_yaw=None):
    """Judges an object's final pose against its goal: the object_at_goal rule (and, with
    min_lift_m, a height rule) of a task's criterion, as tasks.success_criterion also gives them:
    {object, distance, tolerance_m, min_lift_m, yaw_symmetry}. Returns success, distance_m,
    height_m (above the table top), yaw_error_rad (None without both yaws; modulo the object's
    symmetry) and a reason."""
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


def describe_rule(rule):
    """A rule of a task file in words."""
    kind = rule["rule"]
    if kind == "object_at_goal":
        return "the %s ends within %.1f cm of its goal (%s)" % (
            rule["object"], 100 * rule["tolerance_m"],
            "horizontal distance" if rule["distance"] == "xy" else "3-D")
    if kind == "height":
        return "the %s ends %s above the table" % (rule["object"], " and ".join(
            s for s in ("min_m" in rule and ">= %.0f cm" % (100 * rule["min_m"]),
                        "max_m" in rule and "<= %.0f cm" % (100 * rule["max_m"])) if s))
    if kind == "joint":
        return "the joint %s ends %s" % (rule["joint"], " and ".join(
            s
            for s in ("min" in rule and ">= %g" % rule["min"],
                      "max" in rule and "<= %g" % rule["max"]) if s))
    return ("a sustained contact (>= %g N) covers the %.0f cm stroke %d times within %.0f cm"
            % (rule["min_force_n"], 100 * rule["length_m"], rule["passes"],
               100 * rule["tolerance_m"]))


def describe_criteria(task, criteria):
    """One line for reports: what success means for a task (tasks.success_criterion)."""
    return "%s: %s" % (task, ", ".join(describe_rule(r) for r in criteria["rules"]))
