#!/usr/bin/python3
"""rostest: the `snapshot` CLI (lfd_sim_bridge) renders the recorded scene offscreen (OSMesa, no
display) at the end of each segment.

The test writes a synthetic 4 s demonstration bag whose second segment moves the right arm and the
box, runs `snapshot` on it and checks the PNGs: one per segment end, the requested size, the
table's brown, the robot's grey, the box's green and the stick's orange all present, and the box
drawn where the bag put it (its green moves between the two pictures by as much as the box moved),
the files valid compressed 8-bit RGB PNGs. Bad input (missing bag, a time after the bag's end, an
unknown camera) is a clear error.
"""
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np
import rosbag
import rospkg
import rospy
import rostest
from geometry_msgs.msg import PoseStamped
from lfd_msgs.msg import Phase
from PIL import Image
from sensor_msgs.msg import JointState

T0 = 50.0
ARM_JOINTS = ["R_SHOULDER_P", "R_SHOULDER_R", "R_SHOULDER_Y", "R_ELBOW_P", "R_ELBOW_Y",
              "R_WRIST_R", "R_WRIST_Y"]
ARM_FIRST = [-0.38, -0.02, 0.15, -1.06, -0.14, -0.04, 1.29]
ARM_SECOND = [-0.92, -0.37, 0.0, -0.4, -0.25, 0.24, 1.32]
BOX_FIRST = (0.6, -0.35, 0.84)
BOX_SECOND = (0.6, 0.15, 0.84)
STICK = (0.33, -0.5, 0.815)


def urdf_joint_names(urdf_path):
    root = ET.parse(urdf_path).getroot()
    return [j.get("name") for j in root.findall("joint") if j.get("type") != "fixed"]


def pose(stamp, xyz):
    p = PoseStamped()
    p.header.stamp = stamp
    p.header.frame_id = "world"
    p.pose.position.x, p.pose.position.y, p.pose.position.z = xyz
    p.pose.orientation.w = 1.0
    return p


def write_bag(path, names):
    """Segment "reach" on [0, 2) s, "move" on [2, 4] s, 20 Hz."""
    with rosbag.Bag(path, "w") as bag:
        for k in range(81):
            t = 0.05 * k
            stamp = rospy.Time.from_sec(T0 + t)
            second = t >= 2.0
            js = JointState(name=names, position=[0.0] * len(names))
            js.header.stamp = stamp
            for j, v in zip(ARM_JOINTS, ARM_SECOND if second else ARM_FIRST):
                js.position[names.index(j)] = v
            bag.write("/joint_states", js, stamp)
            bag.write("/objects/box/pose", pose(stamp, BOX_SECOND if second else BOX_FIRST), stamp)
            bag.write("/objects/stick/pose", pose(stamp, STICK), stamp)
            phase = Phase(task="push", name="move" if second else "reach", index=int(second))
            phase.header.stamp = stamp
            bag.write("/lfd/phase", phase, stamp)


def colour_masks(rgb):
    r, g, b = (rgb[..., k].astype(int) for k in range(3))
    spread = rgb.max(axis=-1).astype(int) - rgb.min(axis=-1)
    return {
        # table top and legs (0.6 0.45 0.3 / 0.45 0.32 0.2): warm, red > green > blue, dim
        "table": (r > g + 10) & (g > b + 10) & (r - b < 110) & (r > 60) & (r < 230),
        # light and dark greys of the robot's links (the floor is blue, the sky black)
        "robot": (spread < 18) & (r > 60),
        "box": (g > r + 60) & (g > b + 60),  # 0.2 0.7 0.3
        "stick": (r > 150) & (r - b > 120) & (g > 70) & (r > g + 40),  # 0.85 0.55 0.15
    }


