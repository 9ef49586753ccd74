"""The project's configuration files (config/, the lfd_config package), read and checked once.
The tasks (their scenes, skills and success criteria) are lfd_tools.tasks, which reads its files
through this module: the dependency goes one way, and this module imports no other of lfd_tools."""
import functools
import os

import yaml


@functools.lru_cache(maxsize=None)
def config_dir():
    import rospkg
    return rospkg.RosPack().get_path("lfd_config")


def config_path(name):
    return os.path.join(config_dir(), name)


# The robot when LFD_ROBOT does not name one (the launch files' `robot` argument has the same
# default: roslaunch cannot read it from here).
DEFAULT_ROBOT = "jvrc1"


def robot_name():
    """The robot the tools and launch files use: $LFD_ROBOT (the pipeline's --robot sets it), else
    the default. Its description package is <robot>_description."""
    return os.environ.get("LFD_ROBOT") or DEFAULT_ROBOT


def robot_dir(name=None):
    """The robot's description package folder (config/robot.yaml, models/, launch/upload.launch).
    Raises RuntimeError naming the package when it is not installed."""
    import rospkg
    package = (name or robot_name()) + "_description"
    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound:
        raise RuntimeError("robot %r: no package %s (a robot is a <robot>_description package with "
                           "config/robot.yaml; see DESIGN.md, Adding a robot)"
                           % (name or robot_name(), package))


def robot_file():
    """The robot file (lfd::loadRobotSetup's; its sensor table names the topics it publishes): the
    robot description package's config/robot.yaml."""
    return os.path.join(robot_dir(), "config", "robot.yaml")


@functools.lru_cache(maxsize=None)
def sensor_topic(message_type):
    """The topic of the robot file's first sensor table row publishing `message_type` (e.g.
    lfd_msgs/Touch, the pads the judge's contact rules read). Raises RuntimeError without one."""
    for row in load_yaml(robot_file()).get("sensors") or []:
        if row.get("type") == message_type:
            return row["topic"]
    raise RuntimeError("robot file %s has no %s row in its sensor table"
                       % (robot_file(), message_type))


def load_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f)


class _BoundedLoader(yaml.SafeLoader):
    """yaml.SafeLoader composing at most `max_depth` mappings and lists within one another: PyYAML's
    composer recurses once per level, and a deeply nested file ended in a RecursionError."""
    max_depth = 0

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0

    def compose_sequence_node(self, anchor):
        return self._nested(super().compose_sequence_node, anchor)

    def compose_mapping_node(self, anchor):
        return self._nested(super().compose_mapping_node, anchor)

    def _nested(self, compose, anchor):
        self._depth += 1
        try:
            if self._depth > self.max_depth:
                raise yaml.composer.ComposerError(None, None,
                                                  "nested deeper than %d levels" % self.max_depth,
                                                  self.peek_event().start_mark)
            return compose(anchor)
        finally:
            self._depth -= 1


def load_yaml_bounded(path, max_depth):
    """A YAML file of untrusted shape (its bytes decoded as YAML says: UTF-8 unless a BOM tells
    otherwise), at most `max_depth` collections deep. Raises yaml.YAMLError."""
    loader = type("BoundedLoader", (_BoundedLoader,), {"max_depth": max_depth})
    with open(path, "rb") as f:
        return yaml.load(f, Loader=loader)


def load_evaluation(path=None):
    """config/evaluation.yaml (the segmentation protocol: tolerance_s, methods), checked (a clear
    error, not a KeyError in the middle of a run)."""
    path = path or config_path("evaluation.yaml")
    evaluation = load_yaml(path)
    if not isinstance(evaluation, dict) or not isinstance(evaluation.get("segmentation"), dict):
        raise RuntimeError("%s: no 'segmentation:' section" % path)
    for key in ("tolerance_s", "methods"):
        if key not in evaluation["segmentation"]:
            raise RuntimeError("%s: segmentation.%s is missing" % (path, key))
    return evaluation


def run_roots(folder):
    """The folders a pipeline run's services may read and write: the run's output folder, wherever
    it is (the config's default roots are for users calling the services by hand), and what its
    datasets link to (DIR/datasets, or one dataset in it, recorded elsewhere and linked in is the
    user's choice; the services resolve links before they check a path)."""
    roots = [os.path.abspath(folder), os.path.realpath(folder)]
    datasets = os.path.join(folder, "datasets")
    linked = [datasets]
    if os.path.isdir(datasets):
        linked += [os.path.join(datasets, d) for d in sorted(os.listdir(datasets))]
    roots += [os.path.realpath(p) for p in linked if os.path.islink(p)]
    return list(dict.fromkeys(roots))
