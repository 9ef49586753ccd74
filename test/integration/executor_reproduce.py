#!/usr/bin/python3
"""rostest (executor_reproduce.test): learn from a freshly recorded tiny grasp dataset and reproduce
an unseen goal in sim; error paths keep the executor alive."""
import glob
import math
import os
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion
from lfd_msgs.msg import DemoSegmentation
from lfd_msgs.srv import ExecuteTask, LearnSkills, ResetSim, SetScene
from lfd_tools import bags as lfd_bags
from lfd_tools import config as lfd_config
from lfd_tools import judge



def pose(e):
    return Pose(position=Point(*e[:3]),
                orientation=Quaternion(w=math.cos(e[3] / 2), x=0, y=0, z=math.sin(e[3] / 2)))


class ExecutorReproduce(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("executor_test", anonymous=True)
        cls.out = rospy.get_param("executor_test/output_dir")
        cls.tasks = lfd_config.load_tasks()
        for name in ("/executor/execute", "/learner/learn", "/bridge/reset", "/bridge/set_scene"):
            rospy.wait_for_service(name, timeout=120)
        cls.execute = rospy.ServiceProxy("/executor/execute", ExecuteTask)
        cls.learn = rospy.ServiceProxy("/learner/learn", LearnSkills)
        cls.reset = rospy.ServiceProxy("/bridge/reset", ResetSim)
        cls.scene = rospy.ServiceProxy("/bridge/set_scene", SetScene)
        summary = os.path.join(cls.out, "demonstrator_summary_grasp_sim.yaml")
        deadline = time.time() + 300
        while not os.path.exists(summary):
            assert time.time() < deadline, "the demonstrator did not finish the dataset"
            time.sleep(1)
        time.sleep(1)
        bags = sorted(glob.glob(os.path.join(cls.out, "*.bag")))
        assert len(bags) == 4, bags
        cls.library = os.path.join(cls.out, "grasp.json")
        evaluation = lfd_config.load_evaluation()
        expected = lfd_config.expected_transitions(evaluation, "grasp")
        segs = [DemoSegmentation(source=b, changepoint_times=lfd_bags.ground_truth_changepoints(b, expected))
                for b in bags]
        res = cls.learn(task="grasp", output_path=cls.library, segmentations=segs,
                        segment_names=lfd_config.segment_names(evaluation, "grasp"))
        assert res.success, res.error

    def setup_scene(self, entry):
        self.assertTrue(self.reset(joint_names=[], positions=[], reset_objects=True).success)
        park = self.tasks["park"]["box"]
        self.assertTrue(self.scene(object_names=["stick", "box"],
                                   poses=[pose(entry["stick"]), pose(park)]).success)
        end = rospy.Time.now() + rospy.Duration(0.3)
        while rospy.Time.now() < end:
            time.sleep(0.01)

    def test_1_errors_keep_the_node_alive(self):
        entry = self.tasks["grasp"]["unseen"]["sim"][4]
        bad = os.path.join(self.out, "broken.json")
        with open(bad, "w") as f:
            f.write('{"format": "lfd_skill_library", "version": 1, "segments": [')
        r = self.execute(library=bad, object_pose=pose(entry["stick"]), goal=pose(entry["goal"]))
        self.assertFalse(r.success)
        self.assertIn("broken.json", r.error)
        far = list(entry["goal"])
        far[0] = 1.6  # 1.6 m in front of the robot
        r = self.execute(library=self.library, object_pose=pose(entry["stick"]), goal=pose(far))
        self.assertFalse(r.success)
        self.assertIn("unreachable", r.error)
        self.assertEqual(r.execution_time, 0.0)  # refused before moving
        r = self.execute(library=self.library, object_pose=Pose(position=Point(float("nan"), 0, 0)),
                         goal=pose(entry["goal"]))
        self.assertFalse(r.success)
        # Busy: a second request during a (slowed) execution is refused, then cancel stops it.
        from std_srvs.srv import Trigger
        self.setup_scene(entry)
        results = {}
        t = threading.Thread(target=lambda: results.setdefault("first", self.execute(
            library=self.library, object_pose=pose(entry["stick"]), goal=pose(entry["goal"]),
            duration_scale=3.0)))
        t.start()
        from std_msgs.msg import Float64
        rospy.wait_for_message("/executor/progress", Float64, timeout=120)  # streaming now
        r = self.execute(library=self.library, object_pose=pose(entry["stick"]),
                         goal=pose(entry["goal"]), dry_run=True)
        self.assertFalse(r.success)
        self.assertIn("busy", r.error)
        self.assertTrue(rospy.ServiceProxy("/executor/cancel", Trigger)().success)
        t.join(60)
        self.assertIn("cancelled", results["first"].error)

    def test_2_reproduces_an_unseen_goal(self):
        entry = self.tasks["grasp"]["unseen"]["sim"][4]  # id 104, never demonstrated
        self.setup_scene(entry)
        r = self.execute(library=self.library, object_pose=pose(entry["stick"]),
                         goal=pose(entry["goal"]))
        self.assertTrue(r.success, r.error)
        self.assertEqual(list(r.segment_names), ["approach", "move"])
        self.assertEqual(len(r.segment_durations), 2)
        self.assertLess(r.final_position_error, 0.01)
        self.assertGreater(r.execution_time, 0.9 * r.planned_duration)
        end = rospy.Time.now() + rospy.Duration(1.0)
        while rospy.Time.now() < end:
            time.sleep(0.01)
        stick = rospy.wait_for_message("/objects/stick/pose", PoseStamped, timeout=10).pose
        p = stick.position
        outcome = judge.physical_outcome(lfd_config.criteria_of(lfd_config.load_evaluation(), "grasp"),
                                         (p.x, p.y, p.z), entry["goal"], self.tasks["table_top"])
        self.assertTrue(outcome["success"], outcome["reason"])


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "executor_reproduce", ExecutorReproduce)
