#!/usr/bin/python3
"""rostest (round two): the two task file loaders, lfd_sim_bridge's (the demonstrator's,
run as check_task) and lfd_tools.tasks (the scripts'), on bad files. Each refuses a NaN pose, a
nesting deeper than the scene's task_limits/max_nesting_depth (PyYAML died of a RecursionError)
and a time over its max_step_seconds (a step of 1e9 s recorded without end) with an error naming
the file.
Then every shipped task file (config/tasks/*.yaml) mutated MUTANTS_PER_FILE times (seed 23: byte
flips, truncation, deleted and repeated lines, huge numbers, NaN and infinities, deep nesting,
wrong types, bytes that are not UTF-8, a BOM) goes through both: neither crashes, hangs or raises
anything but its clear error, and both accept or both refuse. ~30 s. Master-free."""
import os
import random
import re
import shutil
import subprocess
import tempfile
import unittest

import rostest
from catkin.find_in_workspaces import find_in_workspaces
from lfd_tools import config, tasks

SEED = 23
MUTANTS_PER_FILE = 40
TIMEOUT_S = 10.0  # one small file: anything slower is a hang
NUMBER = re.compile(rb"(?<![\w.])-?\d+\.\d+(?![\w.])")


def check_task():
    return find_in_workspaces(search_dirs=["libexec"], project="lfd_sim_bridge",
                              path="check_task")[0]


def cpp_verdict(path):
    """(accepted, error text) of the demonstrator's loader; fails the test on a crash or a hang."""
    done = subprocess.run([check_task(), "--scene", tasks.scene_file(), path],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S,
                          universal_newlines=True, errors="replace")
    if done.returncode not in (0, 1):
        raise AssertionError("check_task ended with status %d on %s: %s"
                             % (done.returncode, path, done.stderr))
    return done.returncode == 0, done.stderr.strip()


def python_verdict(path):
    """(accepted, error text) of lfd_tools.tasks; anything but its RuntimeError fails the test."""
    try:
        tasks.read_task_file(path)
        return True, ""
    except RuntimeError as exc:
        return False, str(exc)


# ---- mutations: bytes in, bytes out, each drawn from `rng` ---------------------------------------

def flip_bytes(data, rng):
    data = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        data[rng.randrange(len(data))] = rng.randrange(256)
    return bytes(data)


def truncate(data, rng):
    return data[:rng.randrange(len(data))]


def delete_line(data, rng):
    lines = data.split(b"\n")
    del lines[rng.randrange(len(lines))]
    return b"\n".join(lines)


def repeat_line(data, rng):
    lines = data.split(b"\n")
    k = rng.randrange(len(lines))
    return b"\n".join(lines[:k + 1] + lines[k:])


def replace_number(data, rng, values):
    found = list(NUMBER.finditer(data))
    m = rng.choice(found)
    return data[:m.start()] + rng.choice(values) + data[m.end():]


def huge_number(data, rng):
    return replace_number(data, rng, [b"1e9", b"1.0e+9", b"-1.0e+300", b"1.0e+308", b"1e999",
                                      b"123456789012345678901234567890"])


def not_finite(data, rng):
    return replace_number(data, rng, [b".nan", b".NaN", b".inf", b"-.inf", b"nan", b"inf"])


def wrong_type(data, rng):
    return replace_number(data, rng, [b"abc", b"[1, 2]", b"{a: 1}", b"true", b"''", b"~"])


def deep_nesting(data, rng):
    depth = rng.choice([17, 100, 1000, 100000])
    nest = b"[" * depth + b"]" * depth
    lines = data.split(b"\n")
    k = rng.randrange(len(lines))
    if rng.random() < 0.5:
        return b"\n".join(lines[:k] + [b"description: " + nest] + lines[k + 1:])
    return replace_number(data, rng, [nest])


def not_utf8(data, rng):
    k = rng.randrange(len(data))
    return data[:k] + rng.choice([b"\xff", b"\xc3\x28", b"\xe2\x82",
                                  b"\x80abc", b"\x00"]) + data[k:]


def bom(data, rng):
    return b"\xef\xbb\xbf" + data


MUTATIONS = [flip_bytes, truncate, delete_line, repeat_line, huge_number, not_finite, wrong_type,
             deep_nesting, not_utf8, bom]


