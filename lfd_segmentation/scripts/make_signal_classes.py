#!/usr/bin/python3
"""Synthetic demonstrations of the real-world signal classes that break segmentations
(generators in lfd_tools/signal_classes.py): one task of 6-8 demos per class, sharing one phase
sequence, each demo with its own durations and poses (minimum-jerk motions, position noise; a
wrist F/T with offset, white noise and drift; contact forces building up over 0.1-0.4 s):

  contact_wipe      reach -> wipe while pressing (periodic strokes) -> retract; pose + F/T at
                    90 Hz; 2 boundaries (touch, lift)
  in_contact_level  snap-fit assembly: approach -> touch and turn the part (~13 N) -> insert
                    (0.7-1.0 s, force up to ~29 N at the snap) -> mated hold; never leaves
                    contact; pose + F/T at 200 Hz; 3 boundaries
  short_phase       reach -> press a button (0.5-0.9 s) -> move away; 2 boundaries
  stale_sensor      contact_wipe with 1-2 demos whose F/T repeats its first reading for 2-4 s
                    and one whose F/T is constant throughout
  drifting_sensor   contact_wipe with a strongly drifting F/T (a few N per demo, warm-up offset)
  strokes           4 strokes, each press -> stroke -> lift; 8 boundaries (each press, each lift)
  motion_only       pose only: reach -> grate back and forth 3-6 times -> retract; 2 boundaries
  pause_boundaries  7 joint angles only, PR2-like: 4 skills split at 1-4 s pauses, with short
                    (0.2-0.5 s) hesitations inside skills that are no boundaries; 3 boundaries
  contact_wipe@25, @100, @1000, in_contact_level@25, @100, @1000: the same at other rates (at
                    1000 Hz 6 demos of <= 9.5 s, within the CLI's per-request sample limits)

--help lists each class's full description. Output: OUT_DIR/<class>/demo_<k>.csv (a `time`
column, then the state columns, then the sensor columns) and OUT_DIR/<class>/truth.json
({"state_columns", "sensor_columns", "demos": [{"file", "boundaries_s"}], ...}; boundaries in s
on the CSV's clock). The same --seed writes the same files.

  make_signal_classes.py OUT_DIR [--classes a,b] [--seed N] [--demos N]
  segment --state-columns x,y,... --sensor-columns fx,... OUT_DIR/contact_wipe/demo_*.csv
"""
import argparse
import sys

from lfd_tools import signal_classes


def parse_classes(text):
    """The named classes (all when empty), each checked against the registry."""
    names = [c for c in text.split(",") if c] if text else list(signal_classes.CLASSES)
    unknown = [c for c in names if c not in signal_classes.CLASSES]
    if unknown:
        raise ValueError("unknown class %s; known: %s"
                         % (", ".join(unknown), ", ".join(signal_classes.CLASSES)))
    return names


def main():
    epilog = "classes:\n" + "\n".join("  %s (%g Hz): %s" % (n, c.rate, c.doc)
                                      for n, c in signal_classes.CLASSES.items() if "@" not in n)
    ap = argparse.ArgumentParser(description=__doc__, epilog=epilog,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--classes", default="", help="comma-separated names (default: all)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--demos", type=int, default=None, help="demos per class (default: drawn, 6-8)")
    args = ap.parse_args()
    try:
        names = parse_classes(args.classes)
    except ValueError as e:
        ap.error(str(e))
    if args.demos is not None and args.demos < 1:
        ap.error("--demos must be >= 1")
    for name in names:
        truth = signal_classes.write_class(name, args.seed, args.out, args.demos)
        print("%s: %d demos" % (name, len(truth["demos"])), file=sys.stderr)


if __name__ == "__main__":
    main()
