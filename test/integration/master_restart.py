#!/usr/bin/python3
"""rostest (round two): a node outlives a restart of the ROS master. The test runs its own
roscore on a free port (rostest's master is not used), launches lfd_launch/segment.launch on it (the
segmentation node, respawn="true"), waits for /segmentation/segment, kills roscore, starts another
on the same port, and asks that the service be advertised again within RE_REGISTER_S, by a new
process, with the node's parameters on the new master. Before lfd_ros::MasterWatch the node stayed
up, unknown to the new master, forever. Everything started here is stopped by process group."""
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
import xmlrpc.client

import rosgraph
import rostest
from lfd_tools import master

SERVICE = "/segmentation/segment"
NODE = "/segmentation"
START_S = 60.0       # the first start: roslaunch, the node reading its parameters
RE_REGISTER_S = 20.0  # the node notices (1 s), ends, is respawned (2 s) and registers again


def wait_for(what, predicate, timeout):
    deadline = time.time() + timeout
    while time.time() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError("%s: not within %.0f s" % (what, timeout))


class MasterRestart(unittest.TestCase):
    def setUp(self):
        self.home = tempfile.mkdtemp(prefix="lfd_master_restart_")
        self.port = master.free_port()
        self.uri = master.master_uri(self.port)
        self.env = dict(os.environ, ROS_MASTER_URI=self.uri, ROS_HOME=self.home,
                        ROS_LOG_DIR=os.path.join(self.home, "log"))
        self.launches, self.cores = [], []

    def tearDown(self):
        for proc in self.launches + self.cores:  # the nodes first, while their master answers
            master.stop_group(proc, 20)
        shutil.rmtree(self.home, ignore_errors=True)

    def roscore(self):
        core = master.roscore_on(self.port, self.env)
        self.assertIsNotNone(core, "roscore could not take port %d" % self.port)
        self.cores.append(core)
        probe = rosgraph.Master("/master_restart_test", master_uri=self.uri)
        wait_for("roscore's /run_id", lambda: self.answer(probe.hasParam, "/run_id"), 30)
        return core

    @staticmethod
    def answer(call, *args):
        try:
            return call(*args)
        except (OSError, rosgraph.MasterException, xmlrpc.client.Fault):
            return None

    def provider(self):
        """The pid of the process serving SERVICE on the current master, or None."""
        probe = rosgraph.Master("/master_restart_test", master_uri=self.uri)
        if not self.answer(probe.lookupService, SERVICE):
            return None
        node_api = self.answer(probe.lookupNode, NODE)
        if not node_api:
            return None
        code, _, pid = self.answer(xmlrpc.client.ServerProxy(node_api).getPid,
                                   "/master_restart_test") or (0, 0, 0)
        return pid if code == 1 else None

    def test_the_node_registers_again_with_a_new_master(self):
        core = self.roscore()
        launch = subprocess.Popen(["roslaunch", "--wait", "lfd_launch", "segment.launch",
                                   "output:=log"],
                                  env=self.env, stdout=subprocess.DEVNULL, start_new_session=True)
        self.launches.append(launch)
        first = wait_for("%s on the first master" % SERVICE, self.provider, START_S)

        # A crash of the master: nothing unregisters. rosmaster runs in a session of its own
        # (roslaunch starts each process so), so roscore's group is stopped after it.
        os.kill(rosgraph.Master("/master_restart_test", master_uri=self.uri).getPid(),
                signal.SIGKILL)
        master.stop_group(core, 20)
        self.cores.remove(core)
        wait_for("the old master gone", lambda: not master.port_open(self.port), 10)
        self.roscore()

        second = wait_for("%s on the restarted master" % SERVICE, self.provider, RE_REGISTER_S)
        self.assertNotEqual(first, second, "the same process cannot have registered again")
        self.assertEqual(launch.poll(), None, "roslaunch ended")
        probe = rosgraph.Master("/master_restart_test", master_uri=self.uri)
        self.assertTrue(probe.hasParam(NODE + "/rate"),
                        "the node's parameters are not on the new master")
        with self.assertRaises(ProcessLookupError):
            os.kill(first, 0)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "master_restart", MasterRestart)
