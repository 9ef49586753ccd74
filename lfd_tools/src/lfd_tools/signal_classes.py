"""Classes of real-world signals for measuring the segmentation: seeded generators of
synthetic demonstrations, one per kind of recording that other robots produce. Each class is a
task: 6-8 demos that share one phase sequence, each with its own durations and poses. Motions are
minimum-jerk, positions carry sensor noise, a wrist F/T has an offset, white noise and drift, and
a contact force builds up over 0.1-0.4 s after the touch (the surface and the operator's push are
not instantaneous).

The true boundaries are where a phase begins by the task's definition (the first touch, the start
of a lift, motion resuming after a pause), never where a detector would put them: as with a real
sensor, the signals may lag a boundary or hide it. Nothing here knows about the segmentation.

CLASSES maps a name to a SignalClass; `CLASSES[name].make(seed)` is that class's Task (state and
sensor column names, and per demo its clock, columns and true boundaries), the same for the same
seed. A rate variant (`contact_wipe@25`) is its base class's generator at another
rate with the same durations and poses (only the sampling and the noise samples differ): every
demo draws its parameters and its noise from two streams of its own. At a high rate a class holds
fewer demos so that one `segment` request stays within config/segmentation.yaml's limits.
Written as CSV by lfd_segmentation/scripts/make_signal_classes.py, scored by
bench/segmentation/bench_signal_classes.py.
"""
import json
import math
import os
import zlib
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from lfd_tools import synthetic

POSE = ["x", "y", "z", "qx", "qy", "qz", "qw"]
WRENCH = ["fx", "fy", "fz", "tx", "ty", "tz"]
JOINTS = ["r_shoulder_pan_joint", "r_shoulder_lift_joint", "r_upper_arm_roll_joint",
          "r_elbow_flex_joint", "r_forearm_roll_joint", "r_wrist_flex_joint", "r_wrist_roll_joint"]
# config/segmentation.yaml limits: max_samples_per_demo and max_total_samples (one request).
MAX_DEMO_ROWS = 12000
MAX_TASK_ROWS = 60000
DEMOS = (6, 8)  # demos per task, drawn
POSITION_NOISE = 2e-4  # m, a kinesthetic arm's forward kinematics
QUATERNION_NOISE = 2e-4


@dataclass
class Demo:
    t: np.ndarray
    columns: dict  # name -> samples, one per t
    boundaries_s: list  # true boundaries, s on t's clock


@dataclass
class Task:
    state_columns: list
    sensor_columns: list
    demos: list = field(default_factory=list)


