#!/usr/bin/python3
"""rostest: /learner/learn never destroys a file and stays up on any request. Safe paths
(a bag is never overwritten, an existing library only with overwrite, a FIFO is refused at once,
paths outside ~allowed_roots or with '..' are refused), limits (~limits/max_num_basis,
~limits/max_bags), 150 seeded random requests of extreme values (seed 12, about 10 s), and a link
swapped between a bag and a FIFO for 3 s while requests run. Regression: overwrite
replaces only a library lfd wrote; relative paths are refused; overlong strings are refused."""
import hashlib
import math
import os
import random
import shutil
import tempfile
import threading
import time
import unittest

import rosbag
import rospy
import rostest
from geometry_msgs.msg import PoseStamped
from lfd_msgs.srv import LearnSkills, LearnSkillsRequest
from sensor_msgs.msg import JointState

RATE, DURATION, START = 100.0, 4.0, 50.0


def write_demo(path, goal_x):
    with rosbag.Bag(path, "w") as bag:
        for i in range(int(DURATION * RATE)):
            s = i / (DURATION * RATE - 1)
            stamp = rospy.Time.from_sec(START + i / RATE)
            pose = PoseStamped()
            pose.header.stamp = stamp
            pose.pose.position.x = 0.3 + (goal_x - 0.3) * s
            pose.pose.position.y = 0.05 * math.sin(math.pi * s)
            pose.pose.position.z = 0.8 + 0.1 * (s > 0.5)
            pose.pose.orientation.w = 1.0
            bag.write("/ee_pose", pose, stamp)
            grip = JointState()
            grip.header.stamp = stamp
            grip.name = ["R_GRIPPER"]
            grip.position = [0.04 if s < 0.5 else 0.01]
            bag.write("/gripper/state", grip, stamp)


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


