#!/usr/bin/python3
"""rostest (truth_file_scoring.test): the evaluator scores demos from a ground-truth file.

Hand-made case: tiny bags (a two-part demo and a one-part demo) whose first stamps are known, a
ground-truth file in the documented format, and a stand-in segmenter returning chosen changepoint
times. Checks the paper's success rule, Covering, margin F1 and time errors against values worked
out by hand, and the labels.json converter. No master, no segmentation: a second or two."""
import json
import os
import tempfile
import unittest

import rosbag
import rospy
import rostest
from lfd_tools import bags as lfd_bags
from lfd_tools import segmentation_scoring
from std_msgs.msg import Float64


def write_bag(path, t0, t1):
    with rosbag.Bag(path, "w") as bag:
        for t in (t0, 0.5 * (t0 + t1), t1):
            bag.write("/x", Float64(t), rospy.Time.from_sec(t))


class FakeSegmenter(object):
    """Returns fixed changepoints (absolute s) per demo and records the inputs it was given."""

    def __init__(self, changepoints):
        self.changepoints, self.inputs = changepoints, None

    def __call__(self, inputs, method):
        self.inputs = inputs
        return {"demos": [{"changepoint_times": c, "rejected_times": [], "pruned_times": [],
                           "zones": []}
                          for c in self.changepoints],
                "selected_features": ["f"], "selected_weights": [1.0], "warnings": []}


class FakeMultiSegmenter(FakeSegmenter):
    """Also answers every method at once (as the `segment` CLI does); counts its calls."""

    def __init__(self, changepoints):
        FakeSegmenter.__init__(self, changepoints)
        self.calls = []

    def __call__(self, inputs, method):
        self.calls.append([method])
        return FakeSegmenter.__call__(self, inputs, method)

    def methods(self, inputs, methods):
        self.calls.append(list(methods))
        return {m: FakeSegmenter.__call__(self, inputs, m) for m in methods}


