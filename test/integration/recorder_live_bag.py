#!/usr/bin/python3
"""rostest (recorder_live_bag.test): a recorder never touches another recorder's live bag, and
refuses bag paths with ".." or outside its allowed_roots, relative ones, and overlong strings."""
import os
import unittest

import rosbag
import rospy
import rostest
from lfd_msgs.msg import DemoMetadata
from lfd_msgs.srv import StartRecording, StopRecording


class RecorderLiveBag(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("recorder_live_bag_test")
        cls.dir = rospy.get_param("recorder_live_bag/output_dir")
        for name in ("recorder_a", "recorder_b"):
            rospy.wait_for_service("/%s/start" % name, timeout=30.0)

    def start(self, recorder, path):
        meta = DemoMetadata(task="live", extra_json="{}")
        meta.header.stamp = rospy.Time.now()
        start = rospy.ServiceProxy("/%s/start" % recorder, StartRecording)
        return start(bag_path=path, metadata=meta)

    def stop(self, recorder):
        return rospy.ServiceProxy("/%s/stop" % recorder, StopRecording)()

    def test_1_a_refused_start_leaves_a_live_bag_alone(self):
        bag = os.path.join(self.dir, "a.bag")
        res = self.start("recorder_a", bag)
        self.assertTrue(res.success, res.message)
        self.assertTrue(os.path.exists(bag + ".active"))
        refused = self.start("recorder_b", bag)  # the same bag, while recorder_a writes it
        self.assertFalse(refused.success)
        self.assertIn("another recorder is recording it", refused.message)
        self.assertTrue(os.path.exists(bag + ".active"), "the live recording was moved away")
        self.assertFalse(os.path.exists(bag + ".crashed"))
        other = self.start("recorder_b", os.path.join(self.dir, "b.bag"))  # same folder, its own
        self.assertTrue(other.success, other.message)
        self.assertNotIn("crashed", other.message)
        self.assertTrue(os.path.exists(bag + ".active"))
        self.assertTrue(self.stop("recorder_b").success)
        stop = self.stop("recorder_a")
        self.assertTrue(stop.success, stop.message)
        self.assertTrue(os.path.isfile(bag), "a.bag did not appear at its stop")
        self.assertFalse(os.path.exists(bag + ".active"))
        with rosbag.Bag(bag) as b:
            self.assertEqual(next(b.read_messages()).topic, "/lfd/metadata")

    def test_2_a_crashed_bag_of_the_same_path_is_still_recovered(self):
        bag = os.path.join(self.dir, "crashed.bag")
        with open(bag + ".active", "w") as f:  # what a killed recorder leaves: no lock on it
            f.write("only copy")
        res = self.start("recorder_b", bag)
        self.assertIn("crashed recording kept", res.message)
        with open(bag + ".crashed") as f:
            self.assertEqual(f.read(), "only copy")
        if res.success:
            self.assertTrue(self.stop("recorder_b").success)

    def test_3_paths_outside_the_roots_or_with_dotdot_are_refused(self):
        for path, why in ((os.path.join(self.dir, "sub", "..", "up.bag"), "'..'"),
                          ("/var/lib/lfd_recorder_live_bag/x.bag", "allowed_roots")):
            res = self.start("recorder_b", path)
            self.assertFalse(res.success, path)
            self.assertIn(why, res.message)
            self.assertFalse(os.path.exists(path + ".active"))
        self.assertFalse(os.path.exists("/var/lib/lfd_recorder_live_bag"))

    def test_4_relative_paths_are_refused_naming_the_field(self):
        """Regression: a service request path must be absolute."""
        res = self.start("recorder_b", "relative.bag")
        self.assertFalse(res.success)
        self.assertIn("bag_path: path 'relative.bag' is relative", res.message)

    def test_5_overlong_strings_are_refused_naming_the_field(self):
        """Regression: every request string is within ~limits/max_request_string_bytes (the error
        quotes it short)."""
        long_path = os.path.join(self.dir, "x" * 300000 + ".bag")
        res = self.start("recorder_b", long_path)
        self.assertFalse(res.success)
        self.assertIn("bag_path: a string of %d bytes, over the limit of 262207 "
                      "(~limits/max_request_string_bytes)" % len(long_path), res.message)
        self.assertLess(len(res.message), 500)
        meta = DemoMetadata(task="t" * 300000, extra_json="{}")
        meta.header.stamp = rospy.Time.now()
        res = rospy.ServiceProxy("/recorder_b/start", StartRecording)(
            bag_path=os.path.join(self.dir, "long_task.bag"), metadata=meta)
        self.assertFalse(res.success)
        self.assertIn("metadata.task: a string of 300000 bytes", res.message)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "long_task.bag.active")))


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "recorder_live_bag", RecorderLiveBag)
