#!/usr/bin/python3
"""rostest (judge_units.test): the judges behind the README's headline numbers (lfd_tools.judge,
its readers and records) on hand-made cases worked out by hand: the paper's segmentation success
rule and its tolerance edges, missing and extra changepoints, Covering, margin F1 and time errors;
physical success at its distance and lift edges, 3-D against horizontal distance, yaw symmetry;
every rule type of a task file (object at its goal, height, joint, sustained contact along a path);
criteria, skills and transitions read from the task files (a task file written here changes the
verdict; a bad one is a clear error naming the file and the key); a demo bag judged end to end;
the report records. Pure Python: no node, no simulation (rostest's master is not used)."""
import json
import math
import os
import shutil
import tempfile
import unittest

import rosbag
import rospy
import rostest
import yaml
from geometry_msgs.msg import PoseStamped
from lfd_msgs.msg import DemoMetadata, Phase
from std_msgs.msg import Header
from lfd_tools import bags, config, judge, redo, report, stamps, tasks

GRASP = {"object": "stick", "distance": "xyz", "tolerance_m": 0.03, "min_lift_m": 0.10,
         "yaw_symmetry": 2}
PUSH = {"object": "box", "distance": "xy", "tolerance_m": 0.03, "yaw_symmetry": 4}
TABLE = 0.80
GRASP_EXPECTED = [{"from": "approach", "to": "move"}]
PUSH_EXPECTED = [{"from": "approach", "to": "push"}, {"from": "push", "to": "return"}]


class SegmentationRule(unittest.TestCase):
    WINDOWS = [(1.5, 3.5), (5.5, 6.5)]  # two transitions, already widened by the tolerance

    def test_one_changepoint_per_window_in_order(self):
        self.assertTrue(judge.segmentation_correct([2.0, 6.0], self.WINDOWS)[0])
        # order of the list is free
        self.assertTrue(judge.segmentation_correct([6.0, 2.0], self.WINDOWS)[0])

    def test_missing_and_extra_changepoints_fail(self):
        ok, why = judge.segmentation_correct([2.0], self.WINDOWS)
        self.assertFalse(ok)
        self.assertIn("expected 2 changepoints, got 1", why)
        self.assertFalse(judge.segmentation_correct([2.0, 4.5, 6.0], self.WINDOWS)[0])
        self.assertFalse(judge.segmentation_correct([], self.WINDOWS)[0])

    def test_two_in_one_window_and_none_in_the_other_fails(self):
        self.assertFalse(judge.segmentation_correct([2.0, 3.0], self.WINDOWS)[0])

    def test_window_edges_are_inside(self):
        self.assertTrue(judge.segmentation_correct([1.5, 6.5], self.WINDOWS)[0])
        self.assertFalse(judge.segmentation_correct([1.5 - 1e-6, 6.0], self.WINDOWS)[0])
        self.assertFalse(judge.segmentation_correct([2.0, 6.5 + 1e-6], self.WINDOWS)[0])

    def test_tolerance_widens_each_true_window(self):
        # an instant at 5 s, tolerance 0.5 s: 5.5 counts, 5.51 does not
        self.assertTrue(judge.score_demo([5.5], [(5.0, 5.0)], 0.0, 10.0, 0.5)["correct"])
        self.assertFalse(judge.score_demo([5.51], [(5.0, 5.0)], 0.0, 10.0, 0.5)["correct"])
        self.assertTrue(judge.score_demo([5.51], [(5.0, 5.0)], 0.0, 10.0, 0.6)["correct"])

    def test_windows_from_the_ground_truth_phases(self):
        # grasp: approach until 2 s, grasp 2..3 s, move from 3 s: the window is the grasp phase
        grasp = [("approach", 0.0), ("grasp", 2.0), ("move", 3.0), ("done", 8.0)]
        self.assertEqual(judge.expected_windows(grasp, GRASP_EXPECTED, 0.5), [(1.5, 3.5)])
        # push: instants at the start of push (4 s) and of return (7 s)
        push = [("approach", 0.0), ("push", 4.0), ("return", 7.0), ("done", 9.0)]
        self.assertEqual(judge.expected_windows(push, PUSH_EXPECTED, 0.5), [(3.5, 4.5), (6.5, 7.5)])
        with self.assertRaises(RuntimeError):
            judge.expected_windows([("approach", 0.0), ("done", 4.0)], GRASP_EXPECTED, 0.5)