class TruthFileScoring(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp()
        # demo a: parts [100, 104] and [105, 110] -> span 100..110, truth 5 s -> 105 absolute
        write_bag(os.path.join(cls.dir, "a1.bag"), 100.0, 104.0)
        write_bag(os.path.join(cls.dir, "a2.bag"), 105.0, 110.0)
        # demo b: one part [200, 210], truth 3 s and 7 s -> 203, 207
        write_bag(os.path.join(cls.dir, "b.bag"), 200.0, 210.0)
        cls.truth = os.path.join(cls.dir, "truth.yaml")
        with open(cls.truth, "w") as f:
            f.write("demos:\n  - {name: a, bags: [a1.bag, a2.bag], changepoints_s: [5.0]}\n"
                    "  - {name: b, bags: b.bag, changepoints_s: [7.0, 3.0]}\n")

    def evaluate(self, changepoints, tolerance=0.5):
        seg = FakeSegmenter(changepoints)
        out = segmentation_scoring.evaluate_truth_file(seg, lfd_bags.load_truth_file(self.truth),
                                                       "product", tolerance)
        return seg, out

    def test_parts_are_joined_in_order_and_times_relative_to_the_first_bag(self):
        seg, out = self.evaluate([[105.3], [203.0, 207.0]])
        self.assertEqual(seg.inputs, [os.path.join(self.dir, "a1.bag") + ","
                                      + os.path.join(self.dir, "a2.bag"),
                                      os.path.join(self.dir, "b.bag")])
        self.assertEqual(out["correct"], 2)
        a, b = out["details"]
        self.assertAlmostEqual(a["time_errors_s"][0], 0.3)
        self.assertEqual(b["truth_rel_s"], [3.0, 7.0])
        self.assertAlmostEqual(a["changepoints_rel_s"][0], 5.3)
        # Covering of a: truth [100,105],[105,110]; found [100,105.3],[105.3,110]
        # = 0.5 * 5/5.3 + 0.5 * 4.7/5 = 0.941698...
        self.assertAlmostEqual(a["covering"], 0.5 * 5 / 5.3 + 0.5 * 4.7 / 5, places=9)
        self.assertAlmostEqual(b["covering"], 1.0)
        self.assertAlmostEqual(out["f1"], 1.0)

    def test_success_needs_exactly_one_changepoint_within_tolerance_of_each_boundary(self):
        # a: outside 0.5 s (0.7 late); b: an extra changepoint
        _, out = self.evaluate([[105.7], [203.0, 205.0, 207.0]])
        self.assertEqual(out["correct"], 0)
        a, b = out["details"]
        self.assertAlmostEqual(a["time_errors_s"][0], 0.7)
        # F1 of a: truth {100,105,110}, found {100,105.7,110}: tp 2 of 3 -> 2/3
        self.assertAlmostEqual(a["f1"], 2.0 / 3.0)
        # F1 of b: truth 4 points, found 5, tp 4 -> P 4/5, R 1 -> 8/9
        self.assertAlmostEqual(b["f1"], 8.0 / 9.0)
        # the wider tolerance accepts a's late changepoint, never b's extra one
        _, out = self.evaluate([[105.7], [203.0, 205.0, 207.0]], tolerance=1.0)
        self.assertEqual([d["correct"] for d in out["details"]], [True, False])
        self.assertAlmostEqual(out["success_rate"], 0.5)

    def test_missed_boundary_is_counted_and_errors_summarized(self):
        _, out = self.evaluate([[], [203.2, 207.4]])
        self.assertEqual(out["transitions_without_changepoint"], 1)
        self.assertIsNone(out["details"][0]["time_errors_s"][0])
        self.assertAlmostEqual(out["time_error_median_s"], 0.3)
        self.assertAlmostEqual(out["details"][0]["covering"], 0.5)

    def test_several_methods_ask_a_multi_method_segmenter_once(self):
        demos = lfd_bags.load_truth_file(self.truth)
        seg = FakeMultiSegmenter([[105.3], [203.0, 207.0]])
        out = segmentation_scoring.evaluate_truth_file_methods(seg, demos, ["product", "average"],
                                                               0.5)
        self.assertEqual(seg.calls, [["product", "average"]])
        self.assertEqual(sorted(out), ["average", "product"])
        self.assertEqual(out["average"]["correct"], 2)
        self.assertEqual(out["product"]["details"][1]["truth_rel_s"], [3.0, 7.0])
        # one method, or a segmenter without .methods: one call per method
        plain = FakeSegmenter([[105.3], [203.0, 207.0]])
        both = segmentation_scoring.evaluate_truth_file_methods(plain, demos,
                                                                ["product", "average"], 0.5)
        self.assertEqual(both["average"]["correct"], out["average"]["correct"])
        seg.calls = []
        segmentation_scoring.evaluate_truth_file_methods(seg, demos, ["product"], 0.5)
        self.assertEqual(seg.calls, [["product"]])

    def test_labels_json_converts_to_a_truth_file(self):
        labels = {"runs": {"r2": {"parts": [{"file": "r2/p1.bag"}, {"file": "r2/p2.bag"}],
                                  "boundaries_rel": [4.5]},
                           "r1": {"parts": [{"file": "r1/p1.bag"}], "boundaries_rel": []}}}
        path = os.path.join(self.dir, "labels.json")
        with open(path, "w") as f:
            json.dump(labels, f)
        # the single-part run has no boundary: left out
        demos = lfd_bags.truth_from_labels(path)["demos"]
        self.assertEqual([d["name"] for d in demos], ["r2"])
        self.assertEqual(demos[0]["bags"],
                         [os.path.join(self.dir, "r2/p1.bag"), os.path.join(self.dir, "r2/p2.bag")])
        self.assertEqual(demos[0]["changepoints_s"], [4.5])
        named = lfd_bags.truth_from_labels(path, ["r1", "r2"])["demos"]
        self.assertEqual([d["name"] for d in named], ["r1", "r2"])

    def test_malformed_truth_file_gives_a_clear_error(self):
        bad = os.path.join(self.dir, "bad.yaml")
        with open(bad, "w") as f:
            f.write("demos:\n  - {name: a}\n")
        with self.assertRaisesRegex(RuntimeError, "needs 'bags' and 'changepoints_s'"):
            lfd_bags.load_truth_file(bad)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "truth_file_scoring", TruthFileScoring)