class SnapshotRender(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.workdir = tempfile.mkdtemp(prefix="lfd_snapshot_")
        urdf = os.path.join(rospkg.RosPack().get_path("jvrc1_description"), "models",
                            "jvrc1_like.urdf")
        cls.bag = os.path.join(cls.workdir, "push_sim_00.bag")
        write_bag(cls.bag, urdf_joint_names(urdf))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.workdir, ignore_errors=True)

    def snapshot(self, *args):
        return subprocess.run(["rosrun", "lfd_sim_bridge", "snapshot", "--bag", self.bag] +
                              list(args), capture_output=True, text=True, timeout=120)

    def test_segment_ends_show_the_scene_as_recorded(self):
        out = os.path.join(self.workdir, "ends")
        run = self.snapshot("--out", out, "--width", "640", "--height", "480")
        self.assertEqual(run.returncode, 0, run.stderr)
        files = sorted(glob.glob(os.path.join(out, "*.png")))
        # The last "reach" phase message (1.95 s) and the bag's end (4 s).
        self.assertEqual(len(files), 2, run.stdout)
        self.assertEqual([round(float(line.split()[0]), 2) for line in run.stdout.split("\n")
                          if line], [1.95, 4.0])
        images = [np.asarray(Image.open(f).convert("RGB")) for f in files]
        centroids = []
        for f, rgb in zip(files, images):
            self.assertEqual(rgb.shape, (480, 640, 3), f)
            self.assertGreater(rgb.reshape(-1, 3).std(axis=0).min(), 20.0, "blank picture " + f)
            masks = colour_masks(rgb)
            counts = {k: int(m.sum()) for k, m in masks.items()}
            rospy.loginfo("snapshot %s: %s", f, counts)
            self.assertGreater(counts["table"], 15000, "%s: no table, %s" % (f, counts))
            self.assertGreater(counts["robot"], 5000, "%s: no robot, %s" % (f, counts))
            self.assertGreater(counts["box"], 100, "%s: no box, %s" % (f, counts))
            self.assertGreater(counts["stick"], 60, "%s: no stick, %s" % (f, counts))
            ys, xs = np.nonzero(masks["box"])
            centroids.append(np.array([xs.mean(), ys.mean()]))
        # The box moved 0.5 m between the two segment ends: its picture must move too, while the
        # stick (not moved) stays put.
        self.assertGreater(np.linalg.norm(centroids[1] - centroids[0]), 60.0, centroids)
        stick = [np.argwhere(colour_masks(rgb)["stick"]).mean(axis=0) for rgb in images]
        self.assertLess(np.linalg.norm(stick[1] - stick[0]), 5.0, stick)
        # The arm moved too: the pictures differ beyond the box's faces (measured: ~7,000 pixels;
        # ~1,200 when only the box moves, from its shaded sides and shadow).
        changed = np.abs(images[0].astype(int) - images[1].astype(int)).max(axis=-1) > 30
        box_area = colour_masks(images[0])["box"] | colour_masks(images[1])["box"]
        self.assertGreater(int((changed & ~box_area).sum()), 3500)

    def test_fixed_camera_and_explicit_times(self):
        out = os.path.join(self.workdir, "overview")
        run = self.snapshot("--out", out, "--times", "1.0,end", "--relative", "--camera",
                            "overview", "--width", "320", "--height", "240")
        self.assertEqual(run.returncode, 0, run.stderr)
        files = sorted(glob.glob(os.path.join(out, "*.png")))
        self.assertEqual(len(files), 2)
        for f in files:
            rgb = np.asarray(Image.open(f).convert("RGB"))
            self.assertEqual(rgb.shape, (240, 320, 3))
            self.assertGreater(int(colour_masks(rgb)["table"].sum()), 1000, f)

    def test_pictures_are_valid_8bit_rgb_png(self):
        # Encoded by libpng: chunks whose CRCs check, 8-bit RGB without alpha or interlacing, and
        # compressed (a 640 x 480 scene is far below its 900 KB of raw pixels).
        out = os.path.join(self.workdir, "format")
        run = self.snapshot("--out", out, "--times", "end", "--width", "640", "--height", "480")
        self.assertEqual(run.returncode, 0, run.stderr)
        files = glob.glob(os.path.join(out, "*.png"))
        self.assertEqual(len(files), 1)
        with Image.open(files[0]) as im:
            im.verify()
        with Image.open(files[0]) as im:
            self.assertEqual((im.format, im.mode, im.size), ("PNG", "RGB", (640, 480)))
            self.assertFalse(im.info.get("interlace"))
        self.assertLess(os.path.getsize(files[0]), 640 * 480 * 3 // 4)

    def test_bad_input_is_a_clear_error(self):
        out = os.path.join(self.workdir, "bad")
        run = subprocess.run(["rosrun", "lfd_sim_bridge", "snapshot", "--bag",
                              os.path.join(self.workdir, "missing.bag"), "--out", out],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 1)
        self.assertIn("does not exist", run.stderr)
        run = self.snapshot("--out", out, "--times", "9.5", "--relative")
        self.assertEqual(run.returncode, 1)
        self.assertIn("outside the bag", run.stderr)
        run = self.snapshot("--out", out, "--camera", "nowhere")
        self.assertEqual(run.returncode, 1)
        self.assertIn("nowhere", run.stderr)
        run = self.snapshot("--out", out, "--width", "abc")
        self.assertEqual(run.returncode, 2)
        self.assertFalse(glob.glob(os.path.join(out, "*.png")))


if __name__ == "__main__":
    rospy.init_node("snapshot_render_test", anonymous=True)
    rostest.rosrun("lfd_test", "snapshot_render", SnapshotRender, sys.argv)
