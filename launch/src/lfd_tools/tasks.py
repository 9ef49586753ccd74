"""Tasks as the scripts see them: which tasks exist, the scenes of their demonstrations and of
their unseen reproduction goals, and what counts as success. Every script asks here, never the
files themselves, so the files' layout can change in one place.

A scene is {"id": int, "objects": {name: pose}, "goal": pose} in the world frame, with a pose
{"position": [x, y, z], "orientation": [w, x, y, z]}: the objects the task uses where they start,
and where the task's goal is. The objects a task does not use wait at their `parked` poses.
"""
import math

from lfd_tools import config as lfd_config


def pose(entry):
    """A pose from a tasks file entry: [x, y, z], [x, y, z, yaw] or {position, orientation|yaw}."""
    if isinstance(entry, dict):
        position = [float(v) for v in entry["position"]]
        if "orientation" in entry:
            w, x, y, z = (float(v) for v in entry["orientation"])
            n = math.sqrt(w * w + x * x + y * y + z * z)
            return {"position": position, "orientation": [w / n, x / n, y / n, z / n]}
        yaw = float(entry.get("yaw", 0.0))
    else:
        position, yaw = [float(v) for v in entry[:3]], float(entry[3]) if len(entry) > 3 else 0.0
    return {"position": position, "orientation": [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]}


def yaw_of(p):
    """Yaw (rad about world z) of a scene pose."""
    w, x, y, z = p["orientation"]
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _file():
    return lfd_config.load_tasks()


def names():
    """Every task with demonstrations, in file order."""
    return [k for k, v in _file().items() if isinstance(v, dict) and "sim" in v]


def objects(task):
    """The scene objects a task uses (the judged object first)."""
    return [success_criterion(task)["object"]]


def _scene(task, entry):
    obj = objects(task)[0]
    goal = entry["goal"] if "goal" in entry else entry["target"]
    return {"id": int(entry["id"]), "objects": {obj: pose(entry[obj])}, "goal": pose(goal)}


def scenes(task, mode):
    """The demonstrated scenes of a task in a mode (sim | teleop)."""
    return [_scene(task, e) for e in _file()[task][mode]]


def unseen_scenes(task, mode):
    """The reproduction goals of a task never demonstrated, for the libraries of a mode."""
    return [_scene(task, e) for e in _file()[task]["unseen"][mode]]


def parked(task):
    """{object: pose} of the scene objects the task does not use, where they wait."""
    used = set(objects(task))
    return {name: pose(p) for name, p in _file().get("park", {}).items() if name not in used}


def table_top():
    return float(_file()["table_top"])


def success_criterion(task):
    """The physical success criterion of a task (lfd_tools.judge reads it)."""
    return lfd_config.criteria_of(lfd_config.load_evaluation(), task)


def expected_transitions(task):
    """The ground-truth transitions [{from, to}] a task's segmentation must find."""
    return lfd_config.expected_transitions(lfd_config.load_evaluation(), task)


def segment_names(task):
    """A task's skills in order (grasp: approach, move)."""
    return lfd_config.segment_names(lfd_config.load_evaluation(), task)
