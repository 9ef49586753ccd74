#!/usr/bin/python3
"""rostest (datasets_one_launch.test): generate_datasets.py records the datasets of a worker with
one demonstrate.launch: teleop_grasp then sim_grasp (one demo each) in one simulation. The bridge
starts once; the teleop bag carries the teleop noise profile's touch and joint noise
(config/bridge.yaml noise_profiles) and the sim bag none, although it was recorded after the teleop
one; and the sim demo lasts exactly what a launch of its own records (same seed, same demo)."""
import glob
import json
import os
import re
import shutil
import subprocess
import unittest

import numpy as np
import rosbag
import rospkg
import rospy
import rostest

SCRIPTS = os.path.join(rospkg.RosPack().get_path("lfd_sim_bridge"), "scripts")
LEAD_IN_S = 0.25  # the demonstrator holds still for lead_in (0.3 s) after the bag starts


def generate(out, datasets):
    gen = subprocess.run(["/usr/bin/python3", os.path.join(SCRIPTS, "generate_datasets.py"),
                          "--out", out, "--datasets", datasets, "--demos", "1"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=300)
    print(gen.stdout)
    return gen


def the_bag(out, name):
    found = sorted(glob.glob(os.path.join(out, name, "*.bag")))
    assert len(found) == 1, "%s: %s" % (name, found)
    return found[0]


def at_rest(bag):
    """The mode, duration, and the touch values and joint positions of the lead-in (robot still,
    nothing touched): exact readings there are constant, noisy ones scatter."""
    with rosbag.Bag(bag) as b:
        meta = next(b.read_messages(topics=["/lfd/metadata"])).message
        start = meta.header.stamp.to_sec()
        touch, joints = [], []
        for topic, msg, _ in b.read_messages(topics=["/touch", "/joint_states"]):
            if msg.header.stamp.to_sec() > start + LEAD_IN_S:
                continue
            (touch if topic == "/touch" else joints).append(list(msg.values if topic == "/touch"
                                                                 else msg.position))
        duration = b.get_end_time() - b.get_start_time()
    return meta.mode, duration, np.array(touch), np.array(joints)


class DatasetsOneLaunch(unittest.TestCase):
    def test_two_modes_one_launch(self):
        rospy.init_node("datasets_one_launch_test", anonymous=True)
        out = rospy.get_param("datasets_one_launch/output_dir")
        try:
            gen = generate(out, "teleop_grasp,sim_grasp")
            self.assertEqual(gen.returncode, 0, gen.stdout)
            self.assertIn("one launch for teleop_grasp+sim_grasp", gen.stdout)
            logs = "".join(open(os.path.join(out, "logs", n + ".log")).read()
                           for n in ("teleop_grasp", "sim_grasp"))
            # The generator's own lines say why it launched again, when it did.
            said = "\n".join(line for line in gen.stdout.splitlines()
                             if line.startswith("[datasets]"))
            self.assertEqual(len(re.findall(r"process\[bridge-\d+\]: started", logs)), 1,
                             said + "\n" + logs[-3000:])
            self.assertEqual(len(re.findall(r"process\[demonstrator-\d+\]: started", logs)), 1)
            # Each dataset's log holds its own demos.
            sim_log = open(os.path.join(out, "logs", "sim_grasp.log")).read()
            self.assertIn("demonstrator: dataset sim_grasp", sim_log)
            self.assertNotIn("grasp/teleop configuration", sim_log)

            mode, _, touch, joints = at_rest(the_bag(out, "teleop_grasp"))
            self.assertEqual(mode, "teleop")
            self.assertGreater(len(touch), 20)
            self.assertGreater(touch.max(), 0.5)  # 0.8 N noise, clipped at 0
            self.assertGreater(np.diff(joints, axis=0).std(), 1e-3)  # 2 mrad noise
            mode, sim_duration, touch, joints = at_rest(the_bag(out, "sim_grasp"))
            self.assertEqual(mode, "sim")
            self.assertGreater(len(touch), 20)
            self.assertLess(touch.max(), 0.05)
            self.assertLess(np.diff(joints, axis=0).std(), 1e-4)

            # The same dataset alone, in a launch of its own: the same demo.
            alone = os.path.join(out, "alone")
            self.assertEqual(generate(alone, "sim_grasp").returncode, 0)
            _, alone_duration, _, _ = at_rest(the_bag(alone, "sim_grasp"))
            self.assertAlmostEqual(sim_duration, alone_duration, delta=0.006)  # one sensor period
            with rosbag.Bag(the_bag(alone, "sim_grasp")) as b:
                alone_meta = json.loads(
                    next(b.read_messages(topics=["/lfd/metadata"])).message.extra_json)
            with rosbag.Bag(the_bag(out, "sim_grasp")) as b:
                meta = json.loads(
                    next(b.read_messages(topics=["/lfd/metadata"])).message.extra_json)
            self.assertEqual((meta["speed"], meta["planned_duration"]),
                             (alone_meta["speed"], alone_meta["planned_duration"]))
        finally:
            shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "datasets_one_launch", DatasetsOneLaunch)
