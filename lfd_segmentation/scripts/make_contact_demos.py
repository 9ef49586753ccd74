#!/usr/bin/python3
"""Synthetic kinesthetic demonstrations of a reach -> sustained periodic contact -> retract task,
as a 7-DoF arm with a wrist F/T sensor would record them: one CSV per demo at --rate Hz with a
time column, the hand's pose (position, quaternion) as state and the wrench as sensor columns.
During contact the hand wipes back and forth on a surface while pressing on it (the normal force
and the friction follow the motion), so most of the demo is oscillating contact. The F/T has a
rest offset, white noise and a slow drift. For measuring the segmentation on data it was never
tuned on (contact onset and release, and pose-only over-segmentation of periodic motion):
    make_contact_demos.py OUT_DIR [--demos 8] [--rate 100] [--seed 0]
    segment --sensor-columns fx,fy,fz,tx,ty,tz OUT_DIR/demo_*.csv        (with the F/T)
    segment OUT_DIR/demo_0.csv OUT_DIR/demo_1.csv ...                     (pose only)
truth.csv holds each demo's contact onset and release (s).
"""
import os

import numpy as np
from lfd_tools import synthetic

POSE = ["x", "y", "z", "qx", "qy", "qz", "qw"]
WRENCH = ["fx", "fy", "fz", "tx", "ty", "tz"]


def demo(rng, rate):
    reach, wipe, retract = rng.uniform(2.0, 3.5), rng.uniform(6.0, 10.0), rng.uniform(2.0, 3.0)
    start = np.array([0.3, -0.2, 0.35]) + rng.uniform(-0.05, 0.05, 3)
    touch = np.array([0.55, 0.0, 0.10]) + rng.uniform(-0.05, 0.05, 3)
    n_reach, n_wipe, n_retract = (int(round(d * rate)) for d in (reach, wipe, retract))
    above = touch + [0, 0, 0.04]
    path = [synthetic.min_jerk(start, above, n_reach - n_reach // 4),
            synthetic.min_jerk(above, touch, n_reach // 4)]
    period, amp = rng.uniform(1.0, 1.8), rng.uniform(0.04, 0.08)
    tw = np.arange(n_wipe) / rate
    ramp = np.clip(tw / 0.5, 0, 1)  # the stroke builds up over half a second
    wiping = np.tile(touch, (n_wipe, 1))
    wiping[:, 1] += ramp * amp * np.sin(2 * np.pi * tw / period)
    wiping[:, 2] -= 0.002 * ramp  # the surface gives a little under the pressure
    path += [wiping, synthetic.min_jerk(wiping[-1], start + [0, 0, 0.05], n_retract)]
    pos = np.vstack(path)
    n = len(pos)
    t = np.arange(n) / rate
    # The hand points down (half a turn about x) and turns slowly about the vertical.
    yaw = rng.uniform(-0.2, 0.2) + 0.2 * np.sin(2 * np.pi * t / (1.3 * t[-1]))
    quat = synthetic.hand_down_quaternion(yaw)
    pos += 2e-4 * rng.standard_normal(pos.shape)
    # Wrench: press force during contact (ramping in and out over 0.15-0.4 s), friction along the
    # stroke, rest offset, white noise and drift.
    on, off = n_reach, n_reach + n_wipe
    rise, fall = (int(rng.uniform(0.15, 0.4) * rate) for _ in range(2))
    press = np.zeros(n)
    press[on:off] = rng.uniform(8, 15)
    press[on:on + rise] *= np.linspace(0, 1, rise)
    press[off - fall:off] *= np.linspace(1, 0, fall)
    vel = np.gradient(pos[:, 1]) * rate
    stroke = np.zeros(n)
    stroke[on:off] = np.sin(2 * np.pi * tw / period)
    fz = -press * (1 + 0.3 * stroke)
    fy = -0.4 * press * np.tanh(vel / 0.02)
    fx = 0.1 * press * stroke
    wrench = np.column_stack([fx, fy, fz, -0.1 * fy, 0.1 * fx, 0.01 * fy])
    wrench += synthetic.ft_disturbance(rng, n, rate)
    return t, np.column_stack([pos, quat]), wrench, on / rate, off / rate


def main():
    args, rng = synthetic.parse_demo_args(__doc__, demos=8, rate=100.0)
    truth = []
    for d in range(args.demos):
        t, pose, wrench, on, off = demo(rng, args.rate)
        synthetic.write_demo_csv(args.out, d, t, POSE + WRENCH, [pose, wrench])
        truth.append((d, on, off))
    np.savetxt(os.path.join(args.out, "truth.csv"), np.array(truth), delimiter=",",
               header="demo,contact_onset_s,release_s", comments="", fmt=["%d", "%.3f", "%.3f"])


if __name__ == "__main__":
    main()
