#!/usr/bin/python3
"""rostest (signal_classes_units.test): the generators of the real-world signal classes
(lfd_tools/signal_classes.py, written by lfd_segmentation/scripts/make_signal_classes.py) against
what the segmentation's acceptance asks of them, written out here rather than read from the module:
the same seed writes the same files and another seed other files; every class writes its declared
columns on an even clock at its rate; the truth's boundaries are as many as the class has, strictly
increasing and inside the demo; 6-8 demos per task; the 1000 Hz variants within the `segment` CLI's
sample limits (config/segmentation.yaml); the phases the classes promise (a short middle phase, a
short insertion, contact never lost, continuous motions, long pauses before the PR2-like boundaries,
stale and dead F/T). Pure Python, no node and no segmentation: a few seconds."""
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np
import rospkg
import rostest
import yaml
from lfd_tools import signal_classes

PACK = rospkg.RosPack()
SCRIPT = os.path.join(PACK.get_path("lfd_segmentation"), "scripts", "make_signal_classes.py")
SEG_CONFIG = os.path.join(PACK.get_path("lfd_config"), "segmentation.yaml")
POSE = ["x", "y", "z", "qx", "qy", "qz", "qw"]
WRENCH = ["fx", "fy", "fz", "tx", "ty", "tz"]
# class -> (boundaries per demo, state columns, sensor columns, rate in Hz)
EXPECTED = {
    "contact_wipe": (2, POSE, WRENCH, 90), "in_contact_level": (3, POSE, WRENCH, 200),
    "short_phase": (2, POSE, WRENCH, 100), "stale_sensor": (2, POSE, WRENCH, 90),
    "drifting_sensor": (2, POSE, WRENCH, 100), "strokes": (8, POSE, WRENCH, 100),
    "motion_only": (2, POSE, [], 100), "pause_boundaries": (3, None, [], 100),
}
for _base in ("contact_wipe", "in_contact_level"):
    for _rate in (25, 100, 1000):
        EXPECTED["%s@%d" % (_base, _rate)] = EXPECTED[_base][:3] + (_rate,)


def write(out, seed, classes=""):
    cmd = ["/usr/bin/python3", SCRIPT, out,
           "--seed", str(seed)] + (["--classes", classes] if classes else [])
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=120)


def read_class(out, name):
    """(truth.json, [(header, rows)] per demo)."""
    with open(os.path.join(out, name, "truth.json")) as f:
        truth = json.load(f)
    demos = []
    for d in truth["demos"]:
        path = os.path.join(out, name, d["file"])
        with open(path) as f:
            header = f.readline().strip().split(",")
        demos.append((header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)))
    return truth, demos


def content(*parts):
    with open(os.path.join(*parts), "rb") as f:
        return f.read()


def smoothed(values, rate, seconds=0.1):
    n = max(1, int(seconds * rate))
    return np.convolve(values, np.ones(n) / n, mode="same")


