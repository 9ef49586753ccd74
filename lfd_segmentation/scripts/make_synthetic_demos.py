#!/usr/bin/python3
"""Synthetic grasp demonstrations as CSV files with the feature names of the bag adapter
(14 state + 8 sensor features), for timing the segmentation on the paper's workload:
    make_synthetic_demos.py OUT_DIR [--demos 9] [--samples 2000] [--seed 0]
then
    segment --timing --sensor-columns $(cat OUT_DIR/sensor_columns.txt) OUT_DIR/demo_*.csv
"""
import os

import numpy as np
from lfd_tools import synthetic

STATE = ([f"/ee_pose/pose/position/{a}" for a in "xyz"] +
         [f"/ee_pose/pose/orientation/{a}" for a in "xyzw"] +
         [f"/ee_twist/twist/linear/{a}" for a in "xyz"] +
         [f"/ee_twist/twist/angular/{a}" for a in "xyz"] +
         ["/gripper/state/position/gripper"])
SENSOR = ([f"/wrist_ft/wrench/force/{a}" for a in "xyz"] +
          [f"/wrist_ft/wrench/torque/{a}" for a in "xyz"] +
          ["/touch/values/left", "/touch/values/right"])


def demo(rng, n, rate):
    t = np.arange(n) / rate
    u = np.linspace(0, 1, n)
    grasp = 0.4 + rng.uniform(-0.05, 0.05)
    closed = u >= grasp
    phase = np.where(closed, (u - grasp) / (1 - grasp), u / grasp)
    bump = np.sin(np.pi * phase) * np.where(closed, 0.2, 0.3)
    start, goal = rng.uniform(-0.2, 0.2, 3), rng.uniform(-0.2, 0.2, 3)
    cols = {}
    for k, a in enumerate("xyz"):
        cols[f"/ee_pose/pose/position/{a}"] = (start[k] + (goal[k] - start[k]) * u
                                               + 1e-3 * rng.standard_normal(n))
        cols[f"/ee_twist/twist/linear/{a}"] = bump * (0.5 + 0.5 * k) + 3e-3 * rng.standard_normal(n)
        cols[f"/ee_twist/twist/angular/{a}"] = 0.02 * rng.standard_normal(n)
        cols[f"/ee_pose/pose/orientation/{a}"] = 0.05 * np.sin(
            2 * np.pi * rng.uniform(0.05, 0.2) * t)
    cols["/ee_pose/pose/orientation/w"] = np.sqrt(
        1 - sum(cols[f"/ee_pose/pose/orientation/{a}"] ** 2 for a in "xyz"))
    cols["/gripper/state/position/gripper"] = (np.where(closed, 0.02, 0.08)
                                               + 5e-4 * rng.standard_normal(n))
    for k, a in enumerate("xyz"):
        cols[f"/wrist_ft/wrench/force/{a}"] = (np.where(closed, -3.0 * (k == 2), 0)
                                               + 0.05 * rng.standard_normal(n))
        cols[f"/wrist_ft/wrench/torque/{a}"] = 0.01 * rng.standard_normal(n)
    cols["/touch/values/left"] = np.where(closed, 4.0, 0) + 0.02 * rng.standard_normal(n)
    cols["/touch/values/right"] = np.where(closed, 3.5, 0) + 0.02 * rng.standard_normal(n)
    return t, cols, int(np.argmax(closed))


def main():
    args, rng = synthetic.parse_demo_args(
        __doc__, demos=9, rate=50.0,
        extra=lambda ap: ap.add_argument("--samples", type=int, default=2000))
    for d in range(args.demos):
        n = int(args.samples * rng.uniform(0.85, 1.15))
        t, cols, grasp = demo(rng, n, args.rate)
        names = STATE + SENSOR
        synthetic.write_demo_csv(args.out, d, t, names, [cols[c] for c in names])
        print(f"demo_{d}.csv: {n} samples, grasp at sample {grasp}")
    with open(os.path.join(args.out, "sensor_columns.txt"), "w") as f:
        f.write(",".join(SENSOR))


if __name__ == "__main__":
    main()