@dataclass(frozen=True)
class SignalClass:
    name: str  # a rate variant's is <base>@<rate>
    generate: Callable  # (rng, rate, demos) -> Task; its docstring says what the class models
    rate: float  # Hz
    max_seconds: float  # the longest demo it draws: bounds a request's rows

    @property
    def doc(self):
        return " ".join(self.generate.__doc__.split())

    def max_demos(self):
        """The most demos that fit one request at this rate (at most DEMOS[1]; 10 samples for
        the rounding of the phases)."""
        return min(DEMOS[1], MAX_TASK_ROWS // (int(math.ceil(self.rate * self.max_seconds)) + 10))

    def make(self, seed, demos=None):
        """The class's task for `seed` (demos: how many, else drawn). The stream is keyed by the
        base name, so that a rate variant draws what its base draws."""
        rng = np.random.default_rng([seed, zlib.crc32(self.name.split("@")[0].encode())])
        drawn = int(rng.integers(DEMOS[0], DEMOS[1] + 1))  # drawn always: the streams stay aligned
        return self.generate(rng, self.rate, demos or min(drawn, self.max_demos()))


# ---- building blocks -----------------------------------------------------------------------------


class Phases:
    """Consecutive phases of given durations on a clock of `rate`: each phase's sample count and
    first sample; a boundary is a phase's first sample."""

    def __init__(self, rate, seconds):
        self.rate = rate
        self.n = [max(2, int(round(s * rate))) for s in seconds]
        self.start = np.concatenate([[0], np.cumsum(self.n)]).astype(int)

    @property
    def total(self):
        return int(self.start[-1])

    def t(self):
        return np.arange(self.total) / self.rate

    def boundaries(self, phases):
        return [float(self.start[k]) / self.rate for k in phases]


def streams(rng):
    """(parameters, noise) generators of one demo, so that its durations and poses do not depend
    on how many noise samples its rate needs."""
    return tuple(np.random.default_rng(int(rng.integers(2 ** 62))) for _ in range(2))


def envelope(n, on, off, rise, fall):
    """0 until sample `on`, up to 1 over `rise` samples (minimum-jerk), 1 until `off`, down to 0
    over `fall` samples from `off` on."""
    e = np.zeros(n)
    e[on:off] = 1.0
    r = min(rise, off - on)
    e[on:on + r] = synthetic.s_curve(r)
    f = min(fall, n - off)
    e[off:off + f] = 1.0 - synthetic.s_curve(f)
    return e


def seconds(rate, p, lo, hi):
    """A duration drawn in [lo, hi] s, in samples (at least one)."""
    return max(1, int(round(p.uniform(lo, hi) * rate)))


def reach(start, touch, n):
    """A reach to a surface: to 4 cm above the touch point, then a slow last quarter down to it
    (kinesthetic reaches end with a careful descent)."""
    above = touch + [0, 0, 0.04]
    down = max(2, n // 4)
    return np.vstack([synthetic.min_jerk(start, above, n - down),
                      synthetic.min_jerk(above, touch, down)])


def sliding_friction(pos, rate, normal, mu):
    """Friction (n x 2, N) opposing the horizontal sliding of a tool pressed with `normal` N
    (Coulomb, smoothed below 2 cm/s)."""
    vel = np.gradient(pos[:, :2], axis=0) * rate
    speed = np.linalg.norm(vel, axis=1)
    scale = -mu * normal * np.tanh(speed / 0.02) / np.maximum(speed, 1e-9)
    return vel * scale[:, None]


def tip_wrench(friction, normal, lever, yaw, twist=None):
    """fx fy fz tx ty tz at the wrist of a tool `lever` m long whose tip touches: the surface
    pushes back along the tool (-z, the hand points down), friction acts at the tip, the torques
    are the tip's lever arm times the force; forces turned into the hand's frame by its yaw.
    `twist`: a torque about the tool's axis (turning a part in contact)."""
    c, s = np.cos(yaw), np.sin(yaw)
    fx = c * friction[:, 0] + s * friction[:, 1]
    fy = -s * friction[:, 0] + c * friction[:, 1]
    tz = np.zeros(len(fx)) if twist is None else twist
    return np.column_stack([fx, fy, -normal, lever * fy, -lever * fx, tz])


def pose_columns(noise, pos, yaw):
    """POSE columns of a hand pointing down at `pos` turned by `yaw`, with measurement noise."""
    pos = pos + POSITION_NOISE * noise.standard_normal(pos.shape)
    quat = (synthetic.hand_down_quaternion(yaw)
            + QUATERNION_NOISE * noise.standard_normal((len(yaw), 4)))
    return dict(zip(POSE, np.column_stack([pos, quat]).T))


def hand_yaw(p, t):
    """A hand's yaw: an offset per demo and a slow turn a human wrist makes without meaning to."""
    return p.uniform(-0.3, 0.3) + 0.15 * np.sin(2 * np.pi * t / (1.3 * t[-1]) + p.uniform(0, np.pi))


def task_of(rng, demos, state, sensor, shared, demo):
    """A Task of `demos` demos: `shared(rng)` draws what the task's demos have in common, then
    `demo(p, noise, shared)` -> (t, columns, boundaries) draws each from its own streams."""
    common = shared(rng)
    task = Task(list(state), list(sensor))
    for _ in range(demos):
        p, noise = streams(rng)
        t, cols, bounds = demo(p, noise, common)
        task.demos.append(Demo(t, cols, bounds))
    return task


# ---- the wipe (contact_wipe, stale_sensor, drifting_sensor) --------------------------------------


def wipe_shared(rng):
    return {"direction": rng.uniform(0, np.pi), "lever": rng.uniform(0.08, 0.15),
            "mu": rng.uniform(0.3, 0.5)}


def wipe_demo(rate, disturbance):
    """contact_wipe's demo at `rate`, its F/T disturbed by `disturbance(noise, n, rate)`."""
    def demo(p, noise, task):
        ph = Phases(rate, [p.uniform(2.0, 3.0), p.uniform(3.5, 4.5), p.uniform(1.5, 2.0)])
        t, (n_reach, n_wipe, n_retract) = ph.t(), ph.n
        start = np.array([0.3, -0.2, 0.35]) + p.uniform(-0.05, 0.05, 3)
        touch = np.array([0.55, 0.0, 0.10]) + p.uniform(-0.05, 0.05, 3)
        heading = task["direction"] + p.normal(0, 0.1)
        along = np.array([np.cos(heading), np.sin(heading), 0.0])
        period, amp = p.uniform(0.8, 1.4), p.uniform(0.03, 0.07)
        # The operator presses first and starts stroking, and slows the strokes before lifting.
        ease = seconds(rate, p, 0.3, 0.5)  # the strokes are over when the lift starts
        strokes = envelope(n_wipe, 0, n_wipe - ease, seconds(rate, p, 0.3, 0.6), ease)
        tw = np.arange(n_wipe) / rate
        wiping = touch + (amp * strokes * np.sin(2 * np.pi * tw / period))[:, None] * along
        on, off = ph.start[1], ph.start[2]
        press = envelope(ph.total, on, off, seconds(rate, p, 0.1, 0.4), seconds(rate, p, 0.1, 0.4))
        # the surface gives under the pressure
        wiping[:, 2] -= p.uniform(0.001, 0.002) * press[on:off]
        pos = np.vstack([reach(start, touch, n_reach), wiping,
                         synthetic.min_jerk(wiping[-1], start + [0, 0, 0.05], n_retract)])
        # Pressing harder on one stroke direction than the other; a level per demo.
        normal = p.uniform(6, 15) * press * (1 + p.uniform(0.1, 0.3)
                                             * np.sin(2 * np.pi * (t - t[on]) / period))
        yaw = hand_yaw(p, t)
        wrench = tip_wrench(sliding_friction(pos, rate, normal, task["mu"]), normal,
                            task["lever"], yaw)
        wrench += disturbance(noise, ph.total, rate)
        cols = pose_columns(noise, pos, yaw)
        cols.update(zip(WRENCH, wrench.T))
        return t, cols, ph.boundaries([1, 2])
    return demo


def contact_wipe(rng, rate, demos):
    """A kinesthetic wiping task recorded with a wrist F/T (a 7-DoF arm guided by hand, F/T logged
    at its own ~90 Hz): reach to a table from above, wipe it while pressing (6-15 N, periodic
    strokes of 3-7 cm along one direction, friction and pressure following the strokes), lift off
    and retract. Boundaries: the first touch and the start of the lift; the press force builds up
    over 0.1-0.4 s after the touch and unloads over 0.1-0.4 s as the lift starts. The F/T has a
    rest offset (up to 2 N), 0.5-0.7 N noise and a random-walk drift."""
    return task_of(rng, demos, POSE, WRENCH, wipe_shared, wipe_demo(rate, synthetic.ft_disturbance))


def stale_sensor(rng, rate, demos):
    """contact_wipe recorded through a flaky F/T driver: in 1-2 demos the F/T topic repeats its
    first message for the first 2-4 s (a driver that publishes its cached reading until the device
    answers; the reach's touch may fall inside that time), and in one demo it repeats it throughout
    (a dead sensor whose driver keeps publishing). The other demos are normal, and the truth is
    the motion's, as for contact_wipe."""
    task = contact_wipe(rng, rate, demos)
    order = rng.permutation(len(task.demos))
    stale = order[1:1 + int(rng.integers(1, 3))]
    for k in stale:
        freeze(task.demos[k], WRENCH, int(round(rng.uniform(2.0, 4.0) * rate)))
    freeze(task.demos[order[0]], WRENCH, None)
    return task


def freeze(demo, names, rows):
    """The first `rows` samples (None: all) of the named columns repeat the first sample."""
    for name in names:
        col = demo.columns[name]
        col[:rows] = col[0]


def strong_drift(noise, n, rate):
    """ft_disturbance plus what a warming, uncompensated strain-gauge F/T adds: a linear drift of
    0.25-0.6 N/s (0.025-0.06 N m/s) per channel, either sign, and a warm-up offset change of 1-3 N
    (0.1-0.3 N m) approached with a 2-5 s time constant."""
    t = (np.arange(n) / rate)[:, None]
    scale = np.array([1, 1, 1, 0.1, 0.1, 0.1])
    slope = noise.uniform(0.25, 0.6, 6) * noise.choice([-1, 1], 6) * scale
    warm = noise.uniform(1, 3, 6) * noise.choice([-1, 1], 6) * scale
    tau = noise.uniform(2, 5)
    return synthetic.ft_disturbance(noise, n, rate) + slope * t + warm * (1 - np.exp(-t / tau))


def drifting_sensor(rng, rate, demos):
    """contact_wipe with an F/T that drifts strongly: a strain-gauge sensor that is not temperature
    compensated, recorded soon after power-on, so that over a 7-9.5 s demo its zero moves by a few
    newtons (a steady drift plus a warm-up offset change that levels off), comparable to the
    contact force. Same motion, contact and truth as contact_wipe."""
    return task_of(rng, demos, POSE, WRENCH, wipe_shared, wipe_demo(rate, strong_drift))


# ---- snap-fit assembly ---------------------------------------------------------------------------


def snap_demo(rate):
    def demo(p, noise, task):
        ph = Phases(rate, [p.uniform(2.0, 3.0), p.uniform(2.0, 3.0), p.uniform(0.7, 1.0),
                           p.uniform(1.5, 2.5)])
        t, (n_app, n_rot, n_ins, n_mate) = ph.t(), ph.n
        start = np.array([0.35, 0.2, 0.30]) + p.uniform(-0.05, 0.05, 3)
        seat = np.array([0.5, 0.05, 0.12]) + p.uniform(-0.03, 0.03, 3)
        depth, snap = p.uniform(0.004, 0.008), p.uniform(0.001, 0.002)
        mate_t = np.arange(n_mate) / rate
        z_ins = synthetic.min_jerk(seat, seat - [0, 0, depth], n_ins)
        z_mate = seat - [0, 0, depth] - np.outer(snap * (1 - np.exp(-mate_t / 0.01)), [0, 0, 1])
        pos = np.vstack([reach(start, seat, n_app), np.tile(seat, (n_rot, 1)), z_ins, z_mate])
        # The part is turned into its keyed orientation while pressed onto its seat.
        turn = p.uniform(0.3, 0.8) * task["turn_sign"]
        turned = np.zeros(ph.total)
        turned[ph.start[1]:ph.start[2]] = turn * synthetic.s_curve(n_rot)
        turned[ph.start[2]:] = turn
        yaw = hand_yaw(p, t) + turned
        f_rot, f_peak, f_hold = p.normal(13, 1.0), p.normal(29, 1.5), p.uniform(6, 10)
        normal = f_rot * envelope(ph.total, ph.start[1], ph.total, seconds(rate, p, 0.1, 0.4), 0)
        # The snap hook deflects ever harder until it clicks over, then the force falls to the
        # operator's hold with a short ringing of the part.
        normal[ph.start[2]:ph.start[3]] = f_rot + (f_peak - f_rot) * np.linspace(0, 1, n_ins) ** 2
        ring = 3.0 * np.exp(-mate_t / 0.04) * np.sin(2 * np.pi * 25 * mate_t)
        normal[ph.start[3]:] = (f_hold + (f_peak - f_hold) * np.exp(-mate_t / p.uniform(0.03, 0.1))
                                + ring)
        normal *= 1 + 0.03 * np.sin(2 * np.pi * t / p.uniform(1.5, 3.0))  # the hand's push wavers
        spin = np.gradient(turned) * rate  # the part turns on its seat only when turned on purpose
        twist = -task["mu"] * 0.015 * normal * np.tanh(spin / 0.05)  # friction on a 15 mm seat
        # the part sits a little askew
        side = normal[:, None] * task["tilt"] * (1 + p.normal(0, 0.2))
        wrench = tip_wrench(side, normal, task["lever"], yaw, twist)
        wrench += synthetic.ft_disturbance(noise, ph.total, rate)
        cols = pose_columns(noise, pos, yaw)
        cols.update(zip(WRENCH, wrench.T))
        return t, cols, ph.boundaries([1, 2, 3])
    return demo


def snap_shared(rng):
    angle = rng.uniform(0, 2 * np.pi)  # the direction in which the part sits askew
    return {"turn_sign": rng.choice([-1.0, 1.0]), "mu": rng.uniform(0.3, 0.5),
            "lever": rng.uniform(0.06, 0.12),
            "tilt": rng.uniform(0.03, 0.08) * np.array([np.cos(angle), np.sin(angle)])}


def in_contact_level(rng, rate, demos):
    """A snap-fit assembly recorded at 200 Hz (pose and wrist wrench): approach the seat, touch it
    and turn the part into its keyed orientation while pressing (~13 N, friction torque about the
    tool), insert (0.7-1.0 s: 4-8 mm down, the force rising to ~29 N as the hook deflects, the snap
    at its end), then hold it mated (the force falls to a 6-10 N hold with a short ringing). After
    the first touch the part never leaves contact: three boundaries (touch, start of the insertion,
    the snap), the last two changes of the force level in contact, not contact made or lost."""
    return task_of(rng, demos, POSE, WRENCH, snap_shared, snap_demo(rate))


# ---- a short phase -------------------------------------------------------------------------------


def press_demo(rate):
    def demo(p, noise, task):
        ph = Phases(rate, [p.uniform(2.0, 3.0), p.uniform(0.5, 0.9), p.uniform(2.0, 3.0)])
        t, (n_reach, n_press, n_retract) = ph.t(), ph.n
        start = np.array([0.3, -0.1, 0.3]) + p.uniform(-0.05, 0.05, 3)
        button = np.array([0.5, 0.1, 0.12]) + p.uniform(-0.04, 0.04, 3)
        travel = p.uniform(0.002, 0.004)
        down = max(2, int(0.6 * n_press))
        pressed = np.vstack([synthetic.min_jerk(button, button - [0, 0, travel], down),
                             np.tile(button - [0, 0, travel], (n_press - down, 1))])
        away = task["away"] + p.uniform(-0.05, 0.05, 3)
        pos = np.vstack([reach(start, button, n_reach), pressed,
                         synthetic.min_jerk(pressed[-1], away, n_retract)])
        # The rise fits the press (0.1-0.3 s of a 0.5-0.9 s phase); the button unloads as the lift
        # starts.
        normal = p.uniform(8, 15) * envelope(ph.total, ph.start[1], ph.start[2],
                                             seconds(rate, p, 0.1, 0.3), seconds(rate, p, 0.1, 0.3))
        yaw = hand_yaw(p, t)
        wrench = tip_wrench(np.zeros((ph.total, 2)), normal, task["lever"], yaw)
        wrench += synthetic.ft_disturbance(noise, ph.total, rate)
        cols = pose_columns(noise, pos, yaw)
        cols.update(zip(WRENCH, wrench.T))
        return t, cols, ph.boundaries([1, 2])
    return demo


def short_phase(rng, rate, demos):
    """Pressing a button on a panel with a wrist F/T (100 Hz): reach to the button, press it (a
    0.5-0.9 s phase: 2-4 mm of travel, 8-15 N reached in 0.1-0.3 s), move away to a common end
    point. A skill shorter than a second with a clear signature in the force: two boundaries, the
    touch and the start of the move away, 0.5-0.9 s apart."""
    return task_of(rng, demos, POSE, WRENCH,
                   lambda r: {"lever": r.uniform(0.05, 0.12), "away": np.array([0.35, 0.25, 0.3])},
                   press_demo(rate))


# ---- repeated strokes ----------------------------------------------------------------------------

STROKES = 4


def strokes_demo(rate):
    def demo(p, noise, task):
        air = [p.uniform(0.8, 1.3) for _ in range(STROKES - 1)]
        contact = [p.uniform(1.2, 1.8) for _ in range(STROKES)]
        ph = Phases(rate, [p.uniform(1.5, 2.5)]
                    + [d for pair in zip(contact, air + [p.uniform(1.5, 2.5)]) for d in pair])
        t = ph.t()
        along, across = task["along"], np.array([-task["along"][1], task["along"][0], 0.0])
        first = np.array([0.45, -0.1, 0.1]) + p.uniform(-0.04, 0.04, 3)
        spacing, length = p.uniform(0.02, 0.04), p.uniform(0.10, 0.16)
        starts = [first + k * spacing * across + p.normal(0, 0.005, 3) * [1, 1, 0]
                  for k in range(STROKES)]
        home = np.array([0.3, -0.25, 0.3]) + p.uniform(-0.04, 0.04, 3)
        path = [reach(home, starts[0], ph.n[0])]
        normal = np.zeros(ph.total)
        for k in range(STROKES):
            on, off = ph.start[1 + 2 * k], ph.start[2 + 2 * k]
            stroke = synthetic.min_jerk(starts[k], starts[k] + length * along, ph.n[1 + 2 * k])
            press = envelope(ph.total, on, off, seconds(rate, p, 0.1, 0.4),
                             seconds(rate, p, 0.1, 0.4))
            stroke[:, 2] -= 0.0015 * press[on:off]  # the surface gives under the pressure
            normal += p.uniform(6, 14) * press
            n_next = ph.n[2 + 2 * k]
            if k + 1 < STROKES:  # lift, move back over the next stroke's start, and down to it
                back = max(2, int(0.6 * n_next))
                over = starts[k + 1] + [0, 0, p.uniform(0.03, 0.05)]
                path += [stroke, synthetic.min_jerk(stroke[-1], over, back),
                         synthetic.min_jerk(over, starts[k + 1], n_next - back)]
            else:
                path += [stroke, synthetic.min_jerk(stroke[-1], home + [0, 0, 0.05], n_next)]
        pos = np.vstack(path)
        yaw = hand_yaw(p, t)
        wrench = tip_wrench(sliding_friction(pos, rate, normal, task["mu"]), normal,
                            task["lever"], yaw)
        wrench += synthetic.ft_disturbance(noise, ph.total, rate)
        cols = pose_columns(noise, pos, yaw)
        cols.update(zip(WRENCH, wrench.T))
        return t, cols, ph.boundaries(range(1, 2 * STROKES + 1))
    return demo


def heading_shared(rng):
    """The horizontal direction of a task's strokes."""
    heading = rng.uniform(0, 2 * np.pi)
    return {"along": np.array([np.cos(heading), np.sin(heading), 0.0])}


def strokes_shared(rng):
    return dict(heading_shared(rng), mu=rng.uniform(0.3, 0.5), lever=rng.uniform(0.08, 0.15))


def strokes(rng, rate, demos):
    """Wiping with separate strokes (100 Hz, pose and wrist F/T): four times press onto the table,
    stroke 10-16 cm while pressing (6-14 N, a level per stroke), lift, move back over the start of
    the next stroke 2-4 cm aside and come down again; then retract. Every press and every lift is
    a boundary (eight): a wiping skill per stroke, as a demonstrator who counts strokes would
    label it. Air phases last 0.8-1.3 s and strokes 1.2-1.8 s."""
    return task_of(rng, demos, POSE, WRENCH, strokes_shared, strokes_demo(rate))


# ---- pose only -----------------------------------------------------------------------------------


def grating_demo(rate):
    def demo(p, noise, task):
        cycles = [(p.uniform(0.6, 1.0), p.uniform(0.03, 0.06))
                  for _ in range(int(p.integers(3, 7)))]
        ph = Phases(rate, [p.uniform(2.0, 3.0), sum(c[0] for c in cycles), p.uniform(1.5, 2.5)])
        t = ph.t()
        start = np.array([0.3, 0.2, 0.35]) + p.uniform(-0.05, 0.05, 3)
        grater = np.array([0.5, 0.0, 0.2]) + p.uniform(-0.04, 0.04, 3)
        # Each cycle out and back (zero speed at its ends), the hand 2 mm lower at the far end.
        out = np.concatenate(
            [a * (1 - np.cos(2 * np.pi * np.linspace(0, 1, max(2, int(round(d * rate)))))) / 2
             for d, a in cycles])
        # onto the phase's samples
        out = np.interp(np.linspace(0, 1, ph.n[1]), np.linspace(0, 1, len(out)), out)
        grating = (grater + out[:, None] * task["along"]
                   - (0.002 * out / out.max())[:, None] * [0, 0, 1])
        pos = np.vstack([synthetic.min_jerk(start, grater, ph.n[0]), grating,
                         synthetic.min_jerk(grating[-1], start + [0, 0, 0.05], ph.n[2])])
        return t, pose_columns(noise, pos, hand_yaw(p, t)), ph.boundaries([1, 2])
    return demo


def motion_only(rng, rate, demos):
    """A grating task recorded without any force or touch sensor (pose only, 100 Hz): reach the
    grater, grate back and forth 3-6 times (strokes of 3-6 cm, 0.6-1.0 s each, pressing 2 mm down
    on the way out), retract. Two boundaries, the start and the end of the grating; the periodic
    motion in between is one skill, with no boundary between its strokes."""
    return task_of(rng, demos, POSE, [], heading_shared, grating_demo(rate))


SKILLS = 4
HOME = np.array([-0.3, 0.5, -1.2, -1.6, 1.0, -1.0, 0.5])  # a PR2 right arm in front of the robot


def pause_shared(rng):
    """Each skill's sub-motions (2-3), as joint targets the demos share."""
    q, skills = HOME.copy(), []
    for _ in range(SKILLS):
        targets = []
        for _ in range(int(rng.integers(2, 4))):
            q = q + rng.uniform(-0.5, 0.5, 7)
            targets.append(q)
        skills.append(targets)
    return {"skills": skills}


def pause_demo(rate):
    def demo(p, noise, task):
        path, bounds = [np.tile(HOME + p.normal(0, 0.05, 7), (seconds(rate, p, 0.3, 1.0), 1))], []

        def hold(lo, hi):
            path.append(np.tile(path[-1][-1], (seconds(rate, p, lo, hi), 1)))
        for k, targets in enumerate(task["skills"]):
            if k:
                hold(1.0, 4.0)  # the operator's pause between skills
                # the skill begins when the arm moves again
                bounds.append(sum(map(len, path)) / rate)
            for j, target in enumerate(targets):
                if j:
                    hold(0.2, 0.5)  # a hesitation inside the skill
                m = seconds(rate, p, 0.8, 2.0)
                path.append(synthetic.min_jerk(path[-1][-1], target + p.normal(0, 0.05, 7), m))
        hold(0.5, 1.0)
        joints = np.vstack(path)
        joints += 2e-4 * noise.standard_normal(joints.shape)  # encoder and servo jitter
        return np.arange(len(joints)) / rate, dict(zip(JOINTS, joints.T)), bounds
    return demo


def pause_boundaries(rng, rate, demos):
    """A PR2-like recording of joint angles only (7 arm joints, 100 Hz), split into skills by the
    operator at the long pauses: four skills of 2-3 sub-motions each (0.8-2.0 s), with short
    hesitations (0.2-0.5 s) between the sub-motions of a skill and 1-4 s pauses between skills.
    The three boundaries are where the arm moves again after a long pause; the hesitations and
    the stops before them are no boundaries."""
    return task_of(rng, demos, JOINTS, [], pause_shared, pause_demo(rate))


# ---- the registry --------------------------------------------------------------------------------

BASE = {  # name -> (generator, native rate in Hz, longest demo in s)
    "contact_wipe": (contact_wipe, 90.0, 9.5),
    "in_contact_level": (in_contact_level, 200.0, 9.5),
    "short_phase": (short_phase, 100.0, 6.9),
    "stale_sensor": (stale_sensor, 90.0, 9.5),
    "drifting_sensor": (drifting_sensor, 100.0, 9.5),
    "strokes": (strokes, 100.0, 16.1),
    "motion_only": (motion_only, 100.0, 11.5),
    "pause_boundaries": (pause_boundaries, 100.0, 42.0),
}
RATE_VARIANTS = {"contact_wipe": (25, 100, 1000), "in_contact_level": (25, 100, 1000)}


def registry():
    """{name: SignalClass}: every base class at its native rate, then the rate variants."""
    out = {name: SignalClass(name, gen, rate, longest)
           for name, (gen, rate, longest) in BASE.items()}
    for name, rates in RATE_VARIANTS.items():
        gen, _, longest = BASE[name]
        out.update({"%s@%d" % (name, r): SignalClass("%s@%d" % (name, r), gen, float(r), longest)
                    for r in rates})
    return out


CLASSES = registry()


def write_class(name, seed, out, demos=None):
    """OUT/<name>/demo_<k>.csv (a time column, the state columns, the sensor columns) and
    OUT/<name>/truth.json ({class, seed, rate_hz, description, state_columns, sensor_columns,
    demos: [{file, boundaries_s}]}). Returns the truth.json record."""
    cls = CLASSES[name]
    task = cls.make(seed, demos)
    folder = os.path.join(out, name)
    os.makedirs(folder, exist_ok=True)
    names = task.state_columns + task.sensor_columns
    truth = {"class": name, "seed": seed, "rate_hz": cls.rate, "description": cls.doc,
             "state_columns": task.state_columns, "sensor_columns": task.sensor_columns,
             "demos": []}
    for k, demo in enumerate(task.demos):
        path = synthetic.write_demo_csv(folder, k, demo.t, names, [demo.columns[c] for c in names])
        truth["demos"].append({"file": os.path.basename(path),
                               "boundaries_s": [round(b, 6) for b in demo.boundaries_s]})
    with open(os.path.join(folder, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1)
    return truth
