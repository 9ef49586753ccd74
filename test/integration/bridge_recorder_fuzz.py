#!/usr/bin/python3
"""rostest: the bridge and the recorder on random and extreme inputs. Every answer is a
clear error or a sane result, the nodes stay up, and nothing outside the request changes.
Seeded (12), bounded iterations: 200 set_scene requests, 40 trajectories, 30 recorder starts."""
import math
import os
import random
import shutil
import tempfile
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Pose, PoseStamped
from lfd_msgs.msg import DemoMetadata
from lfd_msgs.srv import (ResetSim, SetScene, StartRecording, StepSim, StopRecording)
from sensor_msgs.msg import JointState
from std_srvs.srv import SetBool
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

ELBOW_LIMITS = (-2.5, 0.0)  # URDF R_ELBOW_P
WORKSPACE = ((-3.0, -3.0, -0.5), (3.0, 3.0, 3.0))  # config/bridge.yaml


def pose(x, y, z, q=(1.0, 0.0, 0.0, 0.0)):
    p = Pose()
    p.position.x, p.position.y, p.position.z = x, y, z
    p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z = q
    return p


class BridgeRecorderFuzz(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("bridge_recorder_fuzz")
        for name in ("/bridge/reset", "/bridge/set_scene", "/bridge/pause", "/bridge/step",
                     "/recorder/start", "/recorder/stop"):
            rospy.wait_for_service(name, timeout=60)
        cls.reset = rospy.ServiceProxy("/bridge/reset", ResetSim)
        cls.scene = rospy.ServiceProxy("/bridge/set_scene", SetScene)
        cls.pause = rospy.ServiceProxy("/bridge/pause", SetBool)
        cls.step = rospy.ServiceProxy("/bridge/step", StepSim)
        cls.start = rospy.ServiceProxy("/recorder/start", StartRecording)
        cls.stop = rospy.ServiceProxy("/recorder/stop", StopRecording)
        cls.trajectory = rospy.Publisher("/joint_trajectory", JointTrajectory, queue_size=100)
        cls.elbow = []
        cls.stick = None
        rospy.Subscriber("/joint_states", JointState, cls.on_joints, queue_size=1000)
        rospy.Subscriber("/objects/stick/pose", PoseStamped, cls.on_stick, queue_size=10)
        cls.dir = tempfile.mkdtemp(prefix="lfd_bridge_fuzz_")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    @classmethod
    def on_joints(cls, msg):
        if "R_ELBOW_P" in msg.name:
            cls.elbow.append(msg.position[msg.name.index("R_ELBOW_P")])

    @classmethod
    def on_stick(cls, msg):
        cls.stick = msg.pose.position

    def bridge_alive(self):
        self.assertTrue(self.reset(joint_names=[], positions=[], reset_objects=True).success)

    def test_1_set_scene_random_poses(self):
        rng = random.Random(12)
        values = [0.5, -0.3, 0.9, 0.0, 2.9, 3.1, 1e11, -1e11, 1e-300, 1e308, float("nan"),
                  float("inf")]
        quats = [(1, 0, 0, 0), (0, 0, 0, 0), (2, 0, 0, 0), (1.005, 0, 0, 0), (0.7071, 0, 0, 0.7071),
                 (float("nan"), 0, 0, 0), (1e308, 1e308, 0, 0)]
        names = ["stick", "box", "table", "", "stick", "x" * 1000]
        for k in range(200):
            n = rng.randrange(0, 4)
            req_names = [rng.choice(names) for _ in range(n)]
            poses = [pose(rng.choice(values), rng.choice(values), rng.choice(values),
                          rng.choice(quats)) for _ in range(n + (1 if rng.random() < 0.1 else 0))]
            res = self.scene(object_names=req_names, poses=poses)
            context = "request %d: %s %s" % (k, req_names, [(p.position.x, p.position.y,
                                                            p.position.z) for p in poses])
            if res.success:
                for p in poses:
                    xyz = (p.position.x, p.position.y, p.position.z)
                    for i in range(3):
                        self.assertTrue(WORKSPACE[0][i] <= xyz[i] <= WORKSPACE[1][i], context)
            else:
                self.assertTrue(res.message, context)
        # The case from the issue: refused, and the bridge keeps running (no reset storm).
        res = self.scene(object_names=["stick"], poses=[pose(1e11, 0.0, 0.9)])
        self.assertFalse(res.success)
        self.assertIn("workspace", res.message)
        self.bridge_alive()
        self.assertTrue(self.scene(object_names=["stick"], poses=[pose(0.5, -0.3, 0.86)]).success)
        deadline = time.time() + 10
        while time.time() < deadline and not (self.stick and abs(self.stick.x - 0.5) < 0.01):
            time.sleep(0.05)
        self.assertIsNotNone(self.stick)
        self.assertAlmostEqual(self.stick.x, 0.5, delta=0.01)

    def test_2_step_is_bounded_and_pause_is_served(self):
        self.assertTrue(self.pause(True).success)
        try:
            for steps in (10001, 1000000, 2**32 - 1):
                t0 = time.time()
                res = self.step(steps)
                self.assertFalse(res.success)
                self.assertIn("max_steps_per_call", res.message)
                # Refused before stepping (a million steps would take minutes); room for load.
                self.assertLess(time.time() - t0, 5.0)
            # The largest allowed step: a concurrent pause is answered within its bounded time.
            thread = threading.Thread(target=lambda: self.step(10000), daemon=True)
            thread.start()
            time.sleep(0.05)
            t0 = time.time()
            self.assertTrue(self.pause(True).success)
            self.assertLess(time.time() - t0, 5.0)
            thread.join(30)
            self.assertTrue(self.step(1).success)
        finally:
            self.pause(False)

    def send(self, names, points):
        msg = JointTrajectory(joint_names=names)
        for t, pos, vel in points:
            msg.points.append(JointTrajectoryPoint(positions=pos, velocities=vel,
                                                   time_from_start=rospy.Duration.from_sec(t)))
        self.trajectory.publish(msg)

    def test_3_trajectory_velocities_stay_within_limits(self):
        deadline = time.time() + 10
        while self.trajectory.get_num_connections() == 0 and time.time() < deadline:
            time.sleep(0.05)
        self.bridge_alive()
        rospy.sleep(0.5)
        q0 = self.elbow[-1]
        del self.elbow[:]
        # The case: 1.7e308 rad/s on a 0.1 rad move swung the elbow between its limits.
        self.send(["R_ELBOW_P"], [(0.5, [q0 + 0.05], [1.7e308]), (1.0, [q0 + 0.1], [-1.7e308])])
        rospy.sleep(2.0)
        self.assertTrue(self.elbow)
        # Clamped to the URDF's 3.5 rad/s, the Hermite segments overshoot by a few tenths; the
        # unclamped ones swung across the whole 2.5 rad range.
        self.assertLess(max(self.elbow) - min(self.elbow), 1.2,
                        "elbow range %.2f..%.2f" % (min(self.elbow), max(self.elbow)))
        rng = random.Random(12)
        values = [0.0, -1.0, 1.0, 1e308, -1e308, float("nan"), float("inf"), 1e-300]
        for _ in range(40):
            n = rng.randrange(0, 4)
            self.send(rng.choice([["R_ELBOW_P"], ["R_ELBOW_P", "R_SHOULDER_Y"], ["NOPE"], []]),
                      [(rng.choice([0.1, 0.5, -1.0, 1e9, 1e-9]),
                        [rng.choice(values) for _ in range(rng.randrange(0, 3))],
                        [rng.choice(values) for _ in range(rng.randrange(0, 3))])
                       for _ in range(n)])
            rospy.sleep(0.02)
        rospy.sleep(1.0)
        for q in self.elbow:
            self.assertTrue(math.isfinite(q))
            self.assertTrue(ELBOW_LIMITS[0] - 0.05 <= q <= ELBOW_LIMITS[1] + 0.05, q)
        self.bridge_alive()

    def test_4_recorder_never_truncates_and_answers_every_start(self):
        os.mkdir(os.path.join(self.dir, "crash"))  # a folder the random starts never scan
        crashed = os.path.join(self.dir, "crash", "crashed.bag")
        with open(crashed + ".active", "w") as f:
            f.write("only copy")
        existing = os.path.join(self.dir, "existing.bag")
        with open(existing, "w") as f:
            f.write("done")
        folder = os.path.join(self.dir, "folder.bag")
        os.mkdir(folder)
        rng = random.Random(12)
        paths = ["", "relative.bag", os.path.join(self.dir, "noext"), existing, folder,
                 os.path.join(self.dir, "x" * 300 + ".bag"), "/proc/lfd.bag",
                 os.path.join(self.dir, "a", "..", "b.bag")]
        for k in range(30):
            res = self.start(bag_path=rng.choice(paths), metadata=DemoMetadata(task="fuzz"))
            if res.success:  # a path it could create: close it again
                self.assertTrue(self.stop().success)
            else:
                self.assertTrue(res.message)
        with open(existing) as f:
            self.assertEqual(f.read(), "done")
        # Starting where a crash left an .active: the crash is kept (renamed .crashed) and
        # reported, never truncated; the new recording then proceeds.
        res = self.start(bag_path=crashed, metadata=DemoMetadata(task="fuzz"))
        self.assertIn("crashed recording kept", res.message)
        with open(crashed + ".crashed") as f:
            self.assertEqual(f.read(), "only copy")
        if res.success:
            rospy.sleep(0.5)
            stop = self.stop()
            self.assertTrue(stop.success, stop.message)
            self.assertTrue(os.path.isfile(crashed))
        self.assertFalse(self.stop().success)  # not recording: a clear answer
        self.bridge_alive()


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "bridge_recorder_fuzz", BridgeRecorderFuzz)
