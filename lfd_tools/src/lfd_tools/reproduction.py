"""One reproduction in the simulated cell, judged as a demonstration is: the task's scene placed,
the executor's goal driven in lockstep, the objects left to settle, and the task's success rules
applied to what was measured (lfd_tools.judge). Shared by reproduce_goals.py and the monitoring
benchmarks (which inject faults once the motion is sent)."""
import argparse

from lfd_tools import bags, judge, lockstep, tasks

SETTLE_BEFORE_S = 0.3  # sim s after placing the objects, before executing
SETTLE_AFTER_S = 1.0   # sim s for the objects to come to rest before they are judged


class NotJudged(RuntimeError):
    """The goal ended but its outcome could not be measured; `result` is the executor's."""

    def __init__(self, message, result):
        RuntimeError.__init__(self, message)
        self.result = result


def place_scene(cell, task, scene):
    """The task's objects where the scene has them (the others parked), its joints at their
    start."""
    cell.set_scene(dict(tasks.parked(task), **scene["objects"]), SETTLE_BEFORE_S,
                   scene.get("joints"))


def execute_and_judge(cell, task, scene, library, duration_scale=1.0, allow_extrapolation=False,
                      after_scene=None, on_moving=None, follow=False):
    """(result, wall s, judged outcome). after_scene(): once the scene is placed (e.g. start a bag);
    on_moving(feedback): once the motion is sent (lockstep.Cell.execute); follow: the objects'
    poses in their own tf frames, followed if they move (lockstep.execute_goal)."""
    criterion = tasks.success_criterion(task)
    place_scene(cell, task, scene)
    if after_scene:
        after_scene()
    measured = cell.record(bags.topics_for(criterion))
    try:
        res, wall = cell.execute(lockstep.execute_goal(library, scene, duration_scale,
                                                       allow_extrapolation, follow=follow),
                                 on_moving=on_moving)
        if res is None:
            raise RuntimeError("the executor gave no result")
        cell.advance(SETTLE_AFTER_S)
        with cell.timed("judge_waits"):
            arrived = measured.wait_until(cell.now())
        if not arrived:
            raise NotJudged("the final state was not published (%s)"
                            % ", ".join(measured.messages), res)
    finally:
        measured.close()
    with cell.timed("judging"):
        outcome = judge.judge_rules(criterion, bags.measure(measured, criterion,
                                                            tasks.base_in_world()),
                                    scene, tasks.table_top())
    return res, wall, outcome


def goal_bench_parser(description, goals):
    """The arguments every reproduction benchmark takes: a skill library, its mode, the tasks and
    how many of each task's unseen goals (the first N), and --attach to a running graph."""
    ap = argparse.ArgumentParser(description=description,
                                 formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--library-dir", required=True)
    ap.add_argument("--mode", default="sim")
    ap.add_argument("--tasks", default=None, help="comma-separated (default: every task)")
    ap.add_argument("--goals", type=int, default=goals, help="unseen goals per task (the first N)")
    ap.add_argument("--attach", action="store_true", help="use the nodes at ROS_MASTER_URI")
    return ap


def selected_tasks(arg):
    """The tasks of a comma-separated --tasks argument, or every task."""
    return [t for t in arg.split(",") if t] if arg else tasks.names()
