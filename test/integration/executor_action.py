#!/usr/bin/python3
"""rostest (executor_action.test): the executor's action on a library learned from a freshly
recorded tiny grasp dataset, the simulation driven in lockstep (lfd_tools.lockstep). Covers an
unseen goal reproduced with its feedback, preemption while moving and while planning, an
out-of-range and an unreachable goal, sim time stopping during the final settle, bad
requests and a seeded fuzz of random and extreme goals; after each the node still answers."""
import copy
import glob
import math
import os
import random
import time
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from lfd_msgs.msg import DemoSegmentation, ExecuteTaskFeedback
from lfd_msgs.srv import LearnSkills
from lfd_tools import bags
from lfd_tools import config, judge, lockstep, reproduction, tasks

TASK = "grasp"
FUZZ_GOALS = 150      # seeded random goals of test_7 (~10 s on the 2-core machine)
FUZZ_SECONDS = 120.0  # its wall-time budget
ANSWER_S = 15.0       # wall s any single refused or dry-run goal may take


def moved(pose, dx=0.0, dy=0.0, dz=0.0):
    p = copy.deepcopy(pose)
    p["position"] = [p["position"][0] + dx, p["position"][1] + dy, p["position"][2] + dz]
    return p


class ExecutorAction(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scene = tasks.unseen_scenes(TASK, "sim")[4]  # id 104, never demonstrated
        cls.parked = tasks.parked(TASK)
        out = rospy.get_param("/executor_test/output_dir")
        summary = os.path.join(out, "demonstrator_summary_%s_sim.yaml" % TASK)
        deadline = time.time() + 300
        while not os.path.exists(summary):
            assert time.time() < deadline, "the demonstrator did not finish the dataset"
            time.sleep(1)
        time.sleep(1)
        recorded = sorted(glob.glob(os.path.join(out, "*.bag")))
        assert len(recorded) == 4, recorded
        # The lockstep client (it pauses the simulation) once the demonstrator is done with it.
        cls.cell = lockstep.Cell(node_name="executor_test")
        cls.library = os.path.join(out, "%s.json" % TASK)
        rospy.wait_for_service("/learner/learn", timeout=120)
        segs = [DemoSegmentation(source=b, changepoint_times=bags.ground_truth_changepoints(
            b, tasks.expected_transitions(TASK))) for b in recorded]
        res = rospy.ServiceProxy("/learner/learn", LearnSkills)(
            task=TASK, output_path=cls.library, segmentations=segs,
            segment_names=tasks.segment_names(TASK))
        assert res.success, res.error
        cls.out = out

    # ---- helpers --------------------------------------------------------------------------------
    def place(self, scene=None):
        scene = scene or self.scene
        self.cell.set_scene(dict(self.parked, **scene["objects"]), 0.3, scene.get("joints"))

    def goal(self, scene=None, **kw):
        return lockstep.execute_goal(self.library, scene or self.scene, **kw)

    def answer(self, goal, timeout=ANSWER_S):
        """Sends a goal and drives it: (result, state); fails the test if it does not end."""
        self.cell.send(goal)
        ended = self.cell.drive(timeout=timeout)
        if not ended:
            self.cell.cancel()
        self.assertTrue(ended, "the goal did not end in %.0f s (feedback %s): %s"
                        % (timeout, self.latest(), goal))
        return self.cell.result()

    def refused(self, goal, *fragments):
        result, state = self.answer(goal)
        self.assertEqual(state, GoalStatus.ABORTED, result.error)
        self.assertFalse(result.success)
        for f in fragments:
            self.assertIn(f, result.error)
        return result

    def assert_alive(self):
        """A valid dry run still succeeds (the node is up and not stuck)."""
        result, state = self.answer(self.goal(dry_run=True))
        self.assertEqual(state, GoalStatus.SUCCEEDED, result.error)
        self.assertTrue(result.success)

    def latest(self):
        return self.cell.feedback[-1] if self.cell.feedback else None

    def in_settle(self):
        """Sim time is 0.1 s past the trajectory's end: the executor settles (0.5 s) from there.
        Decided on the stepped clock, not on feedback that might arrive late."""
        f = self.latest()
        return bool(f and f.state != ExecuteTaskFeedback.PLANNING and
                    self.cell.now() >= f.motion_start.to_sec() + f.planned_duration + 0.1)

    # ---- tests ----------------------------------------------------------------------------------
    def test_1_reproduces_an_unseen_goal_with_feedback(self):
        self.place()
        criterion = tasks.success_criterion(TASK)
        measured = self.cell.record(bags.topics_for(criterion))
        result, wall = self.cell.execute(self.goal())
        self.assertTrue(result.success, result.error)
        self.assertEqual(list(result.segment_names), tasks.segment_names(TASK))
        self.assertEqual(len(result.segment_frames), 2)
        # Learned, not written: the approach ends at the stick (its frame or its heading frame,
        # which these 4 demos tell apart by millimetres), the move at the goal.
        self.assertIn(result.segment_frames[0].split(" / ")[0], ("object:stick", "heading:stick"))
        self.assertTrue(result.segment_frames[1].startswith("goal"), result.segment_frames)
        # Each segment's local linear fit, its ridge chosen by leave-one-out among executor.yaml's.
        executor = config.load_yaml(config.config_path("executor.yaml"))
        candidates = executor["generalization"]["slope_ridge_candidates"]
        self.assertEqual(len(result.segment_slope_ridges), 2)
        for ridge in result.segment_slope_ridges:
            self.assertIn(ridge, candidates)
        self.assertGreater(result.motion_start.to_sec(), 0.0)
        self.assertAlmostEqual(sum(result.segment_durations), result.planned_duration, places=6)
        # It reached the end (the TCP may settle on the last sample: equal, as sampled). The
        # execution time is a difference of sim clocks (whole ns), the planned duration a sum of
        # durations: equal times differ by rounding (CI: 8.664 against 8.664000000000001).
        self.assertGreaterEqual(result.execution_time, result.planned_duration - 1e-6)
        self.assertLess(result.execution_time, 1.05 * result.planned_duration + 0.1)
        self.assertLess(result.final_position_error, 0.005)
        self.assertLess(result.extrapolation_distance, 0.05)
        # Feedback and result travel on separate topics: the executor publishes SETTLING, then the
        # result once the settle is over, which a loaded machine may deliver first (the executor's
        # loop stalled while the client stepped past the settle: both within a millisecond).
        # The last feedback, sent as the settle ends, holds the final measured progress.
        deadline = time.time() + 2.0
        while (not any(f.state == ExecuteTaskFeedback.SETTLING and f.progress > 0.99
                       for f in self.cell.feedback)
               and time.time() < deadline):
            time.sleep(0.01)
        fb = self.cell.feedback
        states = [f.state for f in fb]
        for s in (ExecuteTaskFeedback.PLANNING, ExecuteTaskFeedback.MOVING,
                  ExecuteTaskFeedback.SETTLING):
            self.assertIn(s, states)
        self.assertEqual(sorted({f.segment for f in fb if f.state != ExecuteTaskFeedback.PLANNING}),
                         sorted(tasks.segment_names(TASK)))
        progress = [f.progress for f in fb if f.state == ExecuteTaskFeedback.MOVING]
        self.assertEqual(progress, sorted(progress))
        self.assertGreater(fb[-1].progress, 0.99)
        self.assertLess(max(f.tcp_position_error for f in fb), 0.01)  # tracked the plan
        self.assertEqual(fb[-1].motion_start, result.motion_start)
        self.cell.advance(1.0)
        self.assertTrue(measured.wait_until(self.cell.now()))
        measured.close()
        outcome = judge.judge_rules(criterion, bags.measure(measured, criterion,
                                                            tasks.base_in_world()),
                                    self.scene, tasks.table_top())
        self.assertTrue(outcome["success"], outcome["reason"])

    def test_8_follows_the_stick_moved_during_the_approach(self):
        """The stick is moved 5 cm while the hand approaches it (/bridge/inject_fault
        move_object, a third into the approach). Given the stick's pose in its own tf frame, the
        executor follows it: the rest of the motion is planned anew toward where it is, and the
        grasp still succeeds. Given it in the world frame (fixed), the same move is not followed,
        and the task fails: what following is for."""
        from lfd_msgs.srv import InjectFault, InjectFaultRequest
        inject = rospy.ServiceProxy("/bridge/inject_fault", InjectFault)
        dry, _ = self.answer(self.goal(dry_run=True))
        at = 0.35 * dry.segment_durations[0]
        shifted = lockstep.pose_msg(moved(self.scene["objects"]["stick"], dx=0.04, dy=-0.03))

        def move_stick(feedback):
            r = inject(InjectFaultRequest(kind="move_object", target="stick", pose=shifted,
                                          at_time=feedback.motion_start.to_sec() + at))
            self.assertTrue(r.success, r.message)
        outcomes = {}
        for follow in (True, False):
            res, _, outcome = reproduction.execute_and_judge(
                self.cell, TASK, self.scene, self.library, on_moving=move_stick, follow=follow)
            outcomes[follow] = (res, outcome, list(self.cell.feedback))
        followed, judged, feedback = outcomes[True]
        self.assertTrue(followed.success, followed.error)
        self.assertEqual(len(followed.replans), 1, followed.replans)
        self.assertIn("object 'stick' moved 5.00 cm", followed.replans[0])
        self.assertIn(ExecuteTaskFeedback.REPLANNING, [f.state for f in feedback])
        # The arm tracked the plan it was following throughout (0.3 mm measured; 11 mm once with
        # two rostests and their simulations sharing the 2-core machine), up to a recovery if
        # the grasp of the moved stick slipped (then the arm leaves the plan on purpose: back to
        # the approach's start, seen twice in 6 local runs). A plan that jumped to the moved
        # stick instead of following it smoothly would be 5 cm off.
        recovering = [k for k, f in enumerate(feedback)
                      if f.state == ExecuteTaskFeedback.RECOVERING]
        tracked = feedback[:recovering[0]] if recovering else feedback
        self.assertLess(max(f.tcp_position_error for f in tracked), 0.02)
        self.assertTrue(judged["success"], judged["reason"])
        self.assertLess(followed.final_position_error, 0.005)
        fixed, judged, _ = outcomes[False]
        self.assertEqual(list(fixed.replans), [])
        self.assertFalse(judged["success"], "the stick moved 5 cm and the grasp still held")
        # Unfollowed, the hand closes where the stick was. Either it closes on nothing and the
        # motion ends (the judge fails it), or the pads catch the stick's end, the grasp slips
        # in the carry, and the retries (at the same fixed pose) fail the goal explained.
        if not fixed.success:
            self.assertIn("the grasp was lost", fixed.error)
            self.assertGreater(len(fixed.recoveries), 0, fixed.error)

    def drop_stick(self, for_s, grip=0.0, lands_at=None):
        """on_moving callback: the grip's force drops to `grip` (a fraction) a third into the carry
        ('move'), and comes back `for_s` s later (None: never). lands_at: the stick is then put
        down at this pose (scene format), at rest, 0.4 s after the drop."""
        from lfd_msgs.srv import InjectFault, InjectFaultRequest
        inject = rospy.ServiceProxy("/bridge/inject_fault", InjectFault)
        dry, _ = self.answer(self.goal(dry_run=True))
        at = dry.segment_durations[0] + 0.3 * dry.segment_durations[1]
        self.assertTrue(dry.monitored, "the library has no sensory signature")

        def drop(feedback):
            start = feedback.motion_start.to_sec()
            faults = [(at, grip)] + ([(at + for_s, 1.0)] if for_s is not None else [])
            for t, value in faults:
                r = inject(InjectFaultRequest(kind="weaken_grip", value=value, at_time=start + t))
                self.assertTrue(r.success, r.message)
            if lands_at is not None:
                r = inject(InjectFaultRequest(kind="move_object", target="stick",
                                              pose=lockstep.pose_msg(lands_at),
                                              at_time=start + at + 0.4))
                self.assertTrue(r.success, r.message)
        return drop

    def test_9_picks_the_dropped_stick_up_again(self):
        """The stick slips out of the hand during the carry (the grip's force gone for 0.5 s).
        The monitor finds the pads unloaded; the executor opens the gripper, goes back to the start
        of the approach, looks at the stick where it now lies (its own tf frame) and grasps it
        again: the task succeeds (within recovery/max_attempts retries), and the result says how
        it recovered. The fallen stick is put down flat 2 cm from where it was picked up: how a
        falling stick bounces is chaotic (it landed on its end, out of the demonstrated range, or
        against the table's edge in some runs), and this test is about the recovery, not the
        fall; bench_faults.py's grasp_dropped lets it fall freely."""
        stick = self.scene["objects"]["stick"]
        lands_at = moved(stick, dy=0.02)
        res, _, outcome = reproduction.execute_and_judge(
            self.cell, TASK, self.scene, self.library,
            on_moving=self.drop_stick(0.5, lands_at=lands_at), follow=True)
        self.assertTrue(res.success, res.error)
        # Any retries up to the bound: a re-grasp may slip once more.
        attempts = rospy.get_param("/executor/recovery/max_attempts")
        self.assertTrue(1 <= len(res.recoveries) <= attempts, res.recoveries)
        self.assertIn("the grasp was lost", res.recoveries[0])
        self.assertIn("went back to the start of segment 'approach'", res.recoveries[0])
        # The goal's first alarm: the drop, or a reported touch of the approach before it.
        self.assertTrue(res.monitor_alarm)
        self.assertIn(ExecuteTaskFeedback.RECOVERING, [f.state for f in self.cell.feedback])
        self.assertTrue(outcome["success"], outcome["reason"])

    def lost_for_good(self, grip):
        """The goal with the grip weakened to `grip` from a third into the carry on, for good:
        its result (the grip restored after)."""
        from lfd_msgs.srv import InjectFault, InjectFaultRequest
        drop = self.drop_stick(None, grip)
        self.place()
        res, _ = self.cell.execute(self.goal(follow=True), on_moving=drop)
        restored = rospy.ServiceProxy("/bridge/inject_fault", InjectFault)(
            InjectFaultRequest(kind="weaken_grip", value=1.0, at_time=0.0))
        self.assertTrue(restored.success, restored.message)
        self.assertFalse(res.success)
        self.assertIn("the arm holds", res.error)
        return res

    def test_10_a_grasp_lost_for_good_fails_explained(self):
        """A grip too weak to hold the stick, for good: every retry drops it again. After
        recovery/max_attempts retries (or once the weak gripper fails to open) the goal fails,
        saying so, the arm holding. A grip with no
        force at all cannot even open the gripper: no retry, and the goal says why. The node then
        answers the next goal."""
        attempts = rospy.get_param("/executor/recovery/max_attempts")
        weak = self.lost_for_good(0.1)
        # A tenth of the grip opens the gripper within release_time in most runs, not in all: then
        # the retries end early (at the first lost grasp in one local run of ten), explained as a
        # gripper that does not open. Or the dropped stick lies where no retry can be planned
        # (outside the demonstrated range: a fresh root, 1 run): explained as such.
        self.assertLessEqual(len(weak.recoveries), attempts, weak.recoveries)
        if len(weak.recoveries) == attempts:
            self.assertIn("the grasp was lost after %d recoveries" % attempts, weak.error)
        else:
            self.assertTrue(any(why in weak.error for why in (
                "the gripper does not open", "the retry cannot be planned")), weak.error)
        dead = self.lost_for_good(0.0)
        self.assertEqual(list(dead.recoveries), [])
        self.assertIn("the gripper does not open", dead.error)
        self.assert_alive()

    def test_2_preempted_while_moving_then_answers(self):
        self.place()
        self.cell.send(self.goal(duration_scale=2.0))
        self.assertTrue(
            self.cell.drive(until=lambda: self.latest() and self.latest().progress > 0.3))
        self.assertFalse(self.cell.done())
        self.cell.cancel()
        cancelled = time.time()
        while not self.cell.done() and time.time() - cancelled < 10.0:
            time.sleep(0.005)  # not stepping: the cancel is served without sim time moving
        result, state = self.cell.result()
        self.assertEqual(state, GoalStatus.PREEMPTED, result.error)
        self.assertIn("preempted", result.error)
        self.assertIn("the arm holds there", result.error)
        # Served without sim time moving (the plan had ~10 s of it left); the bound leaves room
        # for a loaded 2-core CI machine, a cancel that waits for the motion never comes.
        self.assertLess(time.time() - cancelled, 5.0)
        self.assert_alive()

    def cancel_while_planning(self):
        """(result, state, wall s from the cancel to the end) of a goal cancelled while the
        executor plans it."""
        self.cell.send(self.goal(duration_scale=10.0))  # the longest plan the limits allow
        self.assertTrue(self.cell.drive(until=lambda: self.cell.feedback, timeout=10.0))
        self.cell.cancel()  # active and planning (~0.15 s of IK for 87 s of motion)
        started = time.time()
        self.assertTrue(self.cell.drive(timeout=10.0))
        result, state = self.cell.result()
        return result, state, time.time() - started

    def test_3_preempted_while_planning(self):
        self.place()
        result, state, seconds = self.cancel_while_planning()
        if state == GoalStatus.LOST:
            # Seen once in a fresh root (2026-11-30): the executor logged the preemption, but
            # actionlib's Python client marked the goal LOST (a status array without it arrived
            # while it was active) and kept no result. An open question about the status
            # publishing, not about the preemption this test checks: it is tried once more, and a
            # second LOST fails.
            rospy.logwarn("executor_action: the cancelled goal was marked LOST; once more")
            self.place()
            result, state, seconds = self.cancel_while_planning()
        self.assertEqual(state, GoalStatus.PREEMPTED,
                         result.error if result else "no result (status %d)" % state)
        if "cancelled while planning" in result.error:
            self.assertEqual(result.motion_start.to_sec(), 0.0)  # nothing was sent
        else:
            # The plan takes ~0.15 s of wall time; on a loaded machine (a fresh-root CI run,
            # 2026-11-30) the cancel arrived just after it: then it is served before the motion
            # starts, the arm held where it stands.
            self.assertIn("preempted at t=-", result.error)
        self.assertLess(seconds, 5.0)
        self.assert_alive()

    def test_4_out_of_range_and_unreachable_goals(self):
        far = {"objects": {"stick": moved(self.scene["objects"]["stick"], 0.3, 0.25)},
               "goal": moved(self.scene["goal"], 0.3, 0.25)}
        result = self.refused(self.goal(far), "outside the demonstrated range",
                              "allow_extrapolation")
        self.assertTrue(result.outside_demo_range)
        self.assertGreater(result.extrapolation_distance, 0.1)  # reported with the refusal
        self.assertEqual(result.motion_start.to_sec(), 0.0)  # nothing moved
        result, state = self.answer(self.goal(far, allow_extrapolation=True, dry_run=True))
        self.assertEqual(state, GoalStatus.SUCCEEDED, result.error)
        self.assertTrue(result.outside_demo_range)
        self.assertGreater(result.extrapolation_distance, 0.1)
        self.assertTrue(any("kernel average" in w for w in result.warnings), result.warnings)
        unreachable = {"objects": {"stick": moved(self.scene["objects"]["stick"], 0.9)},
                       "goal": moved(self.scene["goal"], 0.9)}  # 1.3 m in front of the pelvis
        self.refused(self.goal(unreachable, allow_extrapolation=True), "unreachable")
        self.assert_alive()

    def test_5_sim_time_stopping_during_the_settle_fails_the_goal(self):
        # Regression: the call never returned, cancel did nothing, later requests were refused
        # "busy", and when time resumed it reported success.
        self.place()
        self.cell.send(self.goal())
        self.assertTrue(self.cell.drive(until=self.in_settle))
        stopped = time.time()
        while not self.cell.done() and time.time() - stopped < 10.0:
            time.sleep(0.01)  # no stepping: sim time stands still
        result, state = self.cell.result()
        self.assertEqual(state, GoalStatus.ABORTED)
        self.assertFalse(result.success)
        self.assertIn("sim time stopped", result.error)
        self.assertLess(time.time() - stopped, 4.0)  # ~clock_timeout (2 s in the test launch)
        # A cancel during a stopped settle is served at once.
        self.place()
        self.cell.send(self.goal())
        self.assertTrue(self.cell.drive(until=self.in_settle))
        cancelled = time.time()
        self.cell.cancel()
        while not self.cell.done() and time.time() - cancelled < 10.0:
            time.sleep(0.01)
        result, state = self.cell.result()
        self.assertEqual(state, GoalStatus.PREEMPTED, result.error)
        self.assertLess(time.time() - cancelled, 5.0)  # sim time stands still: else never
        self.assert_alive()  # and nothing is "busy"

    def test_6_bad_requests_are_clear_errors(self):
        g = self.goal(dry_run=True)
        cases = []

        def case(fragment, edit):
            goal = copy.deepcopy(g)
            edit(goal)
            cases.append((fragment, goal))

        def quaternion(goal, w, x, y, z):
            goal.goal.pose.orientation.w, goal.goal.pose.orientation.x = w, x
            goal.goal.pose.orientation.y, goal.goal.pose.orientation.z = y, z

        case("zero quaternion", lambda x: quaternion(x, 0, 0, 0, 0))
        case("norm 2", lambda x: quaternion(x, 2 * math.cos(0.15), 0, 0, 2 * math.sin(0.15)))
        case("NaN", lambda x: setattr(x.goal.pose.position, "x", float("nan")))
        case("workspace", lambda x: setattr(x.goal.pose.position, "x", 1e11))
        for scale in (1e-9, 1000.0, -1.0, float("inf")):
            case("~limits/min_duration_scale", lambda x, s=scale: setattr(x, "duration_scale", s))
        case("named twice", lambda x: (x.object_names.append("stick"),
                                       x.object_poses.append(x.object_poses[0])))
        case("empty", lambda x: setattr(x, "object_names", [""]))
        case("object names but", lambda x: x.object_poses.append(x.object_poses[0]))
        case("no transform", lambda x: setattr(x.goal.header, "frame_id", "nowhere"))
        case("frame_id", lambda x: setattr(x.goal.header, "frame_id", ""))
        case("no object 'stick'",
             lambda x: (setattr(x, "object_names", []), setattr(x, "object_poses", [])))
        case("library is empty", lambda x: setattr(x, "library", ""))
        case("missing.json",
             lambda x: setattr(x, "library", os.path.join(self.out, "missing.json")))
        case("~limits/max_name_length", lambda x: setattr(x, "library", "x" * 5000))
        # Regression: a library path must be absolute (the node's working directory is not the
        # caller's).
        case("library: path 'libraries/grasp.json' is relative",
             lambda x: setattr(x, "library", "libraries/grasp.json"))
        # Regression: every goal string within ~limits/max_request_string_bytes before any work,
        # quoted short.
        case("library: a string of 300000 bytes, over the limit of 262207 "
             "(~limits/max_request_string_bytes)", lambda x: setattr(x, "library", "x" * 300000))
        case("object_names[0]: a string of 300000 bytes",
             lambda x: setattr(x, "object_names", ["s" * 300000]))
        old = os.path.join(self.out, "version1.json")
        with open(old, "w") as f:
            f.write('{"format": "lfd_skill_library", "version": 1, "segments": []}')
        case("relearn", lambda x: setattr(x, "library", old))
        for fragment, goal in cases:
            with self.subTest(fragment=fragment):
                self.refused(goal, fragment)
        self.assert_alive()

    def test_7_fuzz_random_and_extreme_goals(self):
        """Seeded random goals: each ends within ANSWER_S with a sane success or a clear error,
        and the whole run stays within FUZZ_SECONDS; the node answers at the end."""
        rng = random.Random(12)
        extremes = [0.0, -0.0, 1e-300, 1e300, -1e300, float("nan"), float("inf"),
                    -float("inf"), 1e-9, 7.0]
        started = time.time()
        succeeded = 0
        for i in range(FUZZ_GOALS):
            goal = self.goal(dry_run=rng.random() < 0.95)
            for p in [goal.goal] + list(goal.object_poses):
                if rng.random() < 0.3:
                    setattr(p.pose.position, rng.choice("xyz"),
                            rng.choice(extremes + [rng.uniform(-3, 3)]))
                if rng.random() < 0.2:
                    setattr(p.pose.orientation, rng.choice("wxyz"),
                            rng.choice(extremes + [rng.uniform(-2, 2)]))
                if rng.random() < 0.02:  # an unknown frame costs ~tf_timeout
                    p.header.frame_id = rng.choice(["", "base_link", "nowhere", "w" * 300])
            if rng.random() < 0.2:
                goal.duration_scale = rng.choice(extremes + [rng.uniform(0.05, 12)])
            if rng.random() < 0.1:
                goal.object_names = rng.choice([[], ["stick", "stick"], ["box"],
                                                ["s" * 1000], [""]])
                goal.object_poses = goal.object_poses[:1] * len(goal.object_names)
            if rng.random() < 0.05:
                goal.library = rng.choice(["", "/", "../x", "/dev/zero", "grasp", "\0"])
            goal.allow_extrapolation = rng.random() < 0.3
            if not goal.dry_run:
                self.place()
            t_goal = time.time()
            result, state = self.answer(goal, timeout=ANSWER_S if goal.dry_run else 60.0)
            rospy.loginfo("fuzz goal %d: state %d in %.2f s: %s", i, state, time.time() - t_goal,
                          result.error if result else None)
            self.assertIn(state, (GoalStatus.SUCCEEDED, GoalStatus.ABORTED), "goal %d" % i)
            if state == GoalStatus.SUCCEEDED:
                succeeded += 1
                self.assertTrue(result.success)
                self.assertTrue(all(math.isfinite(v) for v in
                                    [result.planned_duration, result.extrapolation_distance]))
                self.assertGreater(result.planned_duration, 0.0)
            else:
                self.assertFalse(result.success)
                self.assertTrue(result.error, "goal %d failed without an error" % i)
        elapsed = time.time() - started
        rospy.loginfo("fuzz: %d goals, %d succeeded, %.1f s", FUZZ_GOALS, succeeded, elapsed)
        self.assertLess(elapsed, FUZZ_SECONDS)
        self.assertGreater(succeeded, 0)  # the fuzz also reached planning, not only refusals
        self.assert_alive()


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "executor_action", ExecutorAction)