class SegmentationFigures(unittest.TestCase):
    def test_covering(self):
        self.assertAlmostEqual(judge.covering([5.0], [5.0], 0.0, 10.0), 1.0)
        # [0,10] vs halves: J = 0.5 each
        self.assertAlmostEqual(judge.covering([5.0], [], 0.0, 10.0), 0.5)
        # truth [0,5] [5,10], found [0,2.5] [2.5,10]: best J 0.5 and 5/7.5
        self.assertAlmostEqual(judge.covering([5.0], [2.5], 0.0, 10.0),
                               (5 * 0.5 + 5 * 5 / 7.5) / 10)

    def test_margin_f1(self):
        self.assertAlmostEqual(judge.margin_f1([5.0], [5.4], 0.0, 10.0, 0.5), 1.0)
        self.assertAlmostEqual(judge.margin_f1([5.0], [6.0], 0.0, 10.0, 0.5), 2 / 3)  # P = R = 2/3
        # extra: P 3/4
        self.assertAlmostEqual(judge.margin_f1([5.0], [5.0, 8.0], 0.0, 10.0, 0.5), 2 * 0.75 / 1.75)

    def test_time_errors(self):
        self.assertEqual(judge.time_errors([(2.0, 3.0)], [2.5]), [0.0])
        self.assertAlmostEqual(judge.time_errors([(2.0, 3.0)], [3.4, 9.0])[0], 0.4)
        self.assertAlmostEqual(judge.time_errors([(2.0, 3.0)], [1.0])[0], 1.0)
        self.assertEqual(judge.time_errors([(2.0, 3.0), (5.0, 5.0)], []), [None, None])

    def test_dataset_summary(self):
        scores = [judge.score_demo([5.2], [(5.0, 5.0)], 0.0, 10.0, 0.5),
                  judge.score_demo([], [(5.0, 5.0)], 0.0, 10.0, 0.5),
                  judge.score_demo([5.0, 8.0], [(5.0, 5.0)], 0.0, 10.0, 0.5)]
        s = judge.summarize_scores(scores, 0.5)
        self.assertEqual((s["demos"], s["correct"]), (3, 1))
        self.assertAlmostEqual(s["success_rate"], 1 / 3)
        self.assertEqual(s["transitions_without_changepoint"], 1)
        self.assertAlmostEqual(s["time_error_median_s"], 0.1)  # errors 0.2 s and 0 s


