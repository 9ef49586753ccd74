#!/usr/bin/python3
"""Run gtest binaries built with AddressSanitizer + UndefinedBehaviorSanitizer; JUnit XML out.

  run_sanitized_gtests.py RESULTS_DIR BINARY...

Each binary's suites and cases are renamed `asan.<suite>` so summarize_results.py counts them next
to (and distinguishable from) the normal runs. A sanitizer report aborts the binary (built with
-fno-sanitize-recover=all), which gtest's XML cannot show, so every binary also gets one case
`asan.<binary>.exit_status` that fails unless the process exited 0, carrying the report.
Exit status: 0 only if every binary exited 0.
"""
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from concurrent.futures import ThreadPoolExecutor
from xml.sax.saxutils import escape, quoteattr

PREFIX = "asan."
# Generous against a hang, far above any unit test binary's sanitized run time.
TIMEOUT_S = 900
SANITIZER_ENV = {
    # halt_on_error: the first heap error fails the binary. Leak checking is on: a leak in our
    # code fails the run like any other heap error.
    "ASAN_OPTIONS": "halt_on_error=1:abort_on_error=0:detect_stack_use_after_return=0:"
                    "strict_string_checks=1:check_initialization_order=1",
    "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1",
}


def prefixed(xml_path):
    """The binary's gtest XML with every suite and class name prefixed; None if unreadable."""
    try:
        root = ET.parse(xml_path).getroot()
    except (ET.ParseError, OSError):
        return None
    for suite in ([root] if root.tag == "testsuite" else root.iter("testsuite")):
        suite.set("name", PREFIX + suite.get("name", "?"))
        for case in suite.iter("testcase"):
            case.set("classname", PREFIX + case.get("classname", suite.get("name", "?")))
    return root


def exit_case(name, returncode, output):
    if returncode == 0:
        return '<testcase classname=%s name="exit_status"/>' % quoteattr(PREFIX + name)
    message = "exited with %s under ASan/UBSan" % (
        "signal %d" % -returncode if returncode < 0 else "status %d" % returncode)
    return ('<testcase classname=%s name="exit_status"><failure message=%s>%s</failure></testcase>'
            % (quoteattr(PREFIX + name), quoteattr(message), escape(output[-20000:])))


def run(binary, results):
    name = os.path.basename(binary)
    xml_path = os.path.join(results, "%s%s.gtest.xml" % (PREFIX, name))
    raw = xml_path + ".raw"
    env = dict(os.environ, **SANITIZER_ENV)
    try:
        proc = subprocess.run([binary, "--gtest_output=xml:" + raw], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, env=env, timeout=TIMEOUT_S,
                              cwd=os.path.dirname(binary))
        returncode, output = proc.returncode, proc.stdout.decode(errors="replace")
    except subprocess.TimeoutExpired as exc:
        returncode = 1
        output = (exc.stdout or b"").decode(errors="replace") + "\nTIMEOUT after %d s" % TIMEOUT_S
    root = prefixed(raw)
    cases = ET.tostring(root, encoding="unicode") if root is not None else ""
    if root is not None and root.tag == "testsuites":
        cases = "".join(ET.tostring(s, encoding="unicode") for s in root.iter("testsuite"))
    with open(xml_path, "w") as f:
        f.write('<?xml version="1.0" encoding="UTF-8"?>\n<testsuites>%s<testsuite name=%s>%s'
                '</testsuite></testsuites>\n'
                % (cases, quoteattr(PREFIX + name), exit_case(name, returncode, output)))
    if os.path.exists(raw):
        os.remove(raw)
    print("[asan] %-40s %s" % (name, "ok" if returncode == 0 else "FAILED (%d)" % returncode),
          flush=True)
    return returncode == 0


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    results, binaries = sys.argv[1], sys.argv[2:]
    os.makedirs(results, exist_ok=True)
    with ThreadPoolExecutor(max_workers=int(os.environ.get("LFD_JOBS", "2"))) as pool:
        ok = list(pool.map(lambda b: run(b, results), binaries))
    return 0 if all(ok) else 1


if __name__ == "__main__":
    sys.exit(main())
