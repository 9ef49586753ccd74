#!/usr/bin/python3
"""Run every catkin test target (each gtest binary, each rostest file) on a pool of workers.

`make run_tests` runs the targets one after another, although most of a rostest's time is spent
waiting (on sim time, timeouts, process start-up) and every rostest starts its own master on a
free port. This runner runs the leaf `_run_tests_*` targets of an already built tree (`./lfd build
tests`) with N at a time, longest first, so the two slow halves of the suite overlap.

Each target's output is captured and printed whole when it ends, so the log stays readable. Its
wall time goes to `test_durations.json` in the build folder; the next run schedules from it
(and from the committed `test/durations.json` on a fresh tree). The run closes with the slowest
ten targets.

Before the targets, the lints, one JUnit test case each in test_results/<lint>/, which
summarize_results.py counts like any other (a lint fails with its report, or with a message naming
what is missing when it cannot run); all run from the repository root:
- python_lint: Debian's flake8 with the repository's .flake8 over every Python file git tracks
  (*.py and extension-less scripts with a python shebang);
- catkin_lint: every package.xml and CMakeLists.txt, warnings included.

Usage: run_suites.py BUILD_DIR [--jobs N] [--only SUBSTRING]
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from xml.sax.saxutils import escape, quoteattr

REPO_ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
COMMITTED_DURATIONS = os.path.join(REPO_ROOT, "test", "durations.json")
LINT_TIMEOUT_S = 600  # each lint takes seconds; this only bounds a hang
# A per-target limit well above the slowest target's quiet time (about 10 min), so one hung
# target cannot eat CI's 90 minutes; rostest's own time limits normally end a hang first.
TARGET_TIMEOUT_S = 1500


def leaf_targets(build_dir):
    """{target: its build.make} for every `_run_tests_<pkg>_<kind>_<name>` target that runs one
    gtest binary or rostest file (aggregate targets have no command of their own). Only the
    targets of the current configuration: a removed test's folder stays in the build tree."""
    help_text = subprocess.run(["make", "help"], cwd=build_dir, check=True, capture_output=True,
                               text=True).stdout
    current = set(re.findall(r"^\.\.\. (_run_tests_\S+)$", help_text, flags=re.M))
    targets = {}
    for makefile in glob.glob(os.path.join(build_dir, "**", "CMakeFiles", "_run_tests_*.dir",
                                           "build.make"),
                              recursive=True):
        name = os.path.basename(os.path.dirname(makefile))[:-len(".dir")]
        with open(makefile) as f:
            if name in current and "run_tests.py" in f.read():
                targets[name] = makefile
    return targets


def load_durations(build_dir):
    durations = {}
    for path in (COMMITTED_DURATIONS, os.path.join(build_dir, "test_durations.json")):
        try:
            with open(path) as f:
                durations.update(json.load(f))
        except (OSError, ValueError):
            pass
    return durations


def schedule(targets, durations):
    """Longest first; a target never timed counts as a rostest-sized one (they dominate)."""
    unknown = max(durations.values(), default=60.0)
    return sorted(targets, key=lambda t: -durations.get(t, unknown if "rostest" in t else 1.0))


def run_target(build_dir, target, makefile, log_dir):
    """Only the target's own command, through its build.make as make's Makefile2 calls it: not
    `make <target>`, which would first check every build dependency and clean the package's
    other results."""
    relative = os.path.relpath(os.path.dirname(makefile), build_dir)
    command = ["make", "-s", "-f", os.path.join(relative, "build.make"),
               os.path.join(relative, "build")]
    start = time.monotonic()
    log_path = os.path.join(log_dir, target + ".log")
    with open(log_path, "w") as log:
        try:
            rc = subprocess.run(command, cwd=build_dir, stdout=log, stderr=subprocess.STDOUT,
                                timeout=TARGET_TIMEOUT_S).returncode
        except subprocess.TimeoutExpired:
            log.write("\n[tests] %s killed after %d s\n" % (target, TARGET_TIMEOUT_S))
            rc = -1
    return target, rc, time.monotonic() - start, log_path


def tracked_python_files():
    """Every Python file git tracks, relative to the repository root: *.py, and the files without
    an extension whose first line is a python shebang."""
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=REPO_ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, check=True).stdout.decode()
    files = []
    for path in filter(None, listed.split("\0")):
        if path.endswith(".py"):
            files.append(path)
        elif "." not in os.path.basename(path) and os.path.isfile(os.path.join(REPO_ROOT, path)):
            with open(os.path.join(REPO_ROOT, path), "rb") as f:
                first = f.readline(200)
            if first.startswith(b"#!") and b"python" in first:
                files.append(path)
    return files


def run_linter(command, what, files_text, package):
    """(passed, headline, output) of one linter run from the repository root."""
    try:
        done = subprocess.run(command, cwd=REPO_ROOT, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True, errors="replace",
                              timeout=LINT_TIMEOUT_S)
    except FileNotFoundError:
        return False, ("%s is not installed (no %s): it is the Debian package %s of "
                       ".ci/apt-packages.txt, which `./lfd deps` installs"
                       % (what, command[0], package)), ""
    except subprocess.TimeoutExpired:
        return False, "%s took over %d s over %s" % (what, LINT_TIMEOUT_S, files_text), ""
    output = done.stdout.strip()
    if done.returncode != 0:
        return False, "%s (exit %d) found problems in %s" % (what, done.returncode,
                                                             files_text), output
    return True, "%s: %s clean" % (what, files_text), output


