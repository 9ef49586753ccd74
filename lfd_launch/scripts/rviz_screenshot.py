#!/usr/bin/python3
"""Headless rviz screenshot of a demonstration or reproduction bag (lfd_launch/inspect.launch).

  rviz_screenshot.py --bag B --out shot.png [--segmentation-json J] [--changepoints 8.3,12.9]
                     [--timeout 120]

Starts its own Xvfb (a free display number, reported by Xvfb itself) and, on a private ROS master
(a free port; roslaunch starts and stops it), `roslaunch lfd_launch inspect.launch rate:=0`: the
final state, the whole end-effector path and the segment markers. It saves the screen once rviz's
3-D view has been drawn and stays unchanged for 2 s, then stops every process it started.
Exit status 0 with the PNG written, 1 with a message otherwise.

The Xvfb, launch and grab helpers are lfd_tools.rviz.
"""
import argparse
import os
import sys

from lfd_tools.rviz import screenshot


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bag", required=True)
    parser.add_argument("--out", required=True, help="PNG file")
    parser.add_argument("--segmentation-json", default="")
    parser.add_argument("--changepoints", default="", help="s of bag time, comma-separated")
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    extra = []
    if args.segmentation_json:
        extra.append("segmentation_json:=" + os.path.abspath(args.segmentation_json))
    if args.changepoints:
        extra.append("changepoints:=[%s]" % args.changepoints)
    try:
        print(screenshot(args.bag, args.out, extra, args.timeout))
    except RuntimeError as e:
        print("rviz_screenshot: %s" % e, file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