class PhysicalSuccess(unittest.TestCase):
    GOAL = (0.5, -0.3, 0.95)

    def grasp(self, dx=0.0, dz=0.0, z=None):
        end = (self.GOAL[0] + dx, self.GOAL[1], (z if z is not None else self.GOAL[2]) + dz)
        return judge.physical_outcome(GRASP, end, self.GOAL, TABLE)

    def test_distance_edge(self):
        # exact in binary: goal at x = 0, table at z = 0
        goal = (0.0, 0.0, 0.5)
        self.assertTrue(judge.physical_outcome(GRASP, (0.03, 0.0, 0.5), goal, 0.0)["success"])
        self.assertTrue(judge.physical_outcome(GRASP, (0.0, -0.03, 0.5), goal, 0.0)["success"])
        self.assertFalse(
            judge.physical_outcome(GRASP, (0.03 + 1e-6, 0.0, 0.5), goal, 0.0)["success"])
        self.assertTrue(self.grasp(dx=0.03 - 1e-6)["success"])
        self.assertFalse(self.grasp(dx=0.0301)["success"])

    def test_lift_edge(self):
        # a goal 10 cm above the table (at z = 0): exactly 10 cm of lift counts, 9.9 cm does not
        goal = (0.5, -0.3, 0.10)
        self.assertTrue(judge.physical_outcome(GRASP, goal, goal, 0.0)["success"])
        low = (0.5, -0.3, TABLE + 0.099)
        out = judge.physical_outcome(GRASP, low, low, TABLE)  # at its goal, but too low
        self.assertFalse(out["success"])
        self.assertAlmostEqual(out["height_m"], 0.099)
        self.assertIn("above the table", out["reason"])

    def test_grasp_is_3d_push_is_horizontal(self):
        self.assertFalse(self.grasp(dz=0.04)["success"])  # 4 cm too high: 3-D distance 4 cm
        self.assertAlmostEqual(self.grasp(dx=0.02, dz=0.02)["distance_m"], math.sqrt(0.0008))
        target = (0.5, -0.3, 0.84)
        out = judge.physical_outcome(PUSH, (0.5 + 0.029, -0.3, 0.84 + 0.2), target, TABLE)
        self.assertTrue(out["success"])  # height does not count for a push
        self.assertAlmostEqual(out["distance_m"], 0.029)
        self.assertFalse(judge.physical_outcome(PUSH, (0.5, -0.3 + 0.031, 0.84),
                                                target, TABLE)["success"])

    def test_push_has_no_lift_requirement(self):
        on_table = (0.5, -0.3, TABLE + 0.04)
        self.assertTrue(judge.physical_outcome(PUSH, on_table, on_table, TABLE)["success"])

    def test_yaw_error_modulo_the_objects_symmetry(self):
        g = self.GOAL
        self.assertAlmostEqual(judge.physical_outcome(GRASP, g, g, TABLE,
                                                      0.1 + math.pi, 0.1)["yaw_error_rad"], 0.0)
        self.assertAlmostEqual(judge.physical_outcome(GRASP, g, g, TABLE,
                                                      0.1 + math.pi / 2, 0.1)["yaw_error_rad"],
                               math.pi / 2)
        self.assertAlmostEqual(judge.physical_outcome(PUSH, g, g, TABLE,
                                                      math.pi / 2, 0.0)["yaw_error_rad"], 0.0)
        self.assertAlmostEqual(
            judge.physical_outcome(PUSH, g, g, TABLE, 0.3, 0.0)["yaw_error_rad"], 0.3)
        self.assertIsNone(judge.physical_outcome(PUSH, g, g, TABLE)["yaw_error_rad"])