class LoadersRefuse(unittest.TestCase):
    """Items of the probe: both loaders refuse, naming the file (and the key where there is one)."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="lfd_task_loaders_")
        with open(os.path.join(config.config_path("tasks"), "grasp.yaml")) as f:
            self.grasp = f.read()

    def tearDown(self):
        shutil.rmtree(self.dir)

    def refused_by_both(self, text, says):
        path = os.path.join(self.dir, "bad.yaml")
        with open(path, "w") as f:
            f.write(text)
        for name, verdict in (("check_task", cpp_verdict), ("lfd_tools.tasks", python_verdict)):
            accepted, error = verdict(path)
            self.assertFalse(accepted, "%s accepted: %s" % (name, says))
            self.assertIn(path, error, name)
            self.assertRegex(error, says, name)

    def first_sim_configuration(self, pose):
        return re.sub(r"(configurations:\n  sim:\n    - \{id: 0, stick: )\[[^\]]*\]",
                      r"\g<1>" + pose, self.grasp, 1)

    def test_a_nan_pose(self):
        text = self.first_sim_configuration("[0.5, .nan, 0.815, 0.1]")
        self.assertNotEqual(text, self.grasp)
        self.refused_by_both(text, r"configurations.sim\[0\].stick\[1\]: is not finite")

    def test_deep_nesting(self):
        for depth in (17, 100000):
            nest = "[" * depth + "]" * depth
            text = re.sub(r"^description: .*$", "description: " + nest, self.grasp, 1, flags=re.M)
            self.refused_by_both(text, "nested deeper than 16")

    def test_a_step_of_1e9_seconds(self):
        text = self.grasp.replace("duration: 2.0", "duration: 1.0e+9", 1)
        self.assertNotEqual(text, self.grasp)
        self.refused_by_both(text, r"phases\[0\].steps\[\d\].duration: .* is over 120")

    def test_a_hold_or_a_settle_of_1e9_seconds(self):
        self.refused_by_both(self.grasp.replace("settle: 0.3", "settle: 1.0e+9", 1),
                             "settle: .* is over 120")

    def test_a_contact_rule_with_a_gap_of_1e9_seconds(self):
        with open(os.path.join(config.config_path("tasks"), "wipe.yaml")) as f:
            wipe = f.read()
        text = re.sub(r"max_gap_s: [0-9.]+", "max_gap_s: 1.0e+9", wipe, 1)
        self.assertNotEqual(text, wipe)
        path = os.path.join(self.dir, "wipe.yaml")
        with open(path, "w") as f:
            f.write(text)
        with self.assertRaisesRegex(RuntimeError,
                                    re.escape(path) + r".*success\[0\]: max_gap_s: .* is over 120"):
            tasks.read_task_file(path)


class TaskFileFuzz(unittest.TestCase):
    def test_mutated_shipped_files_in_both_loaders(self):
        rng = random.Random(SEED)
        folder = tempfile.mkdtemp(prefix="lfd_task_fuzz_")
        self.addCleanup(shutil.rmtree, folder)
        counts, disagreements = {"accepted": 0, "refused": 0}, []
        for source in sorted(os.listdir(config.config_path("tasks"))):
            if not source.endswith(".yaml"):
                continue
            with open(os.path.join(config.config_path("tasks"), source), "rb") as f:
                original = f.read()
            for k in range(MUTANTS_PER_FILE):
                mutation = MUTATIONS[k % len(MUTATIONS)]
                path = os.path.join(folder, "%s_%02d_%s.yaml" % (source[:-5], k, mutation.__name__))
                with open(path, "wb") as f:
                    f.write(mutation(original, rng))
                cpp, cpp_error = cpp_verdict(path)
                py, py_error = python_verdict(path)
                counts["accepted" if cpp else "refused"] += 1
                if not cpp:
                    self.assertIn(path, cpp_error)
                if not py:
                    self.assertIn(path, py_error)
                # The success criterion is the judge's alone (the demonstrator never judges): a bad
                # rule is the one thing only the scripts' loader refuses.
                if cpp != py and not (cpp and re.search(r": success(\[\d+\])?: ", py_error)):
                    disagreements.append("%s: check_task %s, lfd_tools.tasks %s" % (
                        path, cpp_error or "accepts", py_error or "accepts"))
        print("task file fuzz: %(accepted)d mutants accepted, %(refused)d refused by both loaders"
              % counts)
        self.assertEqual(disagreements, [])
        self.assertGreater(counts["accepted"], 0)  # a BOM, a repeated comment line, ...
        self.assertGreater(counts["refused"], counts["accepted"])


def all_tests():
    return unittest.TestSuite([unittest.defaultTestLoader.loadTestsFromTestCase(c)
                               for c in (LoadersRefuse, TaskFileFuzz)])


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "task_file_fuzz", "__main__.all_tests")
