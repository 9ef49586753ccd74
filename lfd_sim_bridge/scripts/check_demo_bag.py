#!/usr/bin/python3
"""Physical success of recorded demonstrations, judged from the bags alone.

  check_demo_bag.py BAG_OR_FOLDER [...] [--tasks-dir DIR] [--json]

The task and its scene (the goal) come from the bag's metadata (first message, /lfd/metadata,
extra_json); what the task file's success rules judge (an object's final pose, a joint's final
value, a sustained contact along a path) is read from the bag and judged by lfd_tools.judge.
Prints one line per bag (or one JSON object per line with --json); exit status 0 only if every bag
exists, is readable and succeeded. --tasks-dir: also find task files there (a task of your own).
"""
import argparse
import json
import os
import sys

from lfd_tools import bags, tasks


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="+", help="bags or folders of bags")
    parser.add_argument("--tasks-dir", default=None,
                        help="also find task files here (searched first)")
    parser.add_argument("--json", action="store_true", help="one JSON object per bag")
    args = parser.parse_args()
    if args.tasks_dir:
        os.environ[tasks.TASKS_PATH_VAR] = os.path.abspath(args.tasks_dir)
    found = list(bags.bags_of(args.paths))
    if not found:
        print("no bag found in %s" % " ".join(args.paths), file=sys.stderr)
        return 2
    ok = 0
    for path in found:
        r = bags.demo_outcome(path)
        ok += bool(r["success"])
        if args.json:
            print(json.dumps(r, sort_keys=True))
        else:
            print("%-4s %s: %s" % ("OK" if r["success"] else "FAIL", path, r["reason"]))
    if not args.json:
        print("%d of %d demonstrations succeeded" % (ok, len(found)))
    return 0 if ok == len(found) else 1


if __name__ == "__main__":
    sys.exit(main())