class Rules(unittest.TestCase):
    """The rule types of a task file's criterion, at their edges (judge_rules)."""
    GOAL = {"position": [0.0, 0.0, 0.5], "orientation": [1.0, 0.0, 0.0, 0.0]}

    def judge(self, rules, objects=None, joints=None, contact=None):
        measured = {"objects": {k: {"position": list(v), "orientation": [1.0, 0.0, 0.0, 0.0]}
                                for k, v in (objects or {}).items()},
                    "joints": joints or {}, "contact": contact or []}
        return judge.judge_rules({"rules": rules}, measured, {"goal": self.GOAL}, 0.0)

    def test_every_rule_must_hold(self):
        at_goal = {"rule": "object_at_goal", "object": "block", "distance": "xyz",
                   "tolerance_m": 0.02}
        resting = {"rule": "height", "object": "block", "max_m": 0.03}
        self.assertTrue(self.judge([at_goal], {"block": (0.02, 0.0, 0.5)})["success"])
        # at the goal, but held up
        out = self.judge([at_goal, resting], {"block": (0.02, 0.0, 0.5)})
        self.assertFalse(out["success"])
        self.assertEqual([r["success"] for r in out["rules"]], [True, False])
        self.assertIn("block above the table 50", out["reason"])
        self.assertTrue(self.judge([resting], {"block": (0.3, 0.0, 0.03)})["success"])
        self.assertFalse(self.judge([at_goal], {})["success"])  # not recorded: never a success

    def test_joint_bounds(self):
        rule = {"rule": "joint", "joint": "drawer_slide", "min": 0.05}
        self.assertTrue(self.judge([rule], joints={"drawer_slide": 0.05})["success"])
        self.assertFalse(self.judge([rule], joints={"drawer_slide": 0.0499})["success"])
        both = dict(rule, max=0.1)
        self.assertFalse(self.judge([both], joints={"drawer_slide": 0.11})["success"])
        self.assertIn("was not recorded", self.judge([rule])["reason"])

    WIPE = {"rule": "contact_path", "min_force_n": 2.0, "length_m": 0.16, "tolerance_m": 0.02,
            "passes": 3, "max_gap_s": 0.3}

    def strokes(self, ends, force=8.0, beside=0.0, gap=None, dt=0.01):
        """Samples going through the x positions `ends` at 20 cm/s (the goal's axis is x)."""
        out, t = [], 0.0
        for a, b in zip(ends, ends[1:]):
            n = int(abs(b - a) / (0.2 * dt))
            for k in range(n):
                x = a + (b - a) * k / n
                f = 0.0 if gap and gap[0] <= t < gap[1] else force
                out.append((t, f, [x, beside, 0.5]))
                t += dt
        return out

    def test_contact_path_counts_end_to_end_passes(self):
        three = self.strokes([-0.08, 0.08, -0.08, 0.08])
        out = self.judge([self.WIPE], contact=three)
        self.assertTrue(out["success"], out["reason"])
        self.assertEqual(out["rules"][0]["passes"], 3)
        self.assertFalse(
            self.judge([self.WIPE], contact=self.strokes([-0.08, 0.08, -0.08]))["success"])
        # each end within 2 cm: 6.5 cm short of an end misses it
        short = self.strokes([-0.08, 0.055, -0.08, 0.055])
        self.assertLess(self.judge([self.WIPE], contact=short)["rules"][0]["passes"], 3)
        near_ends = self.strokes([-0.065, 0.065, -0.065, 0.065])
        self.assertTrue(self.judge([self.WIPE], contact=near_ends)["success"])

    def test_contact_must_be_sustained_pressed_and_on_the_path(self):
        light = self.strokes([-0.08, 0.08, -0.08, 0.08], force=1.9)
        self.assertIn("never in contact", self.judge([self.WIPE], contact=light)["reason"])
        aside = self.strokes([-0.08, 0.08, -0.08, 0.08], beside=0.021)
        self.assertFalse(self.judge([self.WIPE], contact=aside)["success"])
        bridged = self.strokes([-0.08, 0.08, -0.08, 0.08], gap=(1.0, 1.25))  # a 0.25 s break
        self.assertTrue(self.judge([self.WIPE], contact=bridged)["success"])
        # lifted for 0.4 s mid-wipe
        broken = self.strokes([-0.08, 0.08, -0.08, 0.08], gap=(1.0, 1.4))
        self.assertFalse(self.judge([self.WIPE], contact=broken)["success"])

    def test_bad_rules_are_refused(self):
        for bad, says in (({"rule": "teleport"}, "expected"),
                          ({"rule": "height", "object": "block"}, "minimum or a maximum"),
                          ({"rule": "joint", "joint": "lid", "min": 0}, "not a joint"),
                          ({"rule": "object_at_goal", "object": "mug", "distance": "xy",
                            "tolerance_m": 0.1}, "mug"),
                          (dict(self.WIPE, passes="3"), "passes must be a number"),
                          (dict(self.WIPE, speed=1), "unknown key")):
            with self.assertRaisesRegex(ValueError, says):
                judge.check_rule(bad, {"block"}, ["drawer_slide"])


