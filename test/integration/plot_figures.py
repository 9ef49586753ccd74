#!/usr/bin/python3
"""rostest (plot_figures.test): lfd_segmentation/scripts/plot_segmentation.py draws every paper
figure from a real `segment --features` run on synthetic grasp bags written here, plus the
success-rate bars from a report; each PNG has its size and real content; the skill map and the
segmentation figure draw the JSON's feature matrix sample for sample (test_segment_cli checks that
it is the C++ bag reader's); bad input gives a one-line error, no traceback."""
import json
import os
import runpy
import shutil
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

import numpy as np
import rosbag
import rospkg
import rospy
import rostest
import yaml
from catkin.find_in_workspaces import find_in_workspaces
from geometry_msgs.msg import PoseStamped, TwistStamped
from lfd_msgs.msg import Phase, Touch
from lfd_tools import figures
from lfd_tools import report as report_records
from matplotlib import image as mpimg
from matplotlib.axes import Axes
from sensor_msgs.msg import JointState

RATE_HZ = 100.0  # recording rate of the synthetic topics
# (width, height) in pixels of each figure; a layout that crops or resizes the canvas fails here.
SEGMENT_FIGURES = {kind: figures.size_px(kind) for kind in (
    "skill_map", "correlation_best", "correlation_all", "relevance", "clasp_profile",
    "segmentation")}
REPORT_FIGURES = {"success_rates": figures.size_px("success_rates")}


def smoothstep(t, t0, duration):
    u = np.clip((t - t0) / duration, 0.0, 1.0)
    return u * u * (3 - 2 * u)


