"""The project's configuration files (config/, the lfd_config package), read and checked once."""
import os

import yaml

DISTANCES = ("xyz", "xy")  # physical criteria: 3-D distance to the goal, or horizontal distance


def config_dir():
    import rospkg
    return rospkg.RosPack().get_path("lfd_config")


def config_path(name):
    return os.path.join(config_dir(), name)


def load_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f)


def load_tasks(path=None):
    return load_yaml(path or config_path("tasks.yaml"))


def load_evaluation(path=None):
    """config/evaluation.yaml, with its reproduction criteria checked (a clear error, not a
    KeyError in the middle of a run)."""
    path = path or config_path("evaluation.yaml")
    evaluation = load_yaml(path)
    for section in ("segmentation", "reproduction"):
        if not isinstance(evaluation, dict) or not isinstance(evaluation.get(section), dict):
            raise RuntimeError("%s: no '%s:' section" % (path, section))
    for task, criteria in evaluation["reproduction"].items():
        check_criteria(task, criteria, path)
    return evaluation


def check_criteria(task, criteria, where):
    if not isinstance(criteria, dict):
        raise RuntimeError("%s: reproduction.%s is not a mapping" % (where, task))
    for key in ("object", "distance", "tolerance_m"):
        if key not in criteria:
            raise RuntimeError("%s: reproduction.%s lacks '%s'" % (where, task, key))
    if criteria["distance"] not in DISTANCES:
        raise RuntimeError("%s: reproduction.%s.distance is '%s', expected one of %s"
                           % (where, task, criteria["distance"], ", ".join(DISTANCES)))


def criteria_of(evaluation, task):
    """The physical success criteria of a task (evaluation.yaml `reproduction.<task>`)."""
    try:
        return evaluation["reproduction"][task]
    except KeyError:
        raise RuntimeError("config/evaluation.yaml has no reproduction criteria for task '%s' (known: %s)"
                           % (task, ", ".join(sorted(evaluation["reproduction"]))))


def expected_transitions(evaluation, task):
    """The ground-truth transitions [{from, to}] a task's segmentation must find."""
    try:
        return evaluation["segmentation"]["expected"][task]
    except KeyError:
        raise RuntimeError("config/evaluation.yaml has no segmentation expectations for task '%s'" % task)


def segment_names(evaluation, task):
    """Names of a task's segments in order: the phase before the first transition, then the phase
    each transition leads to (grasp: approach, move)."""
    transitions = expected_transitions(evaluation, task)
    return [transitions[0]["from"]] + [t["to"] for t in transitions]
