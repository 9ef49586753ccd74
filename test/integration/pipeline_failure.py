#!/usr/bin/python3
"""rostest (pipeline_failure.test): a failing stage is reported and leaves nothing running."""
import contextlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
import uuid

import rospkg
import rostest
from lfd_tools import config, processes

PIPELINE = os.path.join(rospkg.RosPack().get_path("lfd_launch"), "scripts", "pipeline.py")
TIMEOUT = 120  # s for the pipeline to fail and clean up


def processes_with(marker):
    """(pid, command) of every process whose environment holds `marker`."""
    found = []
    for pid in processes.processes_with(marker.encode()):
        with contextlib.suppress(OSError):
            with open("/proc/%d/cmdline" % pid, "rb") as f:
                found.append((pid, f.read().replace(b"\0", b" ").decode(errors="replace")))
    return found


def run_failing_pipeline(out, env_changes):
    """pipeline.py --stages segment on `out` (its bag is not a bag); returns (status, log,
    processes left running that carry a marker set here, report.json, report.md)."""
    marker = uuid.uuid4().hex
    env = dict(os.environ, LFD_PIPELINE_FAILURE_TEST=marker, **env_changes)
    proc = subprocess.Popen(["/usr/bin/python3", PIPELINE, "--out", out, "--stages", "segment",
                             "--datasets", "sim_grasp"], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, universal_newlines=True,
                            start_new_session=True)
    try:
        log, _ = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        log, _ = proc.communicate()
    print(log)
    time.sleep(1.0)  # a process killed a moment ago may still be exiting
    left = processes_with("LFD_PIPELINE_FAILURE_TEST=" + marker)
    for pid, _ in left:  # never leave them to the next test
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    with open(os.path.join(out, "report.json")) as f:
        report = json.load(f)
    with open(os.path.join(out, "report.md")) as f:
        report_md = f.read()
    return proc.returncode, log, left, report, report_md


class FailingStage:
    """Shared checks; a subclass says how the stage's tool fails (ENV) and what it says (SAYS)."""
    ENV = {}
    SAYS = ""

    @classmethod
    def setUpClass(cls):
        cls.out = tempfile.mkdtemp(prefix="lfd_pipeline_failure_")
        os.makedirs(os.path.join(cls.out, "datasets", "sim_grasp"))
        with open(os.path.join(cls.out, "datasets", "sim_grasp", "broken.bag"), "w") as f:
            f.write("this is not a rosbag\n")
        cls.status, cls.log, cls.left, cls.report, cls.report_md = run_failing_pipeline(
            cls.out, cls.ENV)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_exits_non_zero(self):
        self.assertEqual(self.status, 1, self.log[-3000:])

    def test_error_is_in_the_report(self):
        problems = [p for p in self.report["problems"] if p.startswith("stage segment failed")]
        self.assertEqual(len(problems), 1, self.report["problems"])
        self.assertIn("segment", self.report["stage_errors"])
        self.assertIn(self.SAYS, problems[0])  # the tool's own last words, not only its status
        self.assertIn("## Problems", self.report_md)
        self.assertIn(problems[0], self.report_md)

    def test_nothing_left_running(self):
        self.assertEqual(self.left, [], "still running after the pipeline returned")


class ClientDiesAtOnce(FailingStage, unittest.TestCase):
    """The fresh-machine failure: the evaluation client cannot import its messages and dies while
    roslaunch is still starting the segmentation node. Only lfd_tools (the pipeline's own package,
    from its source folder) is importable: no message package."""
    ENV = {"PYTHONPATH": os.path.join(rospkg.RosPack().get_path("lfd_tools"), "src")}
    SAYS = "ModuleNotFoundError: No module named 'lfd_msgs'"


class ClientFailsOnData(FailingStage, unittest.TestCase):
    """The node is up and answering; the client dies on a bag that is not one."""
    SAYS = "does not appear to be a bag file"


class StageCleanup(unittest.TestCase):
    """kill_tagged (lfd_tools.processes, the pipeline's stage cleanup) ends what a stage started
    even when it left its parent's session and outlived it (as roslaunch's nodes do when roslaunch
    is killed): a process group is not enough."""

    def test_orphan_in_its_own_session_is_killed(self):
        tag = "%d:cleanup_test" % os.getpid()
        env = dict(os.environ, **{processes.TAG_VAR: tag})
        # a child that starts a grandchild in a new session, then exits: the grandchild is orphaned
        subprocess.run(["/usr/bin/python3", "-c",
                        "import subprocess; subprocess.Popen(['sleep', '300'],"
                        " start_new_session=True)"], env=env, check=True)
        time.sleep(0.5)
        self.assertEqual(len(processes.tagged_processes(tag)), 1)
        self.assertEqual(processes.kill_tagged(tag), ["sleep"])
        self.assertEqual(processes.tagged_processes(tag), [])


class RunRoots(unittest.TestCase):
    """The folders a run's services may use (config.run_roots): the output folder by its path and
    by what it resolves to, and datasets recorded elsewhere and linked in, whole or one by one
    (the services resolve links, so a linked dataset was refused as outside the run)."""

    def test_linked_output_folder_and_datasets_are_roots(self):
        base = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, base)
        for d in ("real_out", "elsewhere/all", "elsewhere/one", "unrelated"):
            os.makedirs(os.path.join(base, d))
        out = os.path.join(base, "out")
        os.symlink(os.path.join(base, "real_out"), out)
        self.assertEqual(config.run_roots(out), [out, os.path.join(base, "real_out")])
        os.symlink(os.path.join(base, "elsewhere", "all"), os.path.join(out, "datasets"))
        os.symlink(os.path.join(base, "elsewhere", "one"),
                   os.path.join(base, "elsewhere", "all", "sim_x"))
        roots = config.run_roots(out)
        self.assertIn(os.path.join(base, "elsewhere", "all"), roots)
        self.assertIn(os.path.join(base, "elsewhere", "one"), roots)
        self.assertNotIn(os.path.join(base, "unrelated"), roots)
        self.assertEqual(len(roots), len(set(roots)))


def all_tests():
    return unittest.TestSuite([unittest.defaultTestLoader.loadTestsFromTestCase(c)
                               for c in (ClientDiesAtOnce, ClientFailsOnData,
                                         StageCleanup, RunRoots)])


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "pipeline_failure", "__main__.all_tests")
