#!/usr/bin/python3
"""rostest (task_from_yaml_reproduce.test): a task that exists only as a YAML file, written here at
test time in a folder of $LFD_TASKS_PATH (not among config/tasks), goes through demonstrate ->
segment -> learn -> reproduce with no code change: `pipeline.py --datasets sim_hoist`. The
library's segment goals must be learned in the frames the task implies (the reach ends at the
block, the hoist at the goal), and the unseen goals be reached."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import rospkg
import rostest

from lfd_tools import tasks

HOIST = """
description: Take the block from the table and hold it up at the goal.
objects: [block]
goal: where the block's centre must end, in the air
variation:
  block: {x: 0.004, yaw: 0.1}
phases:
  - name: reach
    steps:
      - {gripper: open, duration: 0.5, label: open}
      - {move: {frame: block, position: [0, 0, 0.10], symmetry: 4}, duration: 2.0, label: above}
      - {move: {frame: block, position: [0, 0, 0.003], symmetry: 4}, duration: 1.2, label: descend}
  - name: close
    window: true
    steps:
      - {gripper: close, until_contact: both, duration: 1.0, settle: 0.3, label: close}
  - name: hoist
    steps:
      - {retreat: [0, 0, 0.10], duration: 1.2, label: lift}
      - {carry: block, to: {frame: goal}, duration: 2.0, label: carry}
      - {hold: 0.5}
success:
  - {rule: object_at_goal, object: block, distance: xyz, tolerance_m: 0.03, yaw_symmetry: 4}
  - {rule: height, object: block, min_m: 0.08}
configurations:
  sim:
    - {id: 0, block: [0.42, -0.40, 0.82, 0.0], goal: [0.50, -0.30, 0.95, 0.0]}
    - {id: 1, block: [0.58, -0.40, 0.82, 0.2], goal: [0.46, -0.26, 0.95, 0.2]}
    - {id: 2, block: [0.42, -0.20, 0.82, -0.2], goal: [0.54, -0.34, 0.95, -0.2]}
    - {id: 3, block: [0.58, -0.20, 0.82, 0.1], goal: [0.44, -0.36, 0.95, 0.1]}
    - {id: 4, block: [0.50, -0.30, 0.82, 0.0], goal: [0.56, -0.22, 0.95, 0.0]}
  teleop:
    - {id: 0, block: [0.50, -0.30, 0.82, 0.0], goal: [0.50, -0.24, 0.95, 0.0]}
unseen:
  sim:
    - {id: 100, block: [0.46, -0.34, 0.82, 0.1], goal: [0.52, -0.28, 0.95, 0.1]}
    - {id: 101, block: [0.54, -0.26, 0.82, -0.1], goal: [0.48, -0.32, 0.95, -0.1]}
    - {id: 102, block: [0.50, -0.36, 0.82, 0.0], goal: [0.50, -0.26, 0.95, 0.0]}
"""


class TaskFromYamlReproduce(unittest.TestCase):
    def test_a_new_task_goes_through_the_whole_chain(self):
        root = tempfile.mkdtemp(prefix="lfd_task_chain_")
        try:
            tasks_dir = os.path.join(root, "tasks")
            os.makedirs(tasks_dir)
            with open(os.path.join(tasks_dir, "hoist.yaml"), "w") as f:
                f.write(HOIST)
            shipped = rospkg.RosPack().get_path("lfd_config") + "/tasks"
            self.assertNotIn("hoist.yaml", os.listdir(shipped))
            env = dict(os.environ, **{tasks.TASKS_PATH_VAR: tasks_dir})
            out = os.path.join(root, "run")
            pipeline = os.path.join(rospkg.RosPack().get_path("lfd_launch"), "scripts",
                                    "pipeline.py")
            run = subprocess.run(["/usr/bin/python3", pipeline, "--out", out, "--datasets",
                                  "sim_hoist", "--stages", "datasets,segment,learn,reproduce",
                                  "--reproduce-modes", "sim"],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 text=True, timeout=840)
            print(run.stdout[-6000:])
            with open(os.path.join(out, "report.json")) as f:
                report = json.load(f)
            learned = report["learning"]["sim_hoist"]
            self.assertEqual([g["segment"] for g in learned["segment_goals"]],
                             ["reach", "hoist"], learned)
            # Learned, not written: the reach ends at the block, the hoist at the goal.
            self.assertIn(learned["segment_goals"][0]["position_frame"],
                          ("object:block", "heading:block"))
            self.assertIn(learned["segment_goals"][1]["position_frame"],
                          ("goal", "goal_heading:block"))
            reproduced = report["reproduction"]["hoist"]
            self.assertEqual(reproduced["goals_total"], 3, reproduced)
            self.assertGreaterEqual(reproduced["successes"], 3,
                                    json.dumps(reproduced["goals"], indent=1)[:3000])
            self.assertEqual(run.returncode, 0)
        finally:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "task_from_yaml_reproduce", TaskFromYamlReproduce)
