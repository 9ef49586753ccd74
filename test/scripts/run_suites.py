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
- catkin_lint: every package.xml and CMakeLists.txt, warnings included;
- cxx_format: clang-format (the repository's .clang-format) over every C++ file git tracks;
- cxx_naming: clang-tidy's readability-identifier-naming (the repository's .clang-tidy) over every
  translation unit of the build's compile_commands.json, with the headers they include. It is the
  slow one (~10 min of CPU, parsing): it runs beside the targets, not before them, as two niced
  clang-tidy processes that take the CPU the targets leave (most of a rostest's time is waiting),
  and only that: a target's timing is not disturbed by it.

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
NAMING_TIMEOUT_S = 1800  # the naming lint parses every translation unit (~10 min on one core)
NAMING_PROCESSES = 2  # clang-tidy processes of the naming lint (each on its share of the units)
CXX_SUFFIXES = (".cpp", ".hpp", ".h", ".inc")
NAMING_WARNING = re.compile(
    r"^(/\S+):(\d+):(\d+): warning: (.*) \[readability-identifier-naming\]$", re.M)
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


def tracked_files(suffixes=("",)):
    """The files git tracks whose name ends with one of suffixes, relative to the root."""
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=REPO_ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, check=True).stdout.decode()
    return [p for p in filter(None, listed.split("\0")) if p.endswith(tuple(suffixes))]


def tracked_python_files():
    """Every Python file git tracks, relative to the repository root: *.py, and the files without
    an extension whose first line is a python shebang."""
    files = []
    for path in tracked_files():
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


def lint_cxx_format(build_dir):
    """clang-format --dry-run --Werror over the tracked C++ files (with .clang-format)."""
    try:
        files = tracked_files(CXX_SUFFIXES)
    except (OSError, subprocess.CalledProcessError) as exc:
        return False, "cannot list the C++ files git tracks in %s: %s" % (REPO_ROOT, exc), ""
    lint_cmd = ["/usr/bin/clang-format", "--dry-run", "--Werror"]  # (the install guard reads it)
    return run_linter(lint_cmd + files, "clang-format",
                      "the %d C++ files git tracks" % len(files), "clang-format")


def naming_translation_units(build_dir):
    """The repository's translation units of the build's compile database (generated sources in
    the build tree excluded)."""
    with open(os.path.join(build_dir, "compile_commands.json")) as f:
        entries = json.load(f)
    inside = os.path.join(REPO_ROOT, "")
    generated = (os.path.join(build_dir, ""), os.path.join(REPO_ROOT, "devel", ""))
    return sorted({e["file"] for e in entries
                   if e["file"].startswith(inside) and not e["file"].startswith(generated)})


def lint_cxx_naming(build_dir):
    """clang-tidy with the repository's .clang-tidy (readability-identifier-naming only) over
    every translation unit; passes when no identifier breaks the convention. A header's
    warning, reported once per unit that includes it, is listed once."""
    try:
        units = naming_translation_units(build_dir)
    except (OSError, ValueError, KeyError) as exc:
        return False, ("no usable compile_commands.json in %s (`./lfd build` exports it): %s"
                       % (build_dir, exc)), ""
    lint_cmd = ["/usr/bin/clang-tidy", "--quiet", "-p", build_dir]  # (the install guard reads it)
    if not os.path.exists(lint_cmd[0]):
        return False, ("clang-tidy is not installed: it is the Debian package clang-tidy of "
                       ".ci/apt-packages.txt, which `./lfd deps` installs"), ""
    shares = [units[k::NAMING_PROCESSES] for k in range(NAMING_PROCESSES)]
    with ThreadPoolExecutor(max_workers=NAMING_PROCESSES) as pool:
        runs = list(pool.map(lambda share: run_niced(lint_cmd + share, NAMING_TIMEOUT_S),
                             [share for share in shares if share]))
    if any(run is None for run in runs):
        return False, "clang-tidy took over %d s" % NAMING_TIMEOUT_S, ""
    output = "".join(stdout for _, stdout in runs)
    returncode = max(rc for rc, _ in runs)
    found = sorted(set(NAMING_WARNING.findall(output)),
                   key=lambda w: (w[0], int(w[1]), int(w[2])))
    listing = "\n".join("%s:%s:%s: %s" % (os.path.relpath(f, REPO_ROOT), line, col, text)
                        for f, line, col, text in found)
    what = "the %d translation units of compile_commands.json" % len(units)
    if found:
        return False, "clang-tidy naming: %d identifiers break .clang-tidy's convention in %s" % (
            len(found), what), listing
    if returncode != 0:  # no naming warning, but clang-tidy failed (a unit did not parse)
        return False, "clang-tidy (exit %d) could not check %s" % (returncode, what), \
            output.strip()
    return True, "clang-tidy naming: %s clean" % what, ""


def run_niced(cmd, timeout):
    """(exit status, output) of `cmd` at the lowest CPU priority from the repository root; None
    when it ran over `timeout` s (it is killed)."""
    try:
        done = subprocess.run(["nice", "-n", "19"] + cmd, cwd=REPO_ROOT, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True,
                              errors="replace", timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    return done.returncode, done.stdout


def xml_text(text):
    return re.sub("[^\t\n\r\x20-\ud7ff\ue000-\ufffd]", "?", text)  # XML 1.0 characters only


LINTS = {"python_lint": lambda build_dir: lint_python(),
         "catkin_lint": lambda build_dir: lint_catkin(),
         "cxx_format": lint_cxx_format}
BACKGROUND_LINTS = {"cxx_naming": lint_cxx_naming}  # run beside the targets


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
    """One lint of LINTS or BACKGROUND_LINTS: runs and writes its result; returns its wall time
    and its report for the log."""
    start = time.monotonic()
    passed, headline, output = dict(LINTS, **BACKGROUND_LINTS)[name](build_dir)
    seconds = time.monotonic() - start
    write_lint_result(os.path.join(build_dir, "test_results", name), name, passed, headline,
                      output, seconds)
    report = [headline] + ([output] if not passed and output else [])
    report.append("[tests] %s: %.1f s%s" % (name, seconds, "" if passed else " (FAILED)"))
    return seconds, "\n".join(report)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("build_dir")
    parser.add_argument("--jobs", type=int,
                        default=int(os.environ.get("LFD_TEST_JOBS", os.cpu_count() or 1)))
    parser.add_argument("--only", default="",
                        help="run only targets whose name contains this (the lints': %s)"
                        % ", ".join(list(LINTS) + list(BACKGROUND_LINTS)))
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
            seconds, report_text = run_lint(build_dir, name)
            measured[name] = round(seconds, 1)
            print(report_text, flush=True)
    print("[tests] %d targets, %d at a time" % (len(targets), args.jobs), flush=True)
    printing = threading.Lock()

    def background_lint(name):
        seconds, report_text = run_lint(build_dir, name)
        with printing:
            measured[name] = round(seconds, 1)
            print(report_text, flush=True)
    background = [threading.Thread(target=background_lint, args=(name,))
                  for name in BACKGROUND_LINTS if args.only in name]
    for thread in background:
        thread.start()

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
    for thread in background:
        thread.join()
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
