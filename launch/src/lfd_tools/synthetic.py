"""What the synthetic demonstration writers (lfd_segmentation/scripts/make_*_demos.py) share: their
command line (an output folder, how many demos, the rate, a seed) and one CSV per demo, a time
column first, as the `segment` CLI reads it."""
import argparse
import os

import numpy as np


def parse_demo_args(doc, demos, rate, extra=None):
    """(args, rng): OUT_DIR [--demos N] [--rate HZ] [--seed S], plus what `extra(parser)` adds;
    the output folder is made and the generator seeded."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
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
