#!/usr/bin/python3
"""rostest (executor_clock_reset.test): the executor takes new goals at once after sim time goes
back (a simulator restart), and says so in its log. The test is the clock: it publishes /clock
from a thread, on wall time, so every wait here is in wall time (rospy's own sleeps raise when
sim time goes back)."""
import threading
import time
import unittest

import actionlib
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from lfd_msgs.msg import ExecuteTaskAction, ExecuteTaskGoal
from rosgraph_msgs.msg import Clock

TERMINAL = (GoalStatus.SUCCEEDED, GoalStatus.ABORTED, GoalStatus.REJECTED, GoalStatus.RECALLED,
            GoalStatus.PREEMPTED)


class SimClock(object):
    """/clock at 100 Hz of wall time, running at real time from `start`; set() jumps it."""

    def __init__(self, start):
        self.pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.now, self.lock, self.running = float(start), threading.Lock(), True
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def set(self, t):
        with self.lock:
            self.now = float(t)

    def run(self):
        while self.running:
            with self.lock:
                self.now += 0.01
                t = self.now
            self.pub.publish(Clock(clock=rospy.Time.from_sec(t)))
            time.sleep(0.01)


class ExecutorClockReset(unittest.TestCase):
    def wait_until(self, condition, timeout, what):
        deadline = time.time() + timeout
        while not condition():
            self.assertLess(time.time(), deadline, what)
            time.sleep(0.05)

    def answer(self, client):
        """Sends a goal with no library and waits (wall time) until it ends: (state, error)."""
        client.send_goal(ExecuteTaskGoal(library="", dry_run=True))
        # The status and the result travel on separate topics: a terminal status may come first.
        self.wait_until(lambda: client.get_state() in TERMINAL and client.get_result() is not None,
                        10.0, "the goal did not end with a result")
        result = client.get_result()
        return client.get_state(), result.error if result else ""

    def test_goals_are_taken_at_once_after_sim_time_went_back(self):
        rospy.init_node("executor_clock_reset_test")
        clock = SimClock(100.0)
        try:
            client = actionlib.SimpleActionClient("/executor/execute", ExecuteTaskAction)
            self.wait_until(lambda: client.wait_for_server(rospy.Duration(0.5)), 30.0,
                            "no /executor/execute server")
            state, error = self.answer(client)
            self.assertEqual(state, GoalStatus.ABORTED, error)
            self.assertIn("library is empty", error)
            clock.set(1.0)  # the simulator restarted
            time.sleep(1.0)  # wall: the executor sees the clock go back
            for _ in range(3):  # every goal, not only the first after the reset
                state, error = self.answer(client)
                self.assertEqual(state, GoalStatus.ABORTED,
                                 "state %d, error '%s': a goal stamped on the new clock was not "
                                 "taken" % (state, error))
                self.assertIn("library is empty", error)
        finally:
            clock.running = False
            clock.thread.join()


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "executor_clock_reset", ExecutorClockReset)