class CriteriaFromTheTaskFiles(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp()
        os.environ[tasks.TASKS_PATH_VAR] = self.folder

    def tearDown(self):
        del os.environ[tasks.TASKS_PATH_VAR]
        shutil.rmtree(self.folder)

    def write(self, name, content):
        with open(os.path.join(self.folder, name + ".yaml"), "w") as f:
            yaml.safe_dump(content, f)

    def shipped(self, name):
        return config.load_yaml(os.path.join(config.config_path("tasks"), name + ".yaml"))

    def test_the_shipped_files_are_what_the_judges_read(self):
        grasp = tasks.success_criterion("grasp")
        self.assertEqual((grasp["object"], grasp["distance"], grasp["min_lift_m"]),
                         ("stick", "xyz", 0.10))
        self.assertEqual(tasks.segment_names("grasp"), ["approach", "move"])
        self.assertEqual(tasks.expected_transitions("grasp"), GRASP_EXPECTED)
        self.assertEqual(tasks.expected_transitions("push"), PUSH_EXPECTED)
        self.assertEqual(tasks.segment_names("drawer"), ["approach", "pull", "retreat"])
        # the reported body
        self.assertEqual(tasks.success_criterion("drawer")["object"], "drawer_handle")
        # the evaluation protocol is the segmentation's only (criteria, skills: the task files)
        self.assertNotIn("reproduction", config.load_evaluation())
        for t in ("grasp", "push", "place", "wipe", "drawer"):
            self.assertIn(t, tasks.names())
            self.assertGreaterEqual(len(tasks.scenes(t, "sim")), 9, t)
            self.assertGreaterEqual(len(tasks.scenes(t, "teleop")), 6, t)
            for mode in tasks.MODES:
                self.assertEqual(len(tasks.unseen_scenes(t, mode)), 10, t)

    def test_a_task_file_of_ones_own_changes_the_verdict(self):
        strict = self.shipped("grasp")
        strict["success"][0]["tolerance_m"] = 0.01
        self.write("grasp", strict)  # $LFD_TASKS_PATH is searched first
        criteria = tasks.success_criterion("grasp")
        self.assertFalse(judge.physical_outcome(criteria, (0.52, 0, 1.0),
                                                (0.5, 0, 1.0), TABLE)["success"])
        self.assertTrue(judge.physical_outcome(GRASP, (0.52, 0, 1.0),
                                               (0.5, 0, 1.0), TABLE)["success"])

    def test_bad_task_files_are_a_clear_error(self):
        grasp = self.shipped("grasp")
        cases = ((dict(grasp, success=[dict(grasp["success"][0], distance="xz")]),
                  r"success\[0\]: distance"),
                 (dict(grasp, objects=["mug"]),
                  r"objects\[0\]: 'mug' is not an object of the scene"),
                 (dict(grasp, speed=2), "unknown key"),
                 (dict(grasp, configurations={"sim": grasp["configurations"]["sim"]}),
                  "configurations.teleop"),
                 (dict(grasp, configurations={"sim": [{"id": 0, "goal": [0, 0, 0]}], "teleop": []}),
                  r"configurations.sim\[0\].stick: expected a pose"))
        for i, (content, says) in enumerate(cases):
            self.write("bad%d" % i, content)
            with self.assertRaisesRegex(RuntimeError, "bad%d.yaml.*%s" % (i, says)):
                tasks.scenes("bad%d" % i, "sim")
        with self.assertRaisesRegex(RuntimeError, "no task file wipes.yaml"):
            tasks.success_criterion("wipes")


def write_grasp_bag(path, final_z, extra_poses=()):
    """A hand-written grasp demo bag: metadata scene, ground-truth phases and the stick's last pose
    (final_z: where the stick ends, 0.95 = lifted to its goal); extra_poses: (recorded at, header
    stamp, z) of more stick poses."""
    goal = {"position": [0.5, -0.3, 0.95], "orientation": [1.0, 0.0, 0.0, 0.0]}
    extra = {"task": "grasp",
             "scene": {"frame": "world", "objects": {}, "goal": goal, "joints": {}}}
    with rosbag.Bag(path, "w") as b:
        b.write("/lfd/metadata", DemoMetadata(task="grasp", mode="sim", configuration=0, speed=1.0,
                                              extra_json=json.dumps(extra)), rospy.Time(10.0))
        for t, name in ((10.0, "approach"), (12.0, "grasp"), (13.0, "move"), (13.5, "move"),
                        (18.0, "done")):
            b.write("/lfd/phase", Phase(task="grasp", name=name), rospy.Time(t))
        for t, stamp, z in sorted(((10.5, 0.0, TABLE + 0.015), (18.5, 0.0, final_z))
                                  + tuple(extra_poses)):
            p = PoseStamped()
            p.header.stamp = rospy.Time(stamp)
            p.pose.position.x, p.pose.position.y, p.pose.position.z = 0.5, -0.3, z
            p.pose.orientation.w = 1.0
            b.write("/objects/stick/pose", p, rospy.Time(t))
    return path


class RedoDemos(unittest.TestCase):
    """generate_datasets' choice of the demos to record (again), lfd_tools.redo: a bag that is no
    usable demonstration is set aside, never deleted nor overwritten, and recorded again."""

    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.dir)

    def path(self, name):
        return os.path.join(self.dir, name)

    def test_cut_off_failed_and_missing_demos_are_recorded_again(self):
        good = write_grasp_bag(self.path("grasp_sim_00.bag"), 0.95)
        dropped = write_grasp_bag(self.path("grasp_sim_01.bag"), TABLE + 0.015)
        with open(self.path("grasp_sim_01.bag.failed"), "w") as f:
            f.write("an earlier failure")
        with open(self.path("grasp_sim_03.bag"), "wb") as f:  # cut off: half a bag header
            f.write(b"#ROSBAG V2.0\n\x00\x01")
        bag_of = {i: self.path("grasp_sim_%02d.bag" % i) for i in range(4)}
        todo, aside = redo.demos_to_record(bag_of, bags.demo_outcome)
        self.assertEqual(todo, [1, 2, 3])
        self.assertEqual([(c, os.path.basename(p)) for c, p, _ in aside],
                         [(1, "grasp_sim_01.bag.failed.2"), (3, "grasp_sim_03.bag.failed")])
        self.assertIn("above the table 1.5 cm", aside[0][2])
        self.assertIn("unreadable", aside[1][2])
        self.assertTrue(os.path.exists(good))
        self.assertFalse(os.path.exists(dropped))
        with open(self.path("grasp_sim_01.bag.failed")) as f:
            self.assertEqual(f.read(), "an earlier failure")
        self.assertFalse(bags.demo_outcome(aside[0][1])["success"])  # the same bag, kept
        self.assertEqual(bags.list_bags(self.dir), [good])

    def test_each_version_of_a_bag_is_judged_once(self):
        calls = []
        outcomes = redo.Outcomes(lambda p: calls.append(p) or {"success": True})
        bag = write_grasp_bag(self.path("grasp_sim_00.bag"), 0.95)
        self.assertEqual(redo.demos_to_record({0: bag}, outcomes), ([], []))
        outcomes(bag)
        self.assertEqual(len(calls), 1)
        write_grasp_bag(bag, 0.96)
        os.utime(bag, ns=(1, 1))  # a new version, even within the file system's time resolution
        outcomes(bag)
        self.assertEqual(len(calls), 2)


