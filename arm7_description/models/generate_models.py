#!/usr/bin/python3
"""Single source of truth for the 7-DoF arm's models (arm7_description).

Writes, next to this file:
  arm7.urdf    plain URDF of a 7-DoF arm on a table stand, with a wrist force/torque sensor and a
               parallel gripper
  arm7.xml     the same robot in MJCF (to be <include>d), with actuators, sites and sensors
  workcell.xml the MuJoCo scene of config/scene.yaml (floor, table, the stick, the box, the block,
               the drawer cabinet) with this arm in it

The writers are the robot-independent lfd_tools.robot_models (lfd_tools/src/lfd_tools, importable
after `source devel/setup.bash`); this file holds only the arm's tables. The arm stands where
config/scene.yaml puts the robot (base_link_in_world, the IK and Cartesian frame of every task
pose): its root link base_link is that mount point, no rotation, on a column down to the floor
(beside the table: the table starts at x = 0.15).

Kinematics (like a KUKA iiwa / Franka, elbow in the middle): joints alternate about z and y --
shoulder arm_joint_1 (z) 0.10 above the base, arm_joint_2 (y) and arm_joint_3 (z) at the shoulder
0.30 above the base, the elbow arm_joint_4 (y) and arm_joint_5 (z) 0.50 further, the wrist
arm_joint_6 (y) and arm_joint_7 (z) 0.50 further (a spherical wrist), the flange 0.045 above it.
Every joint frame is aligned with its parent; in the zero pose the arm points straight up. The hand
is the humanoid's (jvrc1_description: the grasps are tuned for it) under the flange, mounted turned
by pi about y: fingers along the flange's +z, so the TCP frame is the task files' tool orientation
(fingers down, pads closing along y) when the arm bends over the table with the hand down. Its
F/T frame (ft_frame) is at the flange, the palm below it, the two fingers (finger_joint and its
mimic, each pad 0 = closed to 0.045 = open from the centre plane) and the TCP between the pads,
12 mm above the finger tips. A positive arm_joint_2 or arm_joint_4 leans the arm forward (+x).
The links are long (0.50 + 0.50): the task files' poses reach 0.93 m from the base (x 0.76,
y -0.50) with the hand vertical above them, and the ready pose comes back to 0.28 m.
Run (after `source devel/setup.bash`):
  /usr/bin/python3 arm7_description/models/generate_models.py [OUT_DIR]
"""

import math
import os
import sys

from lfd_tools.robot_models import (DARK_COLOR, Y, Z, HandNames, Link, Robot, generate, geom,
                                    load_scene, parallel_gripper, revolute, scene_file_beside)

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE_FILE = scene_file_beside(HERE)
MOUNT = tuple(load_scene(SCENE_FILE)['base_link_in_world'])  # world position of base_link

SHOULDER_HEIGHT = 0.30  # arm_joint_2 above base_link
UPPER_ARM = 0.50        # arm_joint_2 -> arm_joint_4
FOREARM = 0.50          # arm_joint_4 -> arm_joint_6 (the wrist centre)
FLANGE = 0.045          # the wrist centre -> ft_frame (the flange)

# Per-joint-group actuation: (kp, damping, armature, velocity limit, effort limit), position
# actuators like the humanoid's arm servos: stiff enough that gravity sags the 1 m arm by a few
# millimetres at the hand (arm_joint_2 holds ~60 N m stretched out); damping is integrated
# implicitly by MuJoCo's Euler integrator.
DRIVE = {
    'shoulder': (10000.0, 300.0, 0.5, 2.0, 300.0),
    'elbow': (4000.0, 120.0, 0.4, 2.5, 150.0),
    'wrist': (400.0, 8.0, 0.05, 4.0, 30.0),
    'gripper': (1500.0, 40.0, 0.05, 0.15, 40.0),
}