def lint_catkin():
    """catkin_lint over every package, warnings included (-W1 --strict); the ids a package
    ignores are in its CMakeLists.txt, with the reason."""
    lint_cmd = ["/usr/bin/catkin_lint", "-W1", "--strict", "."]  # (named *cmd: the install guard)
    return run_linter(lint_cmd, "catkin_lint",
                      "every package.xml and CMakeLists.txt", "catkin-lint")


def lint_python():
    """(passed, headline, flake8's output) of flake8 over the tracked Python files, run from the
    repository root (its .flake8 applies)."""
    try:
        files = tracked_python_files()
    except (OSError, subprocess.CalledProcessError) as exc:
        detail = (getattr(exc, "stderr", None) or b"").decode(errors="replace").strip()
        return False, "cannot list the Python files git tracks in %s: %s" % (REPO_ROOT, exc), detail
    if not files:
        return False, "git tracks no Python file in %s: nothing was linted" % REPO_ROOT, ""
    lint_cmd = ["/usr/bin/flake8", "--"]  # (named *cmd: the install guard reads it)
    return run_linter(lint_cmd + files, "flake8",
                      "the %d Python files git tracks" % len(files), "flake8")


def xml_text(text):
    return re.sub("[^\t\n\r\x20-\ud7ff\ue000-\ufffd]", "?", text)  # XML 1.0 characters only


LINTS = {"python_lint": lint_python, "catkin_lint": lint_catkin}


def write_lint_result(results_dir, name, passed, headline, output, seconds):
    """A lint as one JUnit test case (<name>.<name>) where summarize_results.py reads."""
    os.makedirs(results_dir, exist_ok=True)
    failure = "" if passed else "<failure message=%s>%s</failure>" % (
        quoteattr(xml_text(headline)), escape(xml_text(output[-20000:])))
    with open(os.path.join(results_dir, name + ".xml"), "w") as f:
        f.write('<?xml version="1.0" encoding="UTF-8"?>\n'
                '<testsuite name=%s tests="1" failures="%d" time="%.1f">'
                '<testcase classname=%s name=%s time="%.1f">%s</testcase></testsuite>\n'
                % (quoteattr(name), 0 if passed else 1, seconds, quoteattr(name),
                   quoteattr(name), seconds, failure))


def run_lint(build_dir, name):
    """One lint of LINTS: runs, writes its result, prints its report; returns its wall time."""
    start = time.monotonic()
    passed, headline, output = LINTS[name]()
    seconds = time.monotonic() - start
    write_lint_result(os.path.join(build_dir, "test_results", name), name, passed, headline,
                      output, seconds)
    print(headline)
    if not passed and output:
        print(output)
    print("[tests] %s: %.1f s%s" % (name, seconds, "" if passed else " (FAILED)"),
          flush=True)
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build_dir")
    parser.add_argument("--jobs", type=int,
                        default=int(os.environ.get("LFD_TEST_JOBS", os.cpu_count() or 1)))
    parser.add_argument("--only", default="",
                        help="run only targets whose name contains this (the lints': %s)"
                        % ", ".join(LINTS))
    args = parser.parse_args()
    build_dir = os.path.abspath(args.build_dir)
    log_dir = os.path.join(build_dir, "test_logs")
    os.makedirs(log_dir, exist_ok=True)
    durations = load_durations(build_dir)
    makefiles = leaf_targets(build_dir)
    targets = schedule([t for t in makefiles if args.only in t], durations)
    measured = {}
    start = time.monotonic()
    for name in LINTS:
        if args.only in name:
            measured[name] = round(run_lint(build_dir, name), 1)
    print("[tests] %d targets, %d at a time" % (len(targets), args.jobs), flush=True)
    printing = threading.Lock()

    def report(result):
        target, rc, seconds, log_path = result
        measured[target] = round(seconds, 1)
        with printing, open(log_path, errors="replace") as log:
            sys.stdout.write(log.read())
            print("[tests] %s: %.1f s%s"
                  % (target, seconds, "" if rc == 0 else " (exit %d)" % rc), flush=True)

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for future in [pool.submit(run_target, build_dir, t, makefiles[t], log_dir)
                       for t in targets]:
            future.add_done_callback(lambda f: report(f.result()))
    durations.update(measured)
    with open(os.path.join(build_dir, "test_durations.json"), "w") as f:
        json.dump(durations, f, indent=1, sort_keys=True)
    print("[tests] all targets: %.0f s wall, %.0f s summed"
          % (time.monotonic() - start, sum(measured.values())))
    print("[tests] slowest ten:")
    for target, seconds in sorted(measured.items(), key=lambda kv: -kv[1])[:10]:
        print("[tests]   %7.1f s  %s" % (seconds, target))
    return 0  # failures are counted from the result files by summarize_results.py


if __name__ == "__main__":
    sys.exit(main())
