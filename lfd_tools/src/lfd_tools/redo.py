"""Which demonstrations of a dataset must be recorded (again): the missing ones, and those whose bag
is no usable demonstration (cut off by a crash, unreadable, or physically unsuccessful by the task
file's criterion). Such a bag is never deleted: it is set aside as <bag>.failed (.failed.2, ...)
beside the dataset, where no reader of *.bag takes it for a demonstration, and recorded again."""
import os

from lfd_tools import bags

FAILED_SUFFIX = ".failed"


def set_aside(path):
    """Renames `path` to the first free <path>.failed[.N]; returns the new path."""
    target, n = path + FAILED_SUFFIX, 1
    while os.path.exists(target):
        n += 1
        target = "%s%s.%d" % (path, FAILED_SUFFIX, n)
    os.rename(path, target)
    return target


class Outcomes(object):
    """demo_outcome of each bag, read once per version of the file (its size and mtime): the
    summary after generation reuses what the redo check read."""

    def __init__(self, judge=bags.demo_outcome):
        self._judge = judge
        self._known = {}

    def __call__(self, path):
        st = os.stat(path)
        key = (path, st.st_size, st.st_mtime_ns)
        if key not in self._known:
            self._known[key] = self._judge(path)
        return self._known[key]


def demos_to_record(bag_of, outcome):
    """bag_of: {configuration: bag path}; outcome: path -> demo_outcome dict. Returns (the
    configurations to record, [(configuration, set-aside path, reason)])."""
    todo, aside = [], []
    for config, path in sorted(bag_of.items()):
        if not os.path.exists(path):
            todo.append(config)
            continue
        result = outcome(path)
        if result["success"]:
            continue
        aside.append((config, set_aside(path), result["reason"] or "not physically successful"))
        todo.append(config)
    return todo, aside
