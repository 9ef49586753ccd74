#!/usr/bin/python3
"""rostest: the recorder writes every configured topic at its configured rate (+-10 %, no gap over
two periods), the metadata first; a recorder interrupted by SIGINT still closes its bag; and a
recorder that never received a message (the sim paused) records every topic from a bag's start."""
import os
import signal
import subprocess
import time
import unittest

import rosbag
import rospy
import rostest
import yaml
from lfd_msgs.msg import DemoMetadata
from lfd_msgs.srv import StartRecording, StopRecording
from std_srvs.srv import SetBool


def topic_stamps(bag, topic):
    return [t.to_sec() for _, _, t in bag.read_messages(topics=[topic])]


class RecorderTopics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("recorder_test")
        cls.output_dir = rospy.get_param("recorder_test/output_dir")
        with open(rospy.get_param("recorder_test/recorder_config")) as f:
            cls.config = yaml.safe_load(f)
        # The recorder adds the robot's sensor topics, the rows of its robot file's sensor table.
        cls.robot_file = rospy.get_param("/recorder/robot_file")
        with open(cls.robot_file) as f:
            rows = yaml.safe_load(f)["sensors"]
        cls.topics = cls.config["topics"] + [{"name": r["topic"], "rate": cls.config["sensor_rate"]}
                                             for r in rows]

    def wait_for_file(self, path, timeout):
        deadline = time.time() + timeout
        while not os.path.exists(path):
            self.assertLess(time.time(), deadline, "%s did not appear in %.0f s" % (path, timeout))
            time.sleep(0.2)

    def spawn_recorder(self, name, **params):
        """A second recorder node, `name`, with the shipped topics and services under /<name>/."""
        rospy.set_param("/%s/topics" % name, self.config["topics"])
        rospy.set_param("/%s/robot_file" % name, self.robot_file)
        rospy.set_param("/%s/sensor_rate" % name, self.config["sensor_rate"])
        for key, value in params.items():
            rospy.set_param("/%s/%s" % (name, key), value)
        return subprocess.Popen(["rosrun", "lfd_sim_bridge", "recorder_node", "__name:=" + name,
                                 "/recorder/start:=/%s/start" % name,
                                 "/recorder/stop:=/%s/stop" % name])

    def test_1_demo_bag_has_every_topic_at_its_rate(self):
        bag_path = os.path.join(self.output_dir, "push_sim_00.bag")
        self.wait_for_file(bag_path, 180.0)
        self.assertFalse(os.path.exists(bag_path + ".active"))
        with rosbag.Bag(bag_path) as bag:
            first = next(bag.read_messages())
            self.assertEqual(first.topic, "/lfd/metadata")
            self.assertEqual(first.message.task, "push")
            self.assertEqual(len(topic_stamps(bag, "/lfd/metadata")), 1)
            start, end = bag.get_start_time(), bag.get_end_time()
            self.assertAlmostEqual(start, first.message.header.stamp.to_sec(), places=6)
            self.assertGreater(end - start, 3.0)
            for spec in self.topics:
                name, rate = spec["name"], float(spec.get("rate", 0.0))
                stamps = topic_stamps(bag, name)
                # An event-driven topic (rate 0, e.g. the latched /tf_static) may come once.
                self.assertGreaterEqual(len(stamps), 1 if rate <= 0.0 else 2,
                                        "%s missing from the bag" % name)
                if rate <= 0.0:
                    continue
                period = 1.0 / rate
                measured = (len(stamps) - 1) / (stamps[-1] - stamps[0])
                self.assertAlmostEqual(
                    measured / rate, 1.0, delta=0.10,
                    msg="%s at %.1f Hz, configured %.1f Hz" % (name, measured, rate))
                gaps = [b - a for a, b in zip(stamps, stamps[1:])]
                self.assertLessEqual(max(gaps), 2.0 * period + 1e-6,
                                     "%s has a gap of %.3f s" % (name, max(gaps)))
                # The topic covers the whole demonstration, from its start to its end.
                self.assertLessEqual(stamps[0] - start, 2.0 * period + 1e-6, name)
                self.assertLessEqual(end - stamps[-1], 2.0 * period + 1e-6, name)

    def test_2_sigint_closes_the_bag(self):
        proc = self.spawn_recorder("recorder_sigint")
        try:
            rospy.wait_for_service("/recorder_sigint/start", timeout=30.0)
            time.sleep(0.5)  # subscriptions connect
            bag_path = os.path.join(self.output_dir, "sigint", "interrupted.bag")
            meta = DemoMetadata(task="grasp", configuration=3, mode="sim", speed=1.0,
                                extra_json="{}")
            meta.header.stamp = rospy.Time.now()
            start = rospy.ServiceProxy("/recorder_sigint/start", StartRecording)
            response = start(bag_path=bag_path, metadata=meta)
            # The recorder subscribes before it answers: it records from here at the latest.
            # (The metadata stamp is earlier by however long the call took; the sim may run
            # several times faster than the wall clock while a loaded CI machine answers.)
            recording_by = rospy.Time.now().to_sec()
            self.assertTrue(response.success, response.message)
            rospy.sleep(1.0)  # sim time
            # Freeze the sim and let every message in flight reach the recorder, so the signal
            # lands at a known point: all that was received must then be in the bag.
            rospy.wait_for_service("/bridge/pause", timeout=10.0)
            self.assertTrue(rospy.ServiceProxy("/bridge/pause", SetBool)(True).success)
            time.sleep(1.0)  # wall: delivery and the recorder's callback queue
            interrupted_at = rospy.Time.now().to_sec()
            proc.send_signal(signal.SIGINT)
            self.assertEqual(proc.wait(timeout=30.0), 0)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        self.assertTrue(os.path.exists(bag_path), "the interrupted bag was not renamed")
        self.assertFalse(os.path.exists(bag_path + ".active"))
        with rosbag.Bag(bag_path) as bag:  # readable: the index was written on close
            first = next(bag.read_messages())
            self.assertEqual(first.topic, "/lfd/metadata")
            self.assertEqual(first.message.configuration, 3)
            joints = topic_stamps(bag, "/joint_states")
            # Everything received before the signal is in the bag, up to the frozen sim time
            # (two publishing periods of slack), and at the configured rate.
            rate = next(float(t["rate"]) for t in self.topics if t["name"] == "/joint_states")
            self.assertGreaterEqual(joints[-1], interrupted_at - 2.0 / rate - 1e-3)
            self.assertLessEqual(joints[0], recording_by + 2.0 / rate + 1e-3)
            self.assertGreaterEqual(len(joints), 0.9 * rate * (interrupted_at - recording_by))

    def test_3_paused_sim_every_topic_from_the_start(self):
        # roscpp counts a publisher before the publisher has taken the connection; whatever it
        # sends in between is lost (on CI, four topics joined a bag 7.5 s late). A recorder started
        # while the sim is paused has heard nothing, so only the publishers' own lists of their
        # links tell it when it may start: it must neither start blind nor wait out its timeout.
        rospy.wait_for_service("/bridge/pause", timeout=10.0)
        pause = rospy.ServiceProxy("/bridge/pause", SetBool)
        self.assertTrue(pause(True).success)
        proc = self.spawn_recorder("recorder_paused", connect_timeout=30.0)
        bag_path = os.path.join(self.output_dir, "paused", "paused.bag")
        try:
            rospy.wait_for_service("/recorder_paused/start", timeout=60.0)
            meta = DemoMetadata(task="push", configuration=1, mode="sim", speed=1.0,
                                extra_json="{}")
            meta.header.stamp = rospy.Time.now()
            called = time.time()
            response = rospy.ServiceProxy("/recorder_paused/start", StartRecording)(
                bag_path=bag_path, metadata=meta)
            answered_in = time.time() - called
            self.assertTrue(response.success, response.message)
            self.assertLess(answered_in, 15.0, "the start waited out its 30 s connect_timeout")
            self.assertTrue(pause(False).success)
            rospy.sleep(1.0)  # sim time
            stop = rospy.ServiceProxy("/recorder_paused/stop", StopRecording)()
            self.assertTrue(stop.success, stop.message)
        finally:
            pause(False)
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(timeout=30.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        start = meta.header.stamp.to_sec()
        with rosbag.Bag(bag_path) as bag:
            for spec in self.topics:
                rate = float(spec.get("rate", 0.0))
                if rate <= 0.0 or spec["name"] == "/lfd/phase":  # the demonstrator's, not running
                    continue
                stamps = topic_stamps(bag, spec["name"])
                self.assertTrue(stamps, "%s missing" % spec["name"])
                self.assertLessEqual(stamps[0] - start, 2.0 / rate + 1e-6,
                                     "%s joined %.3f s late" % (spec["name"], stamps[0] - start))


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "recorder_topics", RecorderTopics)