class DemoBagJudged(unittest.TestCase):
    def bag(self, final_z):
        return write_grasp_bag(os.path.join(tempfile.mkdtemp(), "grasp_sim_00.bag"), final_z)

    def test_success_and_failure_from_the_bag(self):
        ok = bags.demo_outcome(self.bag(0.95))
        self.assertTrue(ok["success"], ok["reason"])
        self.assertEqual((ok["task"], ok["mode"]), ("grasp", "sim"))
        dropped = bags.demo_outcome(self.bag(TABLE + 0.015))  # the stick fell back
        self.assertFalse(dropped["success"])
        self.assertAlmostEqual(dropped["height_m"], 0.015)

    def test_a_pose_stamped_out_of_order_is_judged_in_stamp_order(self):
        """Regression (the C++ readers' stamp policy, lfd_tools.stamps): a pose of the stick on the
        table stamped 11 s arrives last, after the lifted one of 18.5 s. By arrival it was the final
        pose (the demo failed); by stamp the demo is judged as the sorted bag, with a warning."""
        folder = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, folder)
        in_order = write_grasp_bag(os.path.join(folder, "in_order.bag"), 0.95,
                                   [(11.0, 11.0, TABLE + 0.015)])
        late = write_grasp_bag(os.path.join(folder, "late.bag"), 0.95,
                               [(19.0, 11.0, TABLE + 0.015)])
        expected, got = bags.demo_outcome(in_order), bags.demo_outcome(late)
        self.assertTrue(expected["success"], expected["reason"])
        self.assertEqual(expected["warnings"], [])
        for key in ("success", "distance_m", "height_m", "reason"):
            self.assertEqual(got[key], expected[key], key)
        self.assertEqual(got["warnings"], ["/objects/stick/pose: of 3 messages, 1 stamped out of "
                                           "order (put in order)"])

    def test_phases_are_taken_in_stamp_order(self):
        folder = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, folder)
        path = os.path.join(folder, "phases.bag")
        with rosbag.Bag(path, "w") as b:
            for t, stamp, name in ((10.0, 10.0, "approach"), (13.0, 13.0, "move"),
                                   (13.1, 12.0, "grasp")):
                b.write("/lfd/phase", Phase(header=Header(stamp=rospy.Time(stamp)),
                                            task="grasp", name=name),
                        rospy.Time(t))
        self.assertEqual(bags.phase_transitions(path)[1],
                         [("approach", 10.0), ("grasp", 12.0), ("move", 13.0)])

    def test_ground_truth_changepoints_start_each_expected_phase(self):
        path = self.bag(0.95)
        self.assertEqual(bags.ground_truth_changepoints(path, GRASP_EXPECTED), [13.0])
        self.assertEqual(bags.phase_transitions(path)[1], [("approach", 10.0), ("grasp", 12.0),
                                                           ("move", 13.0), ("done", 18.0)])
        with self.assertRaisesRegex(RuntimeError, "push"):
            bags.ground_truth_changepoints(path, PUSH_EXPECTED)


