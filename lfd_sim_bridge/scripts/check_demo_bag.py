#!/usr/bin/python3
"""Physical success of recorded demonstrations, judged from the bags alone.

  check_demo_bag.py BAG_OR_FOLDER [...] [--evaluation FILE] [--json]

The goal comes from the bag's metadata (first message, /lfd/metadata, extra_json) and the final
object pose from the last /objects/<object>/pose message, judged with the task's criteria of
config/evaluation.yaml `reproduction` (lfd_tools.judge). Prints one line per bag (or one JSON
object per line with --json); exit status 0 only if every bag exists, is readable and succeeded.
"""
import argparse
import json
import sys

from lfd_tools import bags, config


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="+", help="bags or folders of bags")
    parser.add_argument("--evaluation", default=None, help="criteria file (default: config/evaluation.yaml)")
    parser.add_argument("--json", action="store_true", help="one JSON object per bag")
    args = parser.parse_args()
    found = list(bags.bags_of(args.paths))
    if not found:
        print("no bag found in %s" % " ".join(args.paths), file=sys.stderr)
        return 2
    evaluation = config.load_evaluation(args.evaluation)
    ok = 0
    for path in found:
        r = bags.demo_outcome(path, evaluation)
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
