#!/usr/bin/python3
"""rostest: all four datasets are generated and every demonstration in them succeeds physically,
judged from its bag (metadata goal vs. final object pose)."""
import glob
import os
import shutil
import subprocess
import unittest

import rospkg
import rospy
import rostest

from lfd_tools import bags as lfd_bags
from lfd_tools import config as lfd_config

SCRIPTS = os.path.join(rospkg.RosPack().get_path("lfd_sim_bridge"), "scripts")


class DatasetsSucceed(unittest.TestCase):
    def test_every_demo_succeeds(self):
        rospy.init_node("datasets_test", anonymous=True)
        out = rospy.get_param("datasets_test/output_dir")
        tasks, evaluation = lfd_config.load_tasks(), lfd_config.load_evaluation()
        try:
            gen = subprocess.run([os.path.join(SCRIPTS, "generate_datasets.py"), "--out", out],
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                 timeout=840)
            print(gen.stdout)
            for name in ("sim_grasp", "sim_push", "teleop_grasp", "teleop_push"):
                mode, task = name.split("_")
                expected = len(tasks[task][mode])
                self.assertGreaterEqual(expected, 9 if task == "grasp" else 6, name)
                bags = sorted(glob.glob(os.path.join(out, name, "*.bag")))
                self.assertEqual(len(bags), expected, "%s: %d bags\n%s" % (name, len(bags), gen.stdout))
                for bag in bags:
                    r = lfd_bags.demo_outcome(bag, evaluation)
                    self.assertEqual(r.get("task"), task, bag)
                    self.assertEqual(r.get("mode"), mode, bag)
                    self.assertTrue(r["success"], "%s: %s" % (bag, r["reason"]))
            self.assertEqual(gen.returncode, 0, gen.stdout)
        finally:
            shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "datasets_succeed", DatasetsSucceed)
