"""Tasks as the scripts see them, read from the task files (config/tasks/<name>.yaml, format in
config/tasks/README.md) and the scene file (config/scene.yaml). Every script asks here, never the
files themselves, so the files' layout can change in one place.

A scene is {"id": int, "objects": {name: pose}, "goal": pose, "joints": {joint: start value}} in
the world frame, with a pose {"position": [x, y, z], "orientation": [w, x, y, z]}: the objects the
task uses where they start, where the task's goal is, and the start of the articulated joints of
its objects. The objects a task does not use wait at their `parked` poses.

Task files are found in config/tasks/ and in the folders of $LFD_TASKS_PATH (colon-separated,
searched first), so a task of one's own needs no change to the repository: a file
<folder>/<name>.yaml is the task <name>.

A task file is checked once, by the demonstrator's own loader (lfd_sim_bridge's check_task: the
format, every number finite, every time within the scene's task_limits), then read here within the
same bounds, and its success criterion checked by the judge's rules: one check of the format, not
two that could disagree.
"""
import glob
import math
import os
import subprocess

import yaml

from lfd_tools import config as lfd_config
from lfd_tools import judge

MODES = ("sim", "teleop")
TASKS_PATH_VAR = "LFD_TASKS_PATH"
CHECK_TIMEOUT_S = 30.0  # check_task reads one small file: seconds would mean it hangs
_cache = {}


def pose(entry):
    """A pose from a file entry: [x, y, z], [x, y, z, yaw] or {position, orientation|yaw}."""
    if isinstance(entry, dict):
        position = [float(v) for v in entry["position"]]
        if "orientation" in entry:
            w, x, y, z = (float(v) for v in entry["orientation"])
            n = math.sqrt(w * w + x * x + y * y + z * z)
            return {"position": position, "orientation": [w / n, x / n, y / n, z / n]}
        yaw = float(entry.get("yaw", 0.0))
    else:
        if len(entry) not in (3, 4):
            raise ValueError("a pose is [x, y, z] or [x, y, z, yaw], got %r" % (entry,))
        position, yaw = [float(v) for v in entry[:3]], float(entry[3]) if len(entry) > 3 else 0.0
    return {"position": position, "orientation": [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]}


def yaw_of(p):
    """Yaw (rad about world z) of a scene pose."""
    w, x, y, z = p["orientation"]
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


# ---- files ---------------------------------------------------------------------------------------


def directories():
    """Where task files are looked for, in order: $LFD_TASKS_PATH's folders, then config/tasks."""
    extra = [d for d in os.environ.get(TASKS_PATH_VAR, "").split(":") if d]
    return extra + [lfd_config.config_path("tasks")]


def task_file(task):
    for d in directories():
        path = os.path.join(d, task + ".yaml")
        if os.path.isfile(path):
            return path
    raise RuntimeError("no task file %s.yaml in %s (known tasks: %s)"
                       % (task, ", ".join(directories()), ", ".join(names())))


def _load(path, read):
    key = (path, os.path.getmtime(path))
    if key not in _cache:
        _cache[key] = read(path)
    return _cache[key]


def scene_file():
    return lfd_config.config_path("scene.yaml")


def scene():
    """config/scene.yaml: table_top, base_link_in_world, tool_orientation, objects, task_limits."""
    return _load(scene_file(), _read_scene)


def task_limits():
    """{max_step_seconds, max_nesting_depth}: the bounds of every task file (config/scene.yaml)."""
    return scene()["task_limits"]


def _read_scene(path):
    data = lfd_config.load_yaml(path)
    for key in ("table_top", "base_link_in_world", "objects", "task_limits"):
        if not isinstance(data, dict) or key not in data:
            raise RuntimeError("scene file '%s': '%s' is missing" % (path, key))
    return data


def _task(task):
    return _load(task_file(task), read_task_file)


def names():
    """Every task with a file, sorted by name (a folder of $LFD_TASKS_PATH shadows config/tasks)."""
    found = set()
    for d in directories():
        found.update(os.path.splitext(os.path.basename(p))[0]
                     for p in glob.glob(os.path.join(d, "*.yaml")))
    return sorted(found)