class LearnerFuzz(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("learner_fuzz")
        cls.dir = tempfile.mkdtemp(prefix="lfd_learner_fuzz_")
        cls.bags = [os.path.join(cls.dir, "demo%d.bag" % d) for d in range(3)]
        for d, bag in enumerate(cls.bags):
            write_demo(bag, 0.5 + 0.1 * d)
        cls.sentinel = os.path.join(cls.dir, "sentinel.json")
        with open(cls.sentinel, "w") as f:
            f.write("not to be touched\n")
        cls.fifo = os.path.join(cls.dir, "pipe.bag")
        os.mkfifo(cls.fifo)
        cls.digests = {p: digest(p) for p in cls.bags + [cls.sentinel]}
        rospy.wait_for_service("/learner/learn", timeout=60)
        cls.learn = rospy.ServiceProxy("/learner/learn", LearnSkills)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def valid(self, output, **fields):
        req = LearnSkillsRequest(task="grasp", output_path=output, bag_paths=list(self.bags),
                                 changepoint_counts=[1] * 3,
                                 changepoint_times=[START + DURATION / 2] * 3)
        for k, v in fields.items():
            setattr(req, k, v)
        return req

    def call(self, req, timeout=20.0):
        """The call on a thread: a node blocked in open() fails the test instead of hanging it."""
        box = {}
        thread = threading.Thread(target=lambda: box.update(res=self.learn(req)), daemon=True)
        thread.start()
        thread.join(timeout)
        self.assertFalse(thread.is_alive(), "the learner did not answer in %.0f s" % timeout)
        return box["res"]

    def assertRefused(self, res, needle):
        self.assertFalse(res.success)
        self.assertIn(needle, res.error)

    def assertNothingChanged(self, context=""):
        for path, d in self.digests.items():
            self.assertEqual(digest(path), d, "%s changed: %s" % (path, context))

    def test_1_existing_library_is_kept_unless_overwrite(self):
        out = os.path.join(self.dir, "lib.json")
        self.assertTrue(self.call(self.valid(out)).success)
        first = digest(out)
        self.assertRefused(self.call(self.valid(out)), "exists")
        self.assertEqual(digest(out), first)
        res = self.call(self.valid(out, overwrite=True, num_basis=20))
        self.assertTrue(res.success, res.error)
        self.assertNotEqual(digest(out), first)

    def test_2_output_is_never_one_of_the_bags(self):
        self.assertRefused(self.call(self.valid(self.bags[0], overwrite=True)), "inputs")
        self.assertNothingChanged("output_path = a bag")

    def test_3_named_pipe_refused_at_once(self):
        req = self.valid(os.path.join(self.dir, "pipe.json"))
        req.bag_paths[1] = self.fifo
        t0 = time.time()
        self.assertRefused(self.call(req, timeout=10.0), "named pipe")
        self.assertLess(time.time() - t0, 5.0)

    def test_4_roots_and_parent_references(self):
        self.assertRefused(self.call(self.valid("/etc/lfd_fuzz.json")), "allowed_roots")
        self.assertRefused(self.call(self.valid(self.dir + "/../x/lib.json")), "'..'")
        self.assertFalse(os.path.exists("/etc/lfd_fuzz.json"))

    def test_5_limits_are_named(self):
        self.assertRefused(
            self.call(self.valid(os.path.join(self.dir, "b.json"), num_basis=100000)),
            "limits/max_num_basis")
        req = self.valid(os.path.join(self.dir, "many.json"), bag_paths=self.bags * 30,
                         changepoint_counts=[1] * 90,
                         changepoint_times=[START + DURATION / 2] * 90)
        self.assertRefused(self.call(req), "limits/max_bags")

    def test_8_overwrite_replaces_only_a_library_lfd_wrote(self):
        """Regression: overwrite: true replaced any regular file under the roots (a .bashrc)."""
        bashrc = os.path.join(self.dir, ".bashrc")
        with open(bashrc, "w") as f:
            f.write("export PATH=$HOME/bin:$PATH\n")
        before = digest(bashrc)
        res = self.call(self.valid(bashrc, overwrite=True))
        self.assertRefused(res, "was not written by lfd as a skill library")
        self.assertIn(".bashrc", res.error)
        self.assertEqual(digest(bashrc), before)
        out = os.path.join(self.dir, "own.json")
        self.assertTrue(self.call(self.valid(out)).success)
        res = self.call(self.valid(out, overwrite=True, num_basis=20))
        self.assertTrue(res.success, res.error)

    def test_9_relative_paths_are_refused_naming_the_field(self):
        """Regression: a relative path resolved against the node's own working directory."""
        self.assertRefused(self.call(self.valid("relative.json")),
                           "output_path: path 'relative.json' is relative")
        req = self.valid(os.path.join(self.dir, "rel.json"))
        req.bag_paths[1] = "demo1.bag"
        self.assertRefused(self.call(req), "bag_paths[1]: path 'demo1.bag' is relative")
        self.assertFalse(os.path.exists(os.path.join(self.dir, "rel.json")))

    def test_9b_overlong_strings_are_refused_before_any_work(self):
        """Regression: every request string within ~limits/max_request_string_bytes; the error
        quotes at most 200 characters (a 10 MB string was echoed into errors and logs)."""
        t0 = time.time()
        res = self.call(self.valid(os.path.join(self.dir, "long.json"), task="x" * 300000))
        self.assertRefused(res, "task: a string of 300000 bytes, over the limit of 262207 "
                                "(~limits/max_request_string_bytes)")
        self.assertLess(len(res.error), 500)
        self.assertLess(time.time() - t0, 5.0)
        req = self.valid(os.path.join(self.dir, "long.json"), segment_names=["a", "n" * 300000])
        self.assertRefused(self.call(req), "segment_names[1]: a string of 300000 bytes")
        self.assertFalse(os.path.exists(os.path.join(self.dir, "long.json")))

    def test_7_link_swapped_to_fifo_never_hangs(self):
        """Regression: a link swapped between a bag and a FIFO while requests run (3 s) never
        hangs the learner in open() (it checked the path, then opened it again by name). A call
        over 2 s counts as hung; opening the FIFO for writing then lets the node go on."""
        link = os.path.join(self.dir, "race_link.bag")
        os.symlink(self.bags[0], link)
        stop = threading.Event()

        def swap():
            temp, to_fifo = link + ".swap", True
            while not stop.is_set():
                if os.path.lexists(temp):
                    os.remove(temp)
                os.symlink(self.fifo if to_fifo else self.bags[0], temp)
                os.replace(temp, link)
                to_fifo = not to_fifo

        swapper = threading.Thread(target=swap, daemon=True)
        swapper.start()
        calls, hung, answered = 0, 0, 0
        out = os.path.join(self.dir, "race.json")
        end = time.time() + 3.0
        while time.time() < end:
            req = self.valid(out, overwrite=True, bag_paths=[link] + self.bags[1:])
            box = {}
            thread = threading.Thread(target=lambda: box.update(res=self.learn(req)), daemon=True)
            thread.start()
            thread.join(2.0)
            if thread.is_alive():
                hung += 1
                while thread.is_alive():  # let the node's open() of the FIFO return
                    try:
                        os.close(os.open(self.fifo, os.O_WRONLY | os.O_NONBLOCK))
                    except OSError:
                        pass
                    thread.join(0.05)
            calls += 1
            answered += "res" in box
        stop.set()
        swapper.join()
        os.remove(link)
        self.assertEqual(hung, 0, "%d of %d calls hung" % (hung, calls))
        self.assertEqual(answered, calls)
        self.assertTrue(self.call(self.valid(out, overwrite=True)).success)
        self.assertNothingChanged("link swap race")

    def test_6_random_extreme_requests(self):
        rng = random.Random(12)
        numbers = [0.0, -1.0, START, START + 2.0, START + DURATION, 1e300, -1e300, 1e-300,
                   float("inf"), float("-inf"), float("nan")]
        paths = self.bags + [self.fifo, self.dir, "/dev/null", "", os.path.join(self.dir, "no.bag"),
                             self.sentinel, os.path.join(self.dir, "x" * 300 + ".bag"),
                             self.dir + "/../" + os.path.basename(self.dir) + "/demo0.bag"]
        outputs = paths + [os.path.join(self.dir, "fuzz.json"), "/tmp", "relative.json",
                           os.path.join(self.dir, "missing_folder", "l.json")]
        t0, ok = time.time(), 0
        for k in range(150):
            n = rng.randrange(0, 5)
            req = LearnSkillsRequest(task=rng.choice(["grasp", "", "x" * 1000]),
                                     output_path=rng.choice(outputs),
                                     overwrite=rng.random() < 0.5,
                                     bag_paths=[rng.choice(paths) for _ in range(n)],
                                     num_basis=rng.choice([0, -5, 1, 2, 50, 1000, 1001, 2**31 - 1]))
            counts = [rng.randrange(0, 4) for _ in range(n)]
            if rng.random() < 0.2 and counts:
                counts[0] += 1  # counts and times disagree
            req.changepoint_counts = counts
            req.changepoint_times = [rng.choice(numbers) for _ in range(sum(counts))]
            req.segment_names = rng.choice([[], ["a"], ["a", "b"], ["a"] * 100])
            res = self.call(req)
            context = "request %d: %s" % (k, str(req)[:400])
            if res.success:
                ok += 1
                self.assertTrue(os.path.isfile(res.library_path), context)
            else:
                self.assertTrue(res.error, context)
            self.assertNothingChanged(context)
            if os.path.exists(os.path.join(self.dir, "fuzz.json")) and rng.random() < 0.3:
                os.remove(os.path.join(self.dir, "fuzz.json"))
        rospy.loginfo("learner_fuzz: 150 requests, %d learned, %.1f s", ok, time.time() - t0)
        res = self.call(self.valid(os.path.join(self.dir, "final.json"), overwrite=True))
        self.assertTrue(res.success, res.error)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "learner_fuzz", LearnerFuzz)
