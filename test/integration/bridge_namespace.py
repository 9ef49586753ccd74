#!/usr/bin/python3
"""rostest (bridge_namespace.test): the bridge under /robot2 has its topics and services there,
the sensor table's and the robot's state included, and nothing of them at the root."""
import time
import unittest

import rosgraph
import rospy
import rostest
from lfd_msgs.msg import Touch
from lfd_msgs.srv import StepSim
from sensor_msgs.msg import JointState
from std_srvs.srv import SetBool


class BridgeNamespace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("bridge_namespace_test")
        rospy.wait_for_service("/robot2/bridge/step", timeout=60.0)

    def test_topics_and_services_are_in_the_namespace(self):
        pause = rospy.ServiceProxy("/robot2/bridge/pause", SetBool)
        self.assertTrue(pause(True).success)
        received = {}

        def keep(topic):
            return lambda msg: received.setdefault(topic, msg)
        subs = [rospy.Subscriber("/robot2/joint_states", JointState, keep("joints")),
                rospy.Subscriber("/touch", Touch, keep("touch"))]
        deadline = time.time() + 10.0  # wall time: sim time stands still while paused
        while any(s.get_num_connections() == 0 for s in subs) and time.time() < deadline:
            time.sleep(0.1)
        step = rospy.ServiceProxy("/robot2/bridge/step", StepSim)
        for _ in range(20):  # paused: the bridge publishes only as it is stepped
            self.assertTrue(step(10).success)
            if len(received) == 2:
                break
            time.sleep(0.1)
        self.assertGreater(len(received["joints"].name), 10)
        # The sensor table's rows keep the names the robot file gives them (absolute there).
        self.assertEqual(len(received["touch"].names), 2)
        published = {name for name, _ in rosgraph.Master("/test").getPublishedTopics("")}
        for topic in ("/robot2/gripper/state", "/robot2/ee_pose", "/robot2/objects/joint_states"):
            self.assertIn(topic, published)
        for topic in ("/joint_states", "/gripper/state", "/ee_pose"):
            self.assertNotIn(topic, published)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "bridge_namespace", BridgeNamespace)
