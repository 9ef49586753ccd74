#!/usr/bin/python3
"""rostest (cli_byte_fuzz.test): the master-free CLIs on fuzzed bytes. Seeded mutations
of a valid demo CSV go through `segment`, of a valid trajectory CSV through `dmp_tool learn`, and of
a valid skill library JSON through `dmp_tool info` and `dmp_tool rollout`: byte flips, truncation,
NUL and non-UTF-8 bytes, UTF-8 and UTF-16 byte-order marks, a 2 MB field, a 2 MB header, a
thousand columns, 1e308 and NaN numbers, CRLF line ends, deleted and duplicated lines, deep JSON
nesting. Every run must end by itself within its time limit with exit status 0 (and a readable
output file) or 1-2 and a short error on stderr: never a signal (abort, segfault), never a hang,
never an error that echoes more than ~200 characters of the input. Pure subprocesses: no node
(rostest's master is not used). About 150 runs, under a minute."""
import json
import math
import os
import random
import shutil
import subprocess
import tempfile
import unittest

import rostest
from catkin.find_in_workspaces import find_in_workspaces


def executable(package, name):
    """A package's executable, where rosrun finds it."""
    found = find_in_workspaces(project=package, path=name, search_dirs=["libexec"],
                               first_match_only=True)
    if not found:
        raise RuntimeError("%s/%s is not built" % (package, name))
    return found[0]


SEGMENT = executable("lfd_segmentation", "segment")
DMP_TOOL = executable("lfd_dmp", "dmp_tool")
SEED = 23
TIME_LIMIT_S = 20.0
# A message may name the file and quote some of it; 200 characters of input plus the message.
MAX_STDERR_BYTES = 2000
BIG = 2 * 1024 * 1024


def demo_csv(rng, rows=400, rate=100.0):
    """A pose + wrench demo with two contact phases, as `segment` reads it."""
    lines = ["time,x,y,z,fz"]
    for k in range(rows):
        t = k / rate
        contact = 120 <= k < 280
        lines.append("%.4f,%.5f,%.5f,%.5f,%.4f" % (
            t, 0.3 + 0.2 * math.sin(t), 0.1 * t, 0.2 - (0.05 if contact else 0.0),
            (8.0 if contact else 0.0) + rng.gauss(0, 0.2)))
    return ("\n".join(lines) + "\n").encode()


def trajectory_csv(rows=200):
    """A straight reach with a turning hand and a closing gripper, as `dmp_tool learn` reads it."""
    lines = ["t,x,y,z,qw,qx,qy,qz,gripper"]
    for k in range(rows):
        s = k / (rows - 1.0)
        half = 0.25 * math.pi * s
        lines.append("%.3f,%.4f,%.4f,%.4f,%.5f,0,0,%.5f,%.3f" % (
            0.01 * k, 0.3 + 0.2 * s, 0.1, 0.3 - 0.1 * s, math.cos(half), math.sin(half), 1.0 - s))
    return ("\n".join(lines) + "\n").encode()


