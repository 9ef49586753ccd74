#!/usr/bin/python3
"""rostest (task_from_yaml.test): a task that exists only as a YAML file, written here at test time
(not among config/tasks), is demonstrated, recorded, judged and segmented with no code change: the
task file goes through generate_datasets.py (the demonstrator interprets its primitives), the bags
are judged with the file's own success criterion, their ground truth carries the file's phase
names, and the segmentation (the master-free `segment` CLI, config/segmentation.yaml) is scored
against the transitions between the file's skills.

The task, `tap`: the closed hand comes down on the box's top until it touches (a guarded move),
presses it for a moment and leaves; the box must not move. Three configurations, short durations."""
import glob
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import rosbag
import rospkg
import rostest
from catkin.find_in_workspaces import find_in_workspaces

from lfd_tools import bags as lfd_bags
from lfd_tools import tasks

TAP = """
description: Tap the box's top with the closed hand; the box stays where it is.
objects: [box]
goal: the box's start (it must not move)
gripper_at_start: closed
phases:
  - name: approach
    steps:
      - {move: {frame: box, position: [0, 0, 0.12], symmetry: 4}, duration: 1.5, label: above}
      - {move: {frame: box, position: [0, 0, 0.03], symmetry: 4}, until_contact: any, duration: 1.2,
         settle: 0.1, label: down}
  - name: press
    steps:
      - {move: {frame: box, position: [0, 0, 0.046], symmetry: 4}, duration: 0.3, label: press}
      - {hold: 1.0}
  - name: leave
    steps:
      - {retreat: [0, 0, 0.02], duration: 0.3, label: lift_off}
      - {retreat: [0, 0, 0.08], duration: 0.8, label: up}
      - {move: {frame: start}, duration: 1.5, label: home}
success:
  - {rule: object_at_goal, object: box, distance: xy, tolerance_m: 0.01}
configurations:
  sim:
    - {id: 0, box: [0.45, -0.40, 0.84, 0.0], goal: [0.45, -0.40, 0.84, 0.0]}
    - {id: 1, box: [0.55, -0.30, 0.84, 0.3], goal: [0.55, -0.30, 0.84, 0.3]}
    - {id: 2, box: [0.48, -0.20, 0.84, -0.2], goal: [0.48, -0.20, 0.84, -0.2]}
  teleop:
    - {id: 0, box: [0.50, -0.30, 0.84, 0.0], goal: [0.50, -0.30, 0.84, 0.0]}
"""


def run(cmd, env, timeout):
    return subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=timeout)


class TaskFromYaml(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp(prefix="lfd_task_yaml_")
        self.tasks_dir = os.path.join(self.root, "tasks")
        os.makedirs(self.tasks_dir)
        with open(os.path.join(self.tasks_dir, "tap.yaml"), "w") as f:
            f.write(TAP)
        self.env = dict(os.environ, **{tasks.TASKS_PATH_VAR: self.tasks_dir})
        os.environ[tasks.TASKS_PATH_VAR] = self.tasks_dir

    def tearDown(self):
        del os.environ[tasks.TASKS_PATH_VAR]
        shutil.rmtree(self.root, ignore_errors=True)

    def test_demonstrate_record_judge_and_segment(self):
        self.assertNotIn("tap", os.listdir(rospkg.RosPack().get_path("lfd_config") + "/tasks"))
        data = os.path.join(self.root, "data")
        scripts = rospkg.RosPack().get_path("lfd_sim_bridge") + "/scripts"
        gen = run(["/usr/bin/python3", scripts + "/generate_datasets.py", "--out", data,
                   "--datasets", "sim_tap", "--tasks-dir", self.tasks_dir], self.env, 400)
        print(gen.stdout)
        self.assertEqual(gen.returncode, 0, gen.stdout)  # recorded, and every demo judged a success
        found = sorted(glob.glob(os.path.join(data, "sim_tap", "*.bag")))
        self.assertEqual(len(found), 3)
        for bag in found:
            r = lfd_bags.demo_outcome(bag)
            self.assertTrue(r["success"], r["reason"])
            self.assertEqual([p for p, _ in lfd_bags.phase_transitions(bag)[1]],
                             ["approach", "press", "leave"])
            with rosbag.Bag(bag) as b:
                meta = json.loads(
                    next(b.read_messages(topics=["/lfd/metadata"])).message.extra_json)
            self.assertEqual(list(meta["scene"]["objects"]), ["box"])

        result = os.path.join(self.root, "segmentation.json")
        found = find_in_workspaces(search_dirs=["libexec"], project="lfd_segmentation",
                                   path="segment")
        self.assertTrue(found, "the lfd_segmentation `segment` CLI is not built")
        cli = found[0]
        ev = run(["/usr/bin/python3",
                  rospkg.RosPack().get_path("lfd_segmentation")
                  + "/scripts/evaluate_segmentation.py",
                  "--cli", cli, "--datasets", data, "--names", "sim_tap", "--methods",
                  "weighted_product", "--out", result], self.env, 120)
        print(ev.stdout)
        self.assertEqual(ev.returncode, 0, ev.stdout)
        with open(result) as f:
            record = json.load(f)["segmentation"]["sim_tap"]
        details = record["results"]["weighted_product"]["details"]
        self.assertEqual(len(details), 3)
        # Scored against the file's two transitions (approach -> press, press -> leave); the tap's
        # touch-down and lift-off are the sensory events, so most demos find both.
        self.assertTrue(all(len(d["windows_s"]) == 2 for d in details))
        self.assertGreaterEqual(record["success_rate"], 2 / 3, json.dumps(record, indent=1)[:2000])


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "task_from_yaml", TaskFromYaml)