class StampPolicy(unittest.TestCase):
    """lfd_tools.stamps on the cases of lfd_core's test_stamp_order.cpp: the same order, counts and
    warnings as the C++ readers."""

    def test_one_late_message_is_moved_and_counted_once(self):
        order, r = stamps.order_by_stamp([0.0, 0.1, 0.75, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8], False)
        self.assertEqual(order, [0, 1, 3, 4, 5, 6, 7, 8, 2, 9])
        self.assertEqual((r["out_of_order"], r["duplicates"]), (1, 0))
        self.assertEqual(stamps.warning("/ee_pose", r),
                         "/ee_pose: of 10 messages, 1 stamped out of order (put in order)")

    def test_duplicates_are_kept_or_left_out_but_always_counted(self):
        kept_all, everything = stamps.order_by_stamp([0.0, 0.1, 0.1, 0.2], True)
        firsts, first = stamps.order_by_stamp([0.0, 0.1, 0.1, 0.2], False)
        self.assertEqual((len(kept_all), firsts), (4, [0, 1, 3]))
        self.assertEqual((everything["duplicates"], everything["dropped"],
                          first["dropped"]), (1, 0, 1))
        self.assertIn("1 with a duplicate stamp (the first of each kept)",
                      stamps.warning("/t", first))

    def test_gaps_are_reported_and_a_regular_clock_says_nothing(self):
        regular = [0.01 * i for i in range(100)]
        self.assertEqual(stamps.warning("/t", stamps.order_by_stamp(regular, True)[1]), "")
        _, r = stamps.order_by_stamp([t + (0.3 if t > 0.5 else 0.0) for t in regular], True)
        self.assertAlmostEqual(r["largest_gap"], 0.31)
        self.assertAlmostEqual(r["gap_start"], 0.5)
        self.assertIn("a gap of 0.31 s at t = 0.5", stamps.warning("/t", r))


