"""What the synthetic demonstration writers (lfd_segmentation/scripts/make_*.py, and
lfd_tools.signal_classes) share: their command line (an output folder, how many demos, the rate, a
seed), one CSV per demo, a time column first, as the `segment` CLI reads it, and the pieces of a
kinesthetic recording: minimum-jerk motions, a hand pointing down, a wrist F/T's offset, noise and
drift."""
import argparse
import os

import numpy as np


def parse_demo_args(doc, demos, rate, extra=None):
    """(args, rng): OUT_DIR [--demos N] [--rate HZ] [--seed S], plus what `extra(parser)` adds;
    the output folder is made and the generator seeded."""
    ap = argparse.ArgumentParser(description=doc,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--demos", type=int, default=demos)
    ap.add_argument("--rate", type=float, default=rate, help="Hz")
    ap.add_argument("--seed", type=int, default=0)
    if extra:
        extra(ap)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    return args, np.random.default_rng(args.seed)


def write_demo_csv(out, index, t, names, columns):
    """OUT/demo_<index>.csv: the time column, then one column per name."""
    path = os.path.join(out, "demo_%d.csv" % index)
    np.savetxt(path, np.column_stack([t] + list(columns)), delimiter=",",
               header=",".join(["time"] + list(names)), comments="", fmt="%.6g")
    return path


def s_curve(n):
    """n samples of the minimum-jerk profile from 0 to 1 (10 s^3 - 15 s^4 + 6 s^5)."""
    s = np.linspace(0.0, 1.0, n)
    return 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5


def min_jerk(a, b, n):
    """n samples of the minimum-jerk motion from point a to point b (rows: samples)."""
    return a + (b - a) * s_curve(n)[:, None]


def hand_down_quaternion(yaw):
    """(qx, qy, qz, qw) columns of a hand pointing down (half a turn about a horizontal axis) turned
    by `yaw` (rad, one per sample) about the vertical."""
    zero = np.zeros(len(yaw))
    return np.column_stack([np.cos(yaw / 2), np.sin(yaw / 2), zero, zero])


def ft_disturbance(rng, n, rate, drift=0.01):
    """What a wrist F/T adds to the true wrench (n x 6: fx fy fz tx ty tz): a rest offset (up to
    2 N, 0.2 N m), a random-walk drift (`drift` per square root of a second) and white noise
    (0.5-0.7 N, 0.02-0.03 N m, a small industrial F/T)."""
    offset = rng.uniform(-2, 2, 6) * [1, 1, 1, 0.1, 0.1, 0.1]
    walk = np.cumsum(rng.standard_normal((n, 6)), axis=0) * drift / np.sqrt(rate)
    noise = rng.standard_normal((n, 6)) * [0.5, 0.5, 0.7, 0.03, 0.03, 0.02]
    return offset + walk + noise