class SignalClasses(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.tmp.name, "a")
        write(cls.out, 3)
        cls.data = {name: read_class(cls.out, name) for name in EXPECTED}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def column(self, name, demo, col):
        header, rows = self.data[name][1][demo]
        return rows[:, 0], rows[:, header.index(col)]

    def test_every_class_and_rate_variant_is_registered(self):
        self.assertEqual(sorted(signal_classes.CLASSES), sorted(EXPECTED))
        self.assertEqual(sorted(os.listdir(self.out)), sorted(EXPECTED))

    def test_same_seed_same_files_other_seed_other_files(self):
        again, other = os.path.join(self.tmp.name, "b"), os.path.join(self.tmp.name, "c")
        write(again, 3)
        write(other, 4, "contact_wipe,pause_boundaries")
        for name in EXPECTED:
            for f in sorted(os.listdir(os.path.join(self.out, name))):
                self.assertEqual(content(self.out, name, f), content(again, name, f),
                                 "%s/%s differs between two runs of seed 3" % (name, f))
        for name in ("contact_wipe", "pause_boundaries"):
            self.assertNotEqual(content(self.out, name, "demo_0.csv"),
                                content(other, name, "demo_0.csv"),
                                "%s: seeds 3 and 4 wrote the same demo" % name)

    def test_a_subset_writes_what_the_whole_set_writes(self):
        part = os.path.join(self.tmp.name, "d")
        write(part, 3, "strokes")
        self.assertEqual(content(part, "strokes", "demo_1.csv"),
                         content(self.out, "strokes", "demo_1.csv"))

    def test_declared_columns_on_an_even_clock(self):
        for name, (_, state, sensor, rate) in EXPECTED.items():
            truth, demos = self.data[name]
            if state is not None:
                self.assertEqual(truth["state_columns"], state, name)
            self.assertEqual(len(truth["state_columns"]), 7, name)
            self.assertEqual(truth["sensor_columns"], sensor, name)
            self.assertEqual(truth["rate_hz"], rate, name)
            for k, (header, rows) in enumerate(demos):
                self.assertEqual(header,
                                 ["time"] + truth["state_columns"] + truth["sensor_columns"],
                                 (name, k))
                self.assertEqual(rows.shape[1], len(header), (name, k))
                self.assertTrue(np.all(np.isfinite(rows)), (name, k))
                self.assertEqual(rows[0, 0], 0.0)
                self.assertTrue(np.allclose(np.diff(rows[:, 0]), 1.0 / rate, atol=2e-5), (name, k))

    def test_boundaries_as_many_as_the_class_has_increasing_inside_the_demo(self):
        for name, (count, _, _, _) in EXPECTED.items():
            truth, demos = self.data[name]
            self.assertTrue(6 <= len(demos) <= 8, (name, len(demos)))
            for d, (_, rows) in zip(truth["demos"], demos):
                b = d["boundaries_s"]
                self.assertEqual(len(b), count, (name, d["file"]))
                self.assertTrue(all(x < y for x, y in zip(b, b[1:])), (name, d["file"], b))
                self.assertTrue(0.0 < b[0] and b[-1] < rows[-1, 0],
                                (name, d["file"], b, rows[-1, 0]))

    def test_motions_are_continuous(self):
        # A hand moves at most 1.5 m/s, an arm's joints 3 rad/s; the noise adds a few 1e-4.
        for name, (_, state, _, rate) in EXPECTED.items():
            limit = (1.5 if state == POSE else 3.0) / rate + 2e-3
            for k, (header, rows) in enumerate(self.data[name][1]):
                cols = [header.index(c)
                        for c in (["x", "y", "z"] if state == POSE else header[1:8])]
                step = np.max(np.abs(np.diff(rows[:, cols], axis=0)))
                self.assertLess(step, limit, (name, k))

    def test_1000_hz_variants_fit_the_sample_limits(self):
        with open(SEG_CONFIG) as f:
            limits = yaml.safe_load(f)["limits"]
        for name in ("contact_wipe@1000", "in_contact_level@1000"):
            rows = [len(r) for _, r in self.data[name][1]]
            self.assertLessEqual(max(rows), limits["max_samples_per_demo"], name)
            self.assertLessEqual(max(rows), 11000, name)  # demos of at most 11 s
            self.assertLessEqual(sum(rows), limits["max_total_samples"], name)
            self.assertGreater(min(rows), 5000, name)  # not made to fit by shortening them

    def test_the_limits_take_45_snap_fit_demos_in_one_call(self):
        """Issue 22's robot-run snap-fit set has 45 demos at 200 Hz, segmented in one call."""
        with open(SEG_CONFIG) as f:
            limits = yaml.safe_load(f)["limits"]
        rows = [len(r) for _, r in self.data["in_contact_level"][1]]
        self.assertGreaterEqual(limits["max_bags"], 45)
        self.assertGreaterEqual(limits["max_bag_files"], 45)
        self.assertGreaterEqual(limits["max_total_samples"], 45 * max(rows))

    def test_rate_variants_keep_their_base_durations(self):
        base = self.data["contact_wipe@100"][0]["demos"]
        for rate in (25, 1000):
            other = self.data["contact_wipe@%d" % rate][0]["demos"]
            for a, b in zip(base, other):
                self.assertTrue(np.allclose(a["boundaries_s"], b["boundaries_s"], atol=0.1),
                                (rate, a, b))

    def test_short_phase_and_insertion_last_as_long_as_stated(self):
        for d in self.data["short_phase"][0]["demos"]:
            b = d["boundaries_s"]
            self.assertTrue(0.49 <= b[1] - b[0] <= 0.91, b)
        for name in ("in_contact_level", "in_contact_level@25", "in_contact_level@1000"):
            for d in self.data[name][0]["demos"]:
                b = d["boundaries_s"]
                self.assertTrue(0.68 <= b[2] - b[1] <= 1.02, (name, b))

    def test_contact_force_builds_up_after_the_touch_and_never_leaves_in_assembly(self):
        for name, rate in (("contact_wipe", 90), ("in_contact_level", 200)):
            for k, d in enumerate(self.data[name][0]["demos"]):
                t, fz = self.column(name, k, "fz")
                fz = smoothed(fz, rate)
                touch = d["boundaries_s"][0]
                rest = np.median(fz[t < touch - 0.6])
                self.assertLess(abs(fz[np.searchsorted(t, touch - 0.1)] - rest), 1.5, (name, k))
                self.assertLess(fz[np.searchsorted(t, touch + 0.5)] - rest, -4.0, (name, k))
                if name == "in_contact_level":  # pressed from the touch to the end
                    self.assertLess(np.max(fz[t > touch + 0.45] - rest), -3.0, k)
                    peak = np.min(fz - rest)
                    self.assertTrue(-34 < peak < -22, (k, peak))  # ~29 N at the snap

    def test_pause_boundaries_follow_long_pauses(self):
        truth, demos = self.data["pause_boundaries"]
        for d, (header, rows) in zip(truth["demos"], demos):
            t, q = rows[:, 0], rows[:, 1:]
            at = lambda s: q[np.searchsorted(t, s)]
            for b in d["boundaries_s"]:
                # still
                self.assertLess(np.max(np.abs(at(b - 0.02) - at(b - 0.98))), 0.003, (d["file"], b))
                # moving again
                self.assertGreater(np.max(np.abs(at(b + 0.6) - at(b))), 0.02, (d["file"], b))

    def test_stale_and_dead_force_torque(self):
        truth, demos = self.data["stale_sensor"]
        dead, stale = 0, 0
        for header, rows in demos:
            ft = rows[:, [header.index(c) for c in WRENCH]]
            # rows equal to the first
            repeats = int(np.argmax(np.any(ft != ft[0], axis=1))) or len(ft)
            dead += repeats == len(ft)
            stale += 2.0 * 90 - 2 <= repeats <= 4.0 * 90 + 2
            self.assertTrue(repeats == 1 or repeats == len(ft) or repeats >= 2.0 * 90 - 2, repeats)
        self.assertEqual(dead, 1)
        self.assertIn(stale, (1, 2))


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "signal_classes_units", SignalClasses)