class Response(object):
    """An /executor/execute result (lfd_msgs/ExecuteTaskResult) as the records read it."""

    def __init__(self, success=True, execution_time=12.0, planned_duration=10.0, error=""):
        self.success, self.error, self.warnings = success, error, []
        self.execution_time, self.planned_duration = execution_time, planned_duration
        self.planning_time = 0.1
        self.final_position_error, self.final_orientation_error = 0.004, 0.02
        self.segment_durations = [4.0, 6.0]
        self.segment_frames = ["object:stick / object:stick", "goal / goal"]
        self.segment_slope_ridges = [0.001, -1.0]
        self.extrapolation_distance, self.extrapolation_angle = 0.0, 0.0
        self.outside_demo_range = False
        self.monitored, self.max_anomaly_score, self.monitor_alarm = True, 0.4, ""


class Records(unittest.TestCase):
    def test_goal_and_reproduction_records(self):
        good = report.goal_record(100, Response(), {"success": True, "distance_m": 0.01},
                                  demo_duration=8.0)
        self.assertTrue(good["success"])
        self.assertAlmostEqual(good["time_ratio"], 1.5)
        self.assertAlmostEqual(good["overhead_ratio"], 1.2)
        self.assertEqual((good["monitored"], good["max_anomaly_score"], good["monitor_alarm"]),
                         (True, 0.4, ""))
        refused = report.goal_record(101, Response(success=False, error="unreachable"),
                                     # the object happened to be there
                                     {"success": True, "distance_m": 0.0})
        self.assertFalse(refused["success"])
        self.assertIsNone(refused["time_ratio"])
        crashed = report.goal_record(102, error="reset failed")
        r = report.reproduction_record("lib.json", (8.0, 3, 2), [good, refused, crashed])
        self.assertEqual((r["successes"], r["goals_total"]), (1, 3))
        self.assertAlmostEqual(r["success_rate"], 1 / 3)
        # the goal without a pose is left out
        self.assertAlmostEqual(r["mean_object_position_error_m"], 0.005)
        self.assertNotIn("error", r)  # a goal was reached
        none = report.reproduction_record("lib.json", (8.0, 3, 2), [refused, crashed])
        self.assertEqual(none["error"], "reset failed; unreachable")

    def test_ridges_per_segment(self):
        goals = [{"segment_slope_ridges": [0.01, 100.0, 0.1]},
                 {"segment_slope_ridges": [0.01, 100.0, 0.1]},
                 {"segment_slope_ridges": [0.01, -1.0, 0.1]}, {"segment_slope_ridges": []}]
        self.assertEqual(report.ridges_note(goals),
                         " (ridge per segment: 0.01, 100, 0.1 / 0.01, kernel, 0.1)")
        self.assertEqual(report.ridges_note([{}]), "")
        self.assertEqual(report.goal_record(100, Response())["segment_slope_ridges"], [0.001, -1.0])

    def test_segmentation_record(self):
        r = report.segmentation_record({"weighted_product": {"success_rate": 0.5,
                                                             "selected_features": ["f"]},
                                        "average": {"error": "failed"}}, 0.5)
        self.assertEqual(r["success_rate"], 0.5)
        self.assertEqual(r["methods"], {"weighted_product": 0.5, "average": None})
        self.assertEqual(r["selected_features"], ["f"])


def all_tests():
    return unittest.TestSuite([unittest.defaultTestLoader.loadTestsFromTestCase(c) for c in (
        SegmentationRule, SegmentationFigures, PhysicalSuccess, Rules, CriteriaFromTheTaskFiles,
        DemoBagJudged, StampPolicy, RedoDemos, Records)])


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "judge_units", "__main__.all_tests")
