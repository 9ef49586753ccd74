#!/usr/bin/python3
"""Physical success of recorded demonstrations, judged from the bags alone.

  check_demo_bag.py BAG_OR_FOLDER [...] [--tolerance 0.03] [--min-lift 0.10] [--json]

The goal comes from the bag's metadata (first message, /lfd/metadata, extra_json) and the final
object pose from the last /objects/<object>/pose message:
  grasp: the stick ends >= min-lift above the table and within tolerance of its goal (3-D);
  push:  the box ends within tolerance of its target (horizontal distance).
Prints one line per bag (or one JSON object per line with --json); exit status 0 only if every
bag exists, is readable and succeeded.
"""
import argparse
import glob
import json
import math
import os
import sys

import rosbag


def check_bag(path, tolerance=0.03, min_lift=0.10):
    """Returns a dict: bag, task, mode, configuration, success, distance, height, duration,
    topics (name -> count), reason."""
    result = {"bag": path, "success": False, "reason": ""}
    try:
        with rosbag.Bag(path) as bag:
            info = bag.get_type_and_topic_info().topics
            result["topics"] = {name: t.message_count for name, t in info.items()}
            result["duration"] = bag.get_end_time() - bag.get_start_time()
            first = next(bag.read_messages(), None)
            if first is None or first.topic != "/lfd/metadata":
                result["reason"] = "the first message is not /lfd/metadata"
                return result
            meta = first.message
            extra = json.loads(meta.extra_json)
            result.update(task=meta.task, mode=meta.mode, configuration=meta.configuration,
                          speed=meta.speed)
            obj = extra.get("object", "stick" if meta.task == "grasp" else "box")
            last = None
            for _, msg, _ in bag.read_messages(topics=["/objects/%s/pose" % obj]):
                last = msg
    except (rosbag.ROSBagException, OSError, ValueError, KeyError) as exc:
        result["reason"] = "unreadable: %s" % exc
        return result
    if last is None:
        result["reason"] = "no /objects/%s/pose message" % obj
        return result
    goal = extra["goal"]["position"]
    end = (last.pose.position.x, last.pose.position.y, last.pose.position.z)
    table_top = float(extra.get("table_top", 0.80))
    result["height"] = end[2] - table_top
    if meta.task == "grasp":
        result["distance"] = math.dist(end, goal)
        result["success"] = result["height"] >= min_lift and result["distance"] <= tolerance
        result["reason"] = "stick %.1f cm above the table, %.1f cm from the goal" % (
            100 * result["height"], 100 * result["distance"])
    elif meta.task == "push":
        result["distance"] = math.dist(end[:2], goal[:2])
        result["success"] = result["distance"] <= tolerance
        result["reason"] = "box %.1f cm from its target" % (100 * result["distance"])
    else:
        result["reason"] = "unknown task '%s'" % meta.task
    return result


def bags_of(paths):
    for p in paths:
        if os.path.isdir(p):
            yield from sorted(glob.glob(os.path.join(p, "*.bag")))
        else:
            yield p


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="+", help="bags or folders of bags")
    parser.add_argument("--tolerance", type=float, default=0.03, help="m (default 0.03)")
    parser.add_argument("--min-lift", type=float, default=0.10, help="m (default 0.10)")
    parser.add_argument("--json", action="store_true", help="one JSON object per bag")
    args = parser.parse_args()
    bags = list(bags_of(args.paths))
    if not bags:
        print("no bag found in %s" % " ".join(args.paths), file=sys.stderr)
        return 2
    ok = 0
    for path in bags:
        r = check_bag(path, args.tolerance, args.min_lift)
        ok += bool(r["success"])
        if args.json:
            print(json.dumps(r, sort_keys=True))
        else:
            print("%-4s %s: %s" % ("OK" if r["success"] else "FAIL", path, r["reason"]))
    if not args.json:
        print("%d of %d demonstrations succeeded" % (ok, len(bags)))
    return 0 if ok == len(bags) else 1


if __name__ == "__main__":
    sys.exit(main())