def spread(items, n):
    """n items evenly spread over the list (all of them when n <= 0 or n >= len): a reduced run's
    configurations or goals."""
    if n <= 0 or n >= len(items):
        return list(items)
    if n == 1:
        return [items[len(items) // 2]]
    return [items[round(i * (len(items) - 1) / (n - 1))] for i in range(n)]


def datasets(tasks=None):
    """Dataset names <mode>_<task> of the tasks (default all), sim first."""
    return ["%s_%s" % (m, t) for m in MODES for t in (tasks or names())]


# ---- what a task is ------------------------------------------------------------------------------


def description(task):
    return str(_task(task).get("description", ""))


def objects(task):
    """The scene objects a task uses."""
    return list(_task(task)["objects"])


def joints(task):
    """The articulated joints of the objects a task uses."""
    objs = scene()["objects"]
    return [j for o in objects(task) for j in (objs[o].get("joints") or {})]


def phases(task):
    """[{"name", "window"}] in order: the ground-truth phases (a window is the transition between
    the skills around it, e.g. grasp's gripper closing)."""
    return [{"name": p["name"], "window": bool(p.get("window", False))}
            for p in _task(task)["phases"]]


def grasps(task):
    """Whether the robot grasps something in the task: its hand starts open (gripper_at_start) and
    a step closes it (a fist that pushes or wipes holds nothing)."""
    t = _task(task)
    if str(t.get("gripper_at_start", "open")) == "closed":
        return False
    return any(isinstance(step, dict) and step.get("gripper") == "close"
               for p in t["phases"] for step in p.get("steps", []))


def segment_names(task):
    """A task's skills in order (grasp: approach, move): its phases that are not windows."""
    return [p["name"] for p in phases(task) if not p["window"]]


def expected_transitions(task):
    """The ground-truth transitions [{from, to}] a task's segmentation must find: one between each
    two consecutive skills (across the window between them, if any)."""
    skills = segment_names(task)
    return [{"from": a, "to": b} for a, b in zip(skills, skills[1:])]


def _scene_of(task, entry):
    return {"id": int(entry["id"]), "objects": {o: pose(entry[o]) for o in objects(task)},
            "goal": pose(entry["goal"]),
            "joints": {j: float((entry.get("joints") or {}).get(j, 0.0)) for j in joints(task)}}


def scenes(task, mode):
    """The demonstrated scenes of a task in a mode (sim | teleop)."""
    return [_scene_of(task, e) for e in _task(task)["configurations"][mode]]


def unseen_scenes(task, mode):
    """The reproduction goals of a task never demonstrated, for the libraries of a mode."""
    return [_scene_of(task, e) for e in ((_task(task).get("unseen") or {}).get(mode) or [])]


def parked(task):
    """{object: pose} of the scene objects the task does not use, where they wait."""
    used = set(objects(task))
    return {name: pose(o["park"]) for name, o in scene()["objects"].items() if name not in used}


def table_top():
    return float(scene()["table_top"])


def base_in_world():
    """base_link's position in the world (no rotation): /ee_pose is in base_link."""
    return [float(v) for v in scene()["base_link_in_world"]]


def body_of(name):
    """The body the simulator reports (/objects/<body>/pose) for an object or an object's frame
    ("drawer.handle" -> drawer_handle)."""
    if "." not in name:
        return name
    obj, part = name.split(".", 1)
    frame = scene()["objects"][obj]["frames"][part]
    if not isinstance(frame, dict) or "body" not in frame:
        raise RuntimeError("scene file '%s': objects.%s.frames.%s names no body the simulator "
                           "reports" % (scene_file(), obj, part))
    return frame["body"]


def success_criterion(task):
    """The physical success criterion of a task: {"rules": [...]} (lfd_tools.judge.judge_rules),
    and for a task that judges an object at its goal also that rule's object (its body), distance,
    tolerance_m, yaw_symmetry and min_lift_m (the height rule's minimum), as physical_outcome
    reads them."""
    rules = [dict(r) for r in _task(task)["success"]]
    out = {"rules": rules, "object": None}
    at_goal = next((r for r in rules if r["rule"] == "object_at_goal"), None)
    if at_goal:
        out.update(object=body_of(at_goal["object"]), distance=at_goal["distance"],
                   tolerance_m=at_goal["tolerance_m"], yaw_symmetry=at_goal.get("yaw_symmetry", 1))
        lift = next((r for r in rules if r["rule"] == "height" and r["object"] == at_goal["object"]
                     and "min_m" in r), None)
        if lift:
            out["min_lift_m"] = lift["min_m"]
    return out


# ---- checks --------------------------------------------------------------------------------------


def read_task_file(path):
    """A task file's content, checked: RuntimeError naming the file (and the key) otherwise."""
    check_format(path)
    try:
        data = lfd_config.load_yaml_bounded(path, task_limits()["max_nesting_depth"])
    except yaml.YAMLError as exc:
        raise RuntimeError("task file '%s' cannot be read: %s" % (path, exc))
    _check_success(data, path)
    return data


def check_format(path):
    """The task format, checked by the demonstrator's loader (lfd_sim_bridge check_task)."""
    from catkin.find_in_workspaces import find_in_workspaces
    found = find_in_workspaces(search_dirs=["libexec"], project="lfd_sim_bridge", path="check_task")
    if not found:
        raise RuntimeError("lfd_sim_bridge's check_task is not built (./lfd build): task files "
                           "cannot be checked")
    try:
        done = subprocess.run([found[0], "--scene", scene_file(), path], stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, universal_newlines=True, errors="replace",
                              timeout=CHECK_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        raise RuntimeError("task file '%s': check_task took over %.0f s" % (path, CHECK_TIMEOUT_S))
    if done.returncode in (1, 2):
        raise RuntimeError(done.stderr.strip())
    if done.returncode != 0:
        raise RuntimeError("task file '%s': check_task failed (status %d): %s"
                           % (path, done.returncode, done.stderr.strip()))


def _check_success(data, path):
    """The success criterion (the judge's rules; the demonstrator never judges), with an error
    naming the file and the key."""
    def fail(key, what):
        raise RuntimeError("task file '%s': %s: %s" % (path, key, what))

    known = scene()["objects"]
    objs = data.get("objects") if isinstance(data, dict) else None
    if not isinstance(objs, list) or not all(isinstance(o, str) and o in known for o in objs):
        fail("objects", "not read as check_task read them")
    parts = {"%s.%s" % (o, f) for o in objs for f in (known[o].get("frames") or {})}
    task_joints = [j for o in objs for j in (known[o].get("joints") or {})]
    rules = data.get("success")
    if not isinstance(rules, list) or not rules:
        fail("success", "expected a list of rules")
    for i, rule in enumerate(rules):
        try:
            judge.check_rule(rule, set(objs) | parts, task_joints,
                             task_limits()["max_step_seconds"])
        except ValueError as exc:
            fail("success[%d]" % i, str(exc))
