#!/usr/bin/python3
"""rostest: the datasets of every task in the modes of param datasets_test/mode (sim, teleop or
"sim,teleop"; one .test file per mode, so the two halves run side by side) are generated, every
configuration of each (or the first datasets_test/demos), and every demonstration in them succeeds
physically, judged from its bag with its task file's criterion (lfd_tools.judge).
datasets_test/robot (default: the default robot) records them with another robot
(<robot>_description): the bags then carry that robot's sensor frames.
Also: the bags say what the learner and the judge rely on (the metadata's scene block: every object
the task uses at its start, the goal, the articulated joints) and the ground truth names the task
file's phases."""
import glob
import json
import os
import shutil
import subprocess
import unittest

import rosbag
import rospkg
import rospy
import rostest

from lfd_tools import bags as lfd_bags
from lfd_tools import config, tasks

SCRIPTS = os.path.join(rospkg.RosPack().get_path("lfd_sim_bridge"), "scripts")


def metadata(bag):
    with rosbag.Bag(bag) as b:
        return json.loads(next(b.read_messages(topics=["/lfd/metadata"])).message.extra_json)


def sensor_frames(bag):
    """{topic: header.frame_id} of the first message of each sensor table row's topic."""
    rows = {row["topic"] for row in config.load_yaml(config.robot_file())["sensors"]}
    frames = {}
    with rosbag.Bag(bag) as b:
        for topic, msg, _ in b.read_messages(topics=sorted(rows)):
            frames.setdefault(topic, msg.header.frame_id)
    return frames


class DatasetsSucceed(unittest.TestCase):
    def check_dataset(self, out, name, demos, log):
        mode, task = name.split("_", 1)
        scenes = {s["id"]: s for s in tasks.scenes(task, mode)}
        self.assertGreaterEqual(len(scenes), 9 if mode == "sim" else 6, name)
        found = sorted(glob.glob(os.path.join(out, name, "*.bag")))
        expected_bags = min(demos, len(scenes)) if demos > 0 else len(scenes)
        self.assertEqual(len(found), expected_bags, "%s: %d bags\n%s" % (name, len(found), log))
        robot_frames = {row["topic"]: row["frame"]
                        for row in config.load_yaml(config.robot_file())["sensors"]}
        for bag in found:
            self.assertEqual(sensor_frames(bag), robot_frames, "%s: not the robot's sensors" % bag)
            r = lfd_bags.demo_outcome(bag)
            self.assertEqual((r.get("task"), r.get("mode")), (task, mode), bag)
            self.assertTrue(r["success"], "%s: %s" % (bag, r["reason"]))
            scene = metadata(bag)["scene"]
            expected = scenes[r["configuration"]]
            self.assertEqual(sorted(scene["objects"]), sorted(tasks.objects(task)), bag)
            self.assertEqual(sorted(scene["joints"]), sorted(tasks.joints(task)), bag)
            for got, want in [(scene["goal"], expected["goal"])] + [
                    (scene["objects"][o], expected["objects"][o]) for o in tasks.objects(task)]:
                for a, b in zip(got["position"] + got["orientation"],
                                want["position"] + want["orientation"]):
                    self.assertAlmostEqual(a, b, places=5, msg=bag)
            names = [p for p, _ in lfd_bags.phase_transitions(bag)[1]]
            self.assertEqual(names, [p["name"] for p in tasks.phases(task)], bag)

    def test_every_demo_succeeds(self):
        rospy.init_node("datasets_test", anonymous=True)
        out = rospy.get_param("datasets_test/output_dir")
        modes = rospy.get_param("datasets_test/mode").split(",")
        demos = int(rospy.get_param("datasets_test/demos", 0))
        robot = rospy.get_param("datasets_test/robot", "")
        if robot:
            os.environ["LFD_ROBOT"] = robot  # this process's judge and the generator's launch
        names = [n for n in tasks.datasets() if n.split("_", 1)[0] in modes]
        self.assertTrue(names, "no dataset in mode %r" % modes)
        try:
            gen = subprocess.run([os.path.join(SCRIPTS, "generate_datasets.py"), "--out", out,
                                  "--datasets", ",".join(names), "--demos", str(demos)],
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                 timeout=1500)
            print(gen.stdout)
            for name in names:
                with self.subTest(dataset=name):
                    self.check_dataset(out, name, demos, gen.stdout)
            self.assertEqual(gen.returncode, 0, gen.stdout)
        finally:
            shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "datasets_succeed", DatasetsSucceed)