def write_grasp_bag(path, grasp_time, duration, seed):
    """A grasp-like demo: reach in x, close the gripper at grasp_time (touch pads fire), lift in
    z."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, 1.0 / RATE_HZ)
    x = 0.3 * smoothstep(t, 0.3, grasp_time - 0.5)
    z = 0.8 + 0.15 * smoothstep(t, grasp_time + 0.6, 1.5)
    vx, vz = np.gradient(x, t), np.gradient(z, t)
    gripper = 0.08 - 0.06 * smoothstep(t, grasp_time, 0.3)
    touch = np.where(t >= grasp_time + 0.25, 5.0, 0.0) + 0.05 * rng.standard_normal(len(t)).clip(0)
    phases = [("approach", 0.0), ("grasp", grasp_time), ("move", grasp_time + 0.5)]
    with rosbag.Bag(path, "w") as bag:
        for k, tk in enumerate(t):
            stamp = rospy.Time.from_sec(1.0 + tk)
            pose = PoseStamped()
            pose.header.stamp = stamp
            pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = x[k], 0.1, z[k]
            pose.pose.orientation.w = 1.0
            bag.write("/ee_pose", pose, stamp)
            twist = TwistStamped()
            twist.header.stamp = stamp
            twist.twist.linear.x, twist.twist.linear.z = vx[k], vz[k]
            bag.write("/ee_twist", twist, stamp)
            # JointState and Touch keep a zero header stamp: the readers fall back to the bag time.
            bag.write("/gripper/state", JointState(name=["R_GRIPPER"], position=[gripper[k]],
                                                   velocity=[0.0], effort=[0.0]), stamp)
            bag.write("/touch", Touch(names=["r_touch_left", "r_touch_right"],
                                      values=[touch[k], 0.9 * touch[k]]), stamp)
            if k % 5 == 0:
                name, index = [(n, i) for i, (n, t0) in enumerate(phases) if tk >= t0][-1]
                phase = Phase(task="grasp", name=name, index=index)
                phase.header.stamp = stamp
                bag.write("/lfd/phase", phase, stamp)


TAB_BLUE, TAB_ORANGE = (31, 119, 180), (255, 127, 14)
# Least share of non-white pixels per figure: images and bar charts fill much of the canvas; line
# plots need their curves (checked by colour) beyond axes and text.
MIN_INK = {"skill_map": 0.3, "correlation_best": 0.3, "correlation_all": 0.25, "relevance": 0.15,
           "clasp_profile": 0.015, "segmentation": 0.015, "success_rates": 0.04}
# Colours that must cover >= 300 pixels: the first two curves / bars of each line or bar figure.
MUST_HAVE = {"clasp_profile": (TAB_BLUE, TAB_ORANGE), "segmentation": (TAB_BLUE,),
             "relevance": (TAB_ORANGE,), "success_rates": (TAB_BLUE,)}


def png_checks(testcase, path, kind, size):
    """The PNG exists, has its size and is not blank: enough ink, colours and its curves."""
    testcase.assertTrue(os.path.isfile(path), "%s was not written" % path)
    img = mpimg.imread(path)
    testcase.assertEqual((img.shape[1], img.shape[0]), size, "%s has the wrong size" % path)
    rgb = (img[..., :3] * 255).round().astype(int).reshape(-1, 3)
    colours = len(np.unique(rgb, axis=0))
    ink = np.mean(np.any(rgb < 240, axis=1))
    testcase.assertGreaterEqual(colours, 40,
                                "%s looks blank: %d distinct colours" % (path, colours))
    testcase.assertGreater(ink, MIN_INK[kind], "%s looks blank: %.1f %% ink" % (path, 100 * ink))
    for colour in MUST_HAVE.get(kind, ()):
        count = np.sum(np.all(np.abs(rgb - np.array(colour)) <= 30, axis=1))
        testcase.assertGreaterEqual(count, 300,
                                    "%s: colour %s only on %d pixels" % (path, colour, count))


class PlotFigures(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="lfd_plot_figures_")
        pack = rospkg.RosPack()
        cls.script = os.path.join(pack.get_path("lfd_segmentation"), "scripts",
                                  "plot_segmentation.py")
        found = find_in_workspaces(search_dirs=["libexec"], project="lfd_segmentation",
                                   path="segment")
        assert found, "the lfd_segmentation `segment` CLI is not built"
        cls.segment = found[0]
        with open(os.path.join(pack.get_path("lfd_config"), "segmentation.yaml")) as f:
            config = yaml.safe_load(f)
        config["topics"] = [
            {"topic": "/ee_pose", "role": "state",
             "fields": ["pose/position/x", "pose/position/y", "pose/position/z"]},
            {"topic": "/ee_twist", "role": "state",
             "fields": ["twist/linear/x", "twist/linear/z", "twist/linear/norm"]},
            {"topic": "/gripper/state", "role": "state", "fields": ["position/R_GRIPPER"]},
            {"topic": "/touch", "role": "sensor", "fields": ["values/*"]},
        ]
        config["threads"] = 1
        cls.config = os.path.join(cls.tmp, "segmentation.yaml")
        with open(cls.config, "w") as f:
            yaml.safe_dump(config, f)
        cls.bags = []
        for d, (grasp, duration) in enumerate([(2.5, 6.0), (3.0, 6.5), (2.2, 5.8), (2.8, 6.2)]):
            path = os.path.join(cls.tmp, "grasp_synthetic_%02d.bag" % d)
            write_grasp_bag(path, grasp, duration, d)
            cls.bags.append(path)
        cls.seg_json = os.path.join(cls.tmp, "seg.json")
        seg = subprocess.run([cls.segment, "--config", cls.config, "--features",
                              "--feature-profiles", "--output", cls.seg_json] + cls.bags,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             timeout=60)
        assert seg.returncode == 0, "segment failed:\n" + seg.stdout

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def plot(self, *args):
        return subprocess.run([sys.executable, self.script] + list(args), stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, timeout=120)

    def test_segment_figures(self):
        out = os.path.join(self.tmp, "figs")
        r = self.plot("--segment-json", self.seg_json, "--config", self.config, "--out", out,
                      "--prefix", "grasp_", "--demo", "1", "--bags", *self.bags)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn("warning", r.stderr)
        printed = r.stdout.split()
        for kind, size in SEGMENT_FIGURES.items():
            path = os.path.join(out, "grasp_%s.png" % kind)
            self.assertIn(path, printed)
            png_checks(self, path, kind, size)
        # The segmentation figure draws the touch signal and the ground-truth phases: the phase
        # background colours (beige approach, blue move) must be in the picture.
        img = mpimg.imread(os.path.join(out, "grasp_segmentation.png"))[..., :3]
        rgb = (img * 255).round().astype(int).reshape(-1, 3)
        for colour in ((0xf2, 0xe2, 0xc4), (0xd5, 0xec, 0xd0)):
            blended = np.round(255 - 0.7 * (255 - np.array(colour)))  # alpha 0.7 on white
            near = np.all(np.abs(rgb - blended) <= 3, axis=1).mean()
            self.assertGreater(near, 0.02, "phase colour %s missing (%.3f)" % (colour, near))
        # Confidence zones are bounded by red lines (Fig. 8) whenever the segmenter found one.
        with open(self.seg_json) as f:
            zones = json.load(f)["demos"][1]["zones"]
        red = np.sum((rgb[:, 0] > 200) & (rgb[:, 1] < 80) & (rgb[:, 2] < 80))
        if zones:
            self.assertGreater(red, 500, "zones %s are not drawn" % zones)

    def test_figures_draw_the_segmented_matrix(self):
        """Every sample of the skill map and of the segmentation figure's curves is the JSON's: a
        plotter that read or resampled the bags itself differs by the JSON's rounding at least."""
        plotter = runpy.run_path(self.script, run_name="plot_segmentation")  # main() in-process
        drawn = []  # (method, positional arguments) of every Axes.plot / Axes.imshow call

        def recorded(method):
            original = getattr(Axes, method)

            def record(ax, *args, **kwargs):
                drawn.append((method, args))
                return original(ax, *args, **kwargs)
            return mock.patch.object(Axes, method, record)
        d = 2
        with recorded("plot"), recorded("imshow"):
            status = plotter["main"](["--segment-json", self.seg_json, "--config", self.config,
                                      "--out", os.path.join(self.tmp, "figs_drawn"),
                                      "--demo", str(d)])
        self.assertEqual(status, 0)
        with open(self.seg_json) as f:
            seg = json.load(f)
        matrix = seg["feature_matrices"][d]
        features = matrix["features"]
        normalized = {f["name"]: plotter["normalize01"](np.array(f["values"])) for f in features}
        t = np.array(matrix["time"]) - matrix["time"][0]
        image = [args[0] for method, args in drawn  # the correlation matrices are images too
                 if method == "imshow" and np.shape(args[0]) == (len(features), len(t))]
        self.assertEqual(len(image), 1, "one skill map")
        by_role = [f["name"] for role in ("sensor", "state", "context") for f in features
                   if f["role"] == role]
        self.assertEqual(len(by_role), len(features), "a role that is not state, sensor or context")
        np.testing.assert_array_equal(image[0], np.array([normalized[n] for n in by_role]))
        curves = [np.asarray(args[1], dtype=float) for method, args in drawn
                  if method == "plot" and len(args) >= 2 and np.array_equal(args[0], t)]
        expected = [normalized[n] for n in seg["selected_features"]]
        expected += [np.array(f["values"]) for f in features if f["role"] == "sensor"]
        self.assertGreaterEqual(len(expected), 3)
        for y in expected:
            self.assertTrue(any(np.array_equal(c, y) for c in curves), "a curve is not the JSON's")

    def test_without_matrices_the_rest_is_drawn(self):
        """A JSON of `segment` without --features: Fig. 3, 4, 5 and a warning naming the flag."""
        with open(self.seg_json) as f:
            seg = json.load(f)
        del seg["feature_matrices"]
        path = os.path.join(self.tmp, "no_matrices.json")
        with open(path, "w") as f:
            json.dump(seg, f)
        out = os.path.join(self.tmp, "figs_no_matrices")
        r = self.plot("--segment-json", path, "--config", self.config, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("--features", r.stderr)
        self.assertEqual(sorted(os.listdir(out)), sorted(
            "%s.png" % k
            for k in ("correlation_best", "correlation_all", "relevance", "clasp_profile")))

    def test_dataset_folder_and_several_demos(self):
        out = os.path.join(self.tmp, "figs_dataset")
        r = self.plot("--dataset", self.tmp, "--config", self.config, "--out", out, "--prefix",
                      "syn_", "--demo", "0,3", "--no-ground-truth", "--segment-cli", self.segment)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "syn_segment.json")) as f:
            self.assertEqual([d["source"] for d in json.load(f)["demos"]], self.bags)
        for d in range(len(self.bags)):
            for kind in ("skill_map", "segmentation", "clasp_profile"):
                path = os.path.join(out, "syn_%s_grasp_synthetic_%02d.png" % (kind, d))
                self.assertEqual(os.path.isfile(path), d in (0, 3), path)
        for kind in ("skill_map", "segmentation"):
            png_checks(self, os.path.join(out, "syn_%s_grasp_synthetic_03.png" % kind), kind,
                       SEGMENT_FIGURES[kind])

    def test_report_figure(self):
        report = {"segmentation": {
            "sim_grasp": {"methods": {"average": 1.0, "product": 0.89, "weighted_average": 1.0,
                                      "weighted_product": 1.0}, "tolerance_s": 0.5},
            "teleop_push": {"methods": {"average": 0.0, "product": None, "weighted_average": 0.5,
                                        "weighted_product": 0.33}, "tolerance_s": 0.5}}}
        path = os.path.join(self.tmp, "report.json")
        with open(path, "w") as f:
            json.dump(report, f)
        out = os.path.join(self.tmp, "figs_report")
        r = self.plot("--report", path, "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        png_checks(self, os.path.join(out, "success_rates.png"), "success_rates",
                   REPORT_FIGURES["success_rates"])
        # evaluate_segmentation.py's own output: the same records (lfd_tools.report), a failed
        # method too.
        evaluation = {"tolerance_s": 0.5,
                      "segmentation": {"sim_push": report_records.segmentation_record(
                          {"weighted_product": {"success_rate": 0.75},
                           "average": {"success_rate": 0.5},
                           "product": {"error": "the service failed"}}, 0.5)}}
        with open(path, "w") as f:
            json.dump(evaluation, f)
        r = self.plot("--report", path, "--out", out, "--prefix", "eval_")
        self.assertEqual(r.returncode, 0, r.stderr)
        png_checks(self, os.path.join(out, "eval_success_rates.png"), "success_rates",
                   REPORT_FIGURES["success_rates"])

    def test_bad_input_is_a_clear_error(self):
        bad_json = os.path.join(self.tmp, "bad.json")
        with open(bad_json, "w") as f:
            f.write("{not json")
        empty = os.path.join(self.tmp, "empty.json")
        with open(empty, "w") as f:
            f.write("{}")
        with open(self.seg_json) as f:
            seg = json.load(f)
        seg["feature_matrices"][0]["time"].pop()
        short_time = os.path.join(self.tmp, "short_time.json")
        with open(short_time, "w") as f:
            json.dump(seg, f)
        out = os.path.join(self.tmp, "figs_bad")
        cases = [
            (["--segment-json", os.path.join(self.tmp, "missing.json")], "does not exist"),
            (["--segment-json", bad_json], "not valid JSON"),
            (["--segment-json", empty], "no key 'demos'"),
            (["--segment-json", self.seg_json, "--config", self.config, "--demo", "9"],
             "out of range"),
            (["--segment-json", short_time, "--config", self.config], "feature_matrices[0] holds"),
            (["--segment-json", self.seg_json, "--config", self.config, "--bags",
              "/nonexistent.bag"],
             "1 --bags for 4"),
            (["--segment-json", self.seg_json, "--config", self.config, "--bags"] +
             ["/nonexistent_%d.bag" % d for d in range(4)], "does not exist"),
            (["--segment-json", self.seg_json, "--config", bad_json], "cannot read config"),
            (["--report", empty], "no 'segmentation' section"),
            (["--dataset", os.path.join(self.tmp, "no_such_dir")], "is not a folder"),
            (["--dataset", out], "no .bag files"),
            (["--dataset", self.tmp, "--config", self.config, "--segment-cli", "/bin/false"],
             "segment failed"),
        ]
        for args, message in cases:
            r = self.plot(*(args + ["--out", out]))
            self.assertEqual(r.returncode, 2, "%s: exit %d\n%s" % (args, r.returncode, r.stderr))
            self.assertIn(message, r.stderr, args)
            self.assertNotIn("Traceback", r.stderr, args)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "plot_figures", PlotFigures)