# The MJCF sensors: (kind, name, site). ft_frame is emitted as a site of the hand (the wrench
# between the hand and the flange carries the gripper and any grasped load). No IMU.
SENSORS = [
    ('force', 'ft_force', 'ft_frame'),
    ('torque', 'ft_torque', 'ft_frame'),
    ('touch', 'pad_left', 'touch_left_site'),
    ('touch', 'pad_right', 'touch_right_site'),
]
# The hand's names (the shared parallel gripper, lfd_tools.robot_models.parallel_gripper).
HAND = HandNames(ft_frame='ft_frame', ft_joint='ft_joint', palm='hand', palm_joint='hand_joint',
                 finger_left='finger_left', finger_right='finger_right',
                 finger_joint='finger_joint', mimic_joint='finger_joint_mimic',
                 pad_left='finger_left_pad', pad_right='finger_right_pad',
                 touch_left='touch_left_site', touch_right='touch_right_site',
                 tcp='tcp', tcp_joint='tcp_joint')


def stand_links():
    """base_link at the mount point: the arm's base and the column (with its foot) to the floor.
    The column is visual only in the MJCF (it stands clear of the table and the objects)."""
    height = MOUNT[2]
    return [Link('base_link', None, None, MOUNT, 6.0, [
        geom('cylinder', (0.09, 0.05), (0.0, 0.0, 0.05), color=DARK_COLOR),
        geom('cylinder', (0.06, height / 2), (0.0, 0.0, -height / 2)),
        geom('box', (0.15, 0.15, 0.01), (0.0, 0.0, 0.01 - height), color=DARK_COLOR)])]


def arm_links():
    return [
        Link('arm_link_1', 'base_link', revolute('arm_joint_1', Z, -2.90, 2.90, DRIVE['shoulder']),
             (0.0, 0.0, 0.10), 4.0, [geom('cylinder', (0.07, 0.09), (0.0, 0.0, 0.09))]),
        Link('arm_link_2', 'arm_link_1', revolute('arm_joint_2', Y, -2.00, 2.00, DRIVE['shoulder']),
             (0.0, 0.0, SHOULDER_HEIGHT - 0.10), 3.0, [geom('sphere', (0.07,), color=DARK_COLOR)]),
        Link('arm_link_3', 'arm_link_2', revolute('arm_joint_3', Z, -2.90, 2.90, DRIVE['shoulder']),
             (0.0, 0.0, 0.0), 3.5, [geom('cylinder', (0.055, 0.19), (0.0, 0.0, 0.25))]),
        Link('arm_link_4', 'arm_link_3', revolute('arm_joint_4', Y, -0.30, 3.00, DRIVE['elbow']),
             (0.0, 0.0, UPPER_ARM), 2.0, [geom('sphere', (0.06,), color=DARK_COLOR)]),
        Link('arm_link_5', 'arm_link_4', revolute('arm_joint_5', Z, -2.90, 2.90, DRIVE['elbow']),
             (0.0, 0.0, 0.0), 2.5,
             [geom('cylinder', (0.05, 0.19), (0.0, 0.0, 0.25), collide=True)]),
        Link('arm_link_6', 'arm_link_5', revolute('arm_joint_6', Y, -2.10, 2.10, DRIVE['wrist']),
             (0.0, 0.0, FOREARM), 1.0, [geom('sphere', (0.045,), color=DARK_COLOR)]),
        Link('arm_link_7', 'arm_link_6', revolute('arm_joint_7', Z, -2.90, 2.90, DRIVE['wrist']),
             (0.0, 0.0, 0.0), 0.3, [geom('cylinder', (0.035, 0.02), (0.0, 0.0, 0.02), collide=True,
                                         color=DARK_COLOR)]),
    ]


def hand_links():
    """The humanoid's gripper (lfd_tools.robot_models.parallel_gripper, jvrc1_description's
    r_gripper_*), renamed, its F/T frame at the flange turned by pi about y so that the hand points
    along the forearm."""
    return parallel_gripper(HAND, 'arm_link_7', (0.0, 0.0, FLANGE), DRIVE['gripper'],
                            ft_rpy=(0.0, math.pi, 0.0))


def robot():
    return Robot('arm7', stand_links() + arm_links() + hand_links(), SENSORS,
                 ft_frame=HAND.ft_frame, finger_pads=HAND.finger_pads())


def main(out_dir=HERE):
    """Writes the three model files into out_dir (default: next to this script; the consistency
    test writes them elsewhere and compares)."""
    generate(robot(), out_dir, SCENE_FILE)


if __name__ == '__main__':
    main(*sys.argv[1:])