def mutations(rng, data):
    """(name, bytes): the kinds of damage a user's file or a bad tool gives."""
    lines = data.split(b"\n")
    out = []
    for k in range(6):
        b = bytearray(data)
        for _ in range(rng.randint(1, 20)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        out.append(("flip%d" % k, bytes(b)))
    out += [
        ("truncated", data[: rng.randrange(1, len(data))]),
        ("empty", b""),
        ("nul", data[:50] + b"\x00" * 10 + data[50:]),
        ("non_utf8_header", b"\xff\xfe\xc3(" + data),
        ("non_utf8_field", data.replace(b",", b",\xc3\x28", 3)),
        ("utf8_bom", b"\xef\xbb\xbf" + data),
        ("utf16_bom", b"\xff\xfe" + data.decode("latin-1").encode("utf-16-le")),
        ("huge_field", lines[0] + b"\n" + b"1" * BIG + b"\n" + b"\n".join(lines[1:])),
        ("huge_header", b"x" * BIG + b"," + data),
        ("many_columns", b",".join(b"c%d" % i for i in range(1000)) + b"\n" + data),
        ("crlf", data.replace(b"\n", b"\r\n")),
        ("huge_numbers", data.replace(b"0.", b"1e308", 20)),
        ("nan", data.replace(b"0.1", b"nan", 5)),
        ("deleted_lines", b"\n".join(line for line in lines if rng.random() > 0.2)),
        ("duplicated_lines",
         b"\n".join(line + (b"\n" + line if rng.random() < 0.2 else b"") for line in lines)),
    ]
    return out


class CliByteFuzz(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="lfd_cli_fuzz_")
        cls.rng = random.Random(SEED)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def path(self, name, data):
        p = os.path.join(self.dir, name)
        with open(p, "wb") as f:
            f.write(data)
        return p

    def run_cli(self, cmd, case):
        """Runs one command; returns its exit status after checking it ended cleanly."""
        try:
            proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  timeout=TIME_LIMIT_S, cwd=self.dir)
        except subprocess.TimeoutExpired:
            self.fail("%s: no answer within %.0f s (%s)" % (case, TIME_LIMIT_S, " ".join(cmd[:2])))
        self.assertGreaterEqual(proc.returncode, 0, "%s: killed by signal %d; stderr: %s" % (
            case, -proc.returncode, proc.stderr[-500:]))
        self.assertIn(proc.returncode, (0, 1, 2), "%s: exit status %d" % (case, proc.returncode))
        if proc.returncode != 0:
            self.assertTrue(proc.stderr.strip(), "%s: failed without a message" % case)
        self.assertLessEqual(len(proc.stderr), MAX_STDERR_BYTES, "%s: %d bytes of stderr (input "
                             "echoed?): %r" % (case, len(proc.stderr), proc.stderr[:300]))
        return proc.returncode

    def check_json(self, path, case):
        with open(path, "rb") as f:
            json.loads(f.read().decode("utf-8"))  # valid UTF-8 JSON, or the test errors here

    def test_valid_inputs_work(self):
        """The unmutated files succeed: the fuzz cases start from inputs the CLIs accept."""
        rng = random.Random(SEED)
        demos = [self.path("ok_%d.csv" % k, demo_csv(rng)) for k in range(3)]
        out = os.path.join(self.dir, "ok.json")
        self.assertEqual(self.run_cli([SEGMENT, "--output", out, "--no-profiles",
                                       "--sensor-columns", "fz"] + demos, "valid demos"), 0)
        self.check_json(out, "valid demos")
        lib = os.path.join(self.dir, "ok_lib.json")
        traj = self.path("ok_traj.csv", trajectory_csv())
        self.assertEqual(self.run_cli([DMP_TOOL, "learn", "--csv", traj, "--out", lib], "learn"), 0)
        self.assertEqual(self.run_cli([DMP_TOOL, "info", "--library", lib], "info"), 0)

    def test_segment_on_fuzzed_csv(self):
        rng = random.Random(SEED + 1)
        good = [self.path("seg_good_%d.csv" % k, demo_csv(rng)) for k in range(2)]
        for name, data in mutations(rng, demo_csv(rng)):
            bad = self.path("seg_%s.csv" % name, data)
            out = os.path.join(self.dir, "seg_%s.json" % name)
            if os.path.exists(out):
                os.remove(out)
            rc = self.run_cli([SEGMENT, "--output", out, "--no-profiles", "--sensor-columns", "fz",
                               bad] + good, "segment " + name)
            if rc == 0:
                self.check_json(out, "segment " + name)

    def test_dmp_tool_learn_on_fuzzed_csv(self):
        rng = random.Random(SEED + 2)
        for name, data in mutations(rng, trajectory_csv()):
            bad = self.path("traj_%s.csv" % name, data)
            out = os.path.join(self.dir, "traj_%s.json" % name)
            if self.run_cli([DMP_TOOL, "learn", "--csv", bad, "--out", out, "--overwrite"],
                            "learn " + name) == 0:
                self.check_json(out, "learn " + name)

    def test_dmp_tool_on_fuzzed_library(self):
        rng = random.Random(SEED + 3)
        lib = os.path.join(self.dir, "base_lib.json")
        traj = self.path("base_traj.csv", trajectory_csv())
        self.assertEqual(self.run_cli([DMP_TOOL, "learn", "--csv", traj, "--out", lib], "learn"), 0)
        with open(lib, "rb") as f:
            data = f.read()
        cases = mutations(rng, data) + [
            ("deep_nesting", b"[" * 100000 + b"]" * 100000),
            ("deep_object", b'{"a":' * 50000 + b"1" + b"}" * 50000),
        ]
        for name, bad_bytes in cases:
            bad = self.path("lib_%s.json" % name, bad_bytes)
            self.run_cli([DMP_TOOL, "info", "--library", bad], "info " + name)
            out = os.path.join(self.dir, "roll_%s.csv" % name)
            self.run_cli([DMP_TOOL, "rollout", "--library", bad, "--out", out, "--overwrite"],
                         "rollout " + name)


if __name__ == "__main__":
    rostest.rosrun("lfd_test", "cli_byte_fuzz", CliByteFuzz)
