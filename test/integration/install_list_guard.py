#!/usr/bin/python3
"""rostest (install_list_guard.test): the install-list guard fails when a package is left out."""
import os
import subprocess
import tempfile
import unittest

import rospkg
import rostest

ROOT = os.path.dirname(rospkg.RosPack().get_path("lfd_test"))
GUARD = os.path.join(ROOT, "test", "scripts", "check_install_list.py")
LIST = os.path.join(ROOT, ".ci", "apt-packages.txt")


def guard(packages):
    with tempfile.NamedTemporaryFile("w", suffix=".txt") as f:
        f.write("\n".join(packages) + "\n")
        f.flush()
        run = subprocess.run(["/usr/bin/python3", GUARD, "--list", f.name], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)
    print(run.stdout)
    return run.returncode, run.stdout


class InstallListGuard(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(LIST) as f:
            cls.listed = [line.strip() for line in f if line.strip() and not line.startswith("#")]

    def test_the_list_passes(self):
        rc, out = guard(self.listed)
        self.assertEqual(rc, 0, out)

    def test_without_rosbash_rosrun_is_missing(self):
        rc, out = guard([p for p in self.listed if p != "rosbash"])
        self.assertEqual(rc, 1, out)
        line = [x for x in out.splitlines() if x.strip().startswith("MISSING rosrun:")]
        self.assertEqual(len(line), 1, out)
        self.assertIn("rosbash", line[0])
        self.assertIn("lfd_launch/scripts/pipeline.py", line[0])  # the file that needs it

    def test_without_matplotlib_its_imports_are_missing(self):
        rc, out = guard([p for p in self.listed if p != "python3-matplotlib"])
        self.assertEqual(rc, 1, out)
        self.assertRegex(out,
                         r"MISSING matplotlib: .*lfd_segmentation/scripts/plot_segmentation.py")

    def test_without_a_ros_package_its_key_is_missing(self):
        rc, out = guard([p for p in self.listed if p != "ros-robot-state-publisher"])
        self.assertEqual(rc, 1, out)
        self.assertRegex(out, r"MISSING robot_state_publisher: .*lfd_launch/sim.launch")


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "install_list_guard", InstallListGuard)
