#!/usr/bin/python3
"""Summarize every gtest/rostest JUnit XML under a results folder.

Prints each failing test case, then one closing line `N passed, N failed` so a run that executed
nothing can never pass: zero test cases is reported as a failure. Exit status: 0 only if all passed.
"""
import os
import sys
import xml.etree.ElementTree as ET


def cases_of(path):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        yield (os.path.basename(path), "unreadable result file", False, str(exc))
        return
    suites = [root] if root.tag == "testsuite" else root.iter("testsuite")
    for suite in suites:
        for case in suite.iter("testcase"):
            name = "%s.%s" % (case.get("classname", suite.get("name", "?")), case.get("name", "?"))
            failure = case.find("failure")
            if failure is None:
                failure = case.find("error")
            skipped = case.find("skipped") is not None or case.get("status") == "notrun"
            if skipped:
                yield (name, "skipped", None, "")
            elif failure is not None:
                text = (failure.get("message") or "") + "\n" + (failure.text or "")
                yield (name, "failed", False, text.strip())
            else:
                yield (name, "passed", True, "")


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "build/test_results"
    passed = failed = skipped = 0
    for dirpath, _, files in os.walk(folder):
        for fname in sorted(files):
            if not fname.endswith(".xml"):
                continue
            for name, status, ok, text in cases_of(os.path.join(dirpath, fname)):
                if ok is None:
                    skipped += 1
                elif ok:
                    passed += 1
                else:
                    failed += 1
                    print("FAILED %s (%s)\n    %s"
                          % (name, fname, text[:2000].replace("\n", "\n    ")))
    if passed + failed == 0:
        print("no test results found under %s" % folder)
        failed = 1
    line = "%d passed, %d failed" % (passed, failed)
    if skipped:
        line += ", %d skipped" % skipped
    print(line)
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
