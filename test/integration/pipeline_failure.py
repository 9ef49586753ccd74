#!/usr/bin/python3
"""rostest (pipeline_failure.test): a failing stage is reported and leaves nothing running."""
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

PIPELINE = os.path.join(rospkg.RosPack().get_path("lfd_launch"), "scripts", "pipeline.py")
TIMEOUT = 120  # s for the pipeline to fail and clean up


def processes_with(marker):
    """(pid, command) of every process whose environment holds `marker`."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/environ" % entry, "rb") as f:
                if marker.encode() not in f.read():
                    continue
            with open("/proc/%s/cmdline" % entry, "rb") as f:
                found.append((int(entry), f.read().replace(b"\0", b" ").decode(errors="replace")))
        except OSError:
            continue
    return found


class PipelineFailure(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = tempfile.mkdtemp(prefix="lfd_pipeline_failure_")
        os.makedirs(os.path.join(cls.out, "datasets", "sim_grasp"))
        with open(os.path.join(cls.out, "datasets", "sim_grasp", "broken.bag"), "w") as f:
            f.write("this is not a rosbag\n")
        cls.marker = "LFD_PIPELINE_FAILURE_TEST=%s" % uuid.uuid4().hex
        env = dict(os.environ, LFD_PIPELINE_FAILURE_TEST=cls.marker.split("=", 1)[1])
        proc = subprocess.Popen(["/usr/bin/python3", PIPELINE, "--out", cls.out, "--stages", "segment",
                                 "--datasets", "sim_grasp"], env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, universal_newlines=True,
                                start_new_session=True)
        try:
            cls.log, _ = proc.communicate(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            cls.log, _ = proc.communicate()
        print(cls.log)
        cls.status = proc.returncode
        time.sleep(1.0)  # a process killed a moment ago may still be exiting
        cls.left = processes_with(cls.marker)
        for pid, _ in cls.left:  # never leave them to the next test
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        with open(os.path.join(cls.out, "report.json")) as f:
            cls.report = json.load(f)
        with open(os.path.join(cls.out, "report.md")) as f:
            cls.report_md = f.read()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_exits_non_zero(self):
        self.assertEqual(self.status, 1, self.log[-3000:])

    def test_error_is_in_the_report(self):
        problems = [p for p in self.report["problems"] if p.startswith("stage segment failed")]
        self.assertEqual(len(problems), 1, self.report["problems"])
        self.assertIn("segment", self.report["stage_errors"])
        # the tool's own last words (its exception), not only an exit status
        self.assertRegex(problems[0], r"exit \d+\): .*\w")
        self.assertIn("## Problems", self.report_md)
        self.assertIn(problems[0], self.report_md)

    def test_nothing_left_running(self):
        self.assertEqual(self.left, [], "still running after the pipeline returned")


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "pipeline_failure", PipelineFailure)
