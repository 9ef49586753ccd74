#!/usr/bin/python3
"""Single source of truth for the lfd robot and workcell models.

Writes, next to this file:
  jvrc1_like.urdf  plain URDF of a JVRC-1-like humanoid with a fixed pelvis and a right gripper
  jvrc1_like.xml   the same robot in MJCF (to be <include>d), with actuators, sites and sensors
  workcell.xml     the MuJoCo scene: robot, floor, table, the stick, the box, the block and the
                   drawer cabinet

The workcell's shared facts (table, the robot's placement, object sizes, park poses, the drawer's
joint and handle) are read from config/scene.yaml, which the task files and the demonstrator read
too; the robot's numbers live in the tables below, and the writers (URDF, MJCF, workcell) are the
robot-independent lfd_tools.robot_models (lfd_tools/src/lfd_tools, importable after
`source devel/setup.bash`). Both robot files are emitted from the same link list, so the URDF and
MJCF cannot drift apart (lfd_sim_bridge/test/test_model_consistency.cpp checks it, and that
workcell.xml is what this script makes of scene.yaml).

Conventions: every joint frame is aligned with its parent (no rotation offsets), "P" joints turn
about y, "R" about x, "Y" about z. In the zero pose the robot stands upright with the arms hanging
and the gripper fingers pointing down. R_GRIPPER is the distance (m) of each finger pad from the
gripper centre plane: 0 = closed, 0.045 = fully open (gap = 2 * R_GRIPPER).
The robot's files and the scene it stands in are generated together because the scene includes the
robot (a relative MJCF <include>) and pairs its finger pads with the table; a second robot has its
own description package and its own scene of the same config/scene.yaml.
Run (after `source devel/setup.bash`):
  /usr/bin/python3 jvrc1_description/models/generate_models.py [OUT_DIR]
"""

import os
import sys

from lfd_tools.robot_models import (DARK_COLOR, X, Y, Z, HandNames, Link, Robot, generate, geom,
                                    load_scene, parallel_gripper, revolute, scene_file_beside)

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE_FILE = scene_file_beside(HERE)
# world z of base_link (the pelvis is fixed)
PELVIS_HEIGHT = load_scene(SCENE_FILE)['base_link_in_world'][2]

# Per-joint-group actuation: (kp, damping, armature, velocity limit, effort limit).
# Gains are stiff, like a high-ratio position-controlled humanoid servo, so that gravity sag stays
# at a few millimetres at the hand; damping is integrated implicitly by MuJoCo's Euler integrator.
DRIVE = {
    'hip': (3000.0, 60.0, 0.5, 4.0, 200.0),
    'knee': (3000.0, 60.0, 0.5, 4.0, 300.0),
    'ankle': (1500.0, 30.0, 0.3, 4.0, 150.0),
    'waist': (8000.0, 300.0, 0.8, 2.0, 300.0),
    'neck': (200.0, 4.0, 0.05, 4.0, 20.0),
    'shoulder': (4000.0, 120.0, 0.4, 3.0, 150.0),
    'elbow': (2000.0, 50.0, 0.2, 3.5, 80.0),
    'wrist': (400.0, 8.0, 0.05, 4.0, 30.0),
    'gripper': (1500.0, 40.0, 0.05, 0.15, 40.0),
}

# The MJCF sensors: (kind, name, site). The F/T site is the massless frame r_wrist_ft, emitted on
# the palm; the IMU site sits at the pelvis.
SENSORS = [
    ('force', 'r_wrist_force', 'r_wrist_ft'),
    ('torque', 'r_wrist_torque', 'r_wrist_ft'),
    ('touch', 'r_touch_left', 'r_touch_left_site'),
    ('touch', 'r_touch_right', 'r_touch_right_site'),
    ('gyro', 'imu_gyro', 'imu'),
    ('accelerometer', 'imu_accel', 'imu'),
    ('framequat', 'imu_quat', 'imu'),
]
# The right hand: the shared parallel gripper (lfd_tools.robot_models.parallel_gripper) under these
# names, its F/T frame r_wrist_ft at the flange 4.5 cm below the wrist.
HAND = HandNames(ft_frame='r_wrist_ft', ft_joint='R_WRIST_FT_JOINT',
                 palm='r_gripper_palm', palm_joint='R_GRIPPER_PALM_JOINT',
                 finger_left='r_gripper_finger_l', finger_right='r_gripper_finger_r',
                 finger_joint='R_GRIPPER', mimic_joint='R_GRIPPER_MIMIC',
                 pad_left='r_finger_l_pad', pad_right='r_finger_r_pad',
                 touch_left='r_touch_left_site', touch_right='r_touch_right_site',
                 tcp='r_gripper_tcp', tcp_joint='R_GRIPPER_TCP_JOINT')
OPTION_NOTE = ('1 kHz physics. Elliptic friction cones with a high impratio keep a pinch grasp '
               'from creeping;\n'
               '       the Euler integrator treats the (large) joint damping implicitly; sparse '
               'Jacobians are a\n'
               '       little faster for this 46-DoF tree.')


def leg_links(side):
    s = -1.0 if side == 'R' else 1.0
    p = side.lower()
    # Hip roll range is mirrored so that positive values always mean "towards the other leg" for L.
    roll = (-0.80, 0.35) if side == 'R' else (-0.35, 0.80)
    return [
        Link(f'{p}_hip_p_link', 'base_link',
             revolute(f'{side}_HIP_P', Y, -2.00, 0.60, DRIVE['hip']), (0.0, s * 0.096, -0.10), 1.0,
             [geom('sphere', (0.05,))]),
        Link(f'{p}_hip_r_link', f'{p}_hip_p_link',
             revolute(f'{side}_HIP_R', X, *roll, DRIVE['hip']), (0.0, 0.0, 0.0), 1.0,
             [geom('cylinder', (0.05, 0.04), color=DARK_COLOR)]),
        Link(f'{p}_hip_y_link', f'{p}_hip_r_link',
             revolute(f'{side}_HIP_Y', Z, -0.80, 0.80, DRIVE['hip']), (0.0, 0.0, 0.0), 5.0,
             [geom('cylinder', (0.06, 0.165), (0.0, 0.0, -0.165))]),
        Link(f'{p}_knee_link', f'{p}_hip_y_link',
             revolute(f'{side}_KNEE', Y, 0.0, 2.40, DRIVE['knee']), (0.0, 0.0, -0.33), 3.0,
             [geom('cylinder', (0.05, 0.165), (0.0, 0.0, -0.165))]),
        Link(f'{p}_ankle_r_link', f'{p}_knee_link',
             revolute(f'{side}_ANKLE_R', X, -0.50, 0.50, DRIVE['ankle']), (0.0, 0.0, -0.33), 0.5,
             [geom('sphere', (0.035,), color=DARK_COLOR)]),
        Link(f'{p}_ankle_p_link', f'{p}_ankle_r_link',
             revolute(f'{side}_ANKLE_P', Y, -1.20, 0.80, DRIVE['ankle']), (0.0, 0.0, 0.0), 1.5,
             [geom('box', (0.11, 0.05, 0.02), (0.03, 0.0, -0.068))]),
    ]


def arm_links(side):
    s = -1.0 if side == 'R' else 1.0
    p = side.lower()
    # Shoulder roll: negative moves the right arm outwards (away from the body), mirrored for L.
    roll = (-1.75, 0.35) if side == 'R' else (-0.35, 1.75)
    collide = side == 'R'  # only the working (right) forearm and hand touch the world
    links = [
        Link(f'{p}_shoulder_p_link', 'chest_link',
             revolute(f'{side}_SHOULDER_P', Y, -3.10, 1.00, DRIVE['shoulder']),
             (0.0, s * 0.21, 0.36), 0.8, [geom('sphere', (0.05,), color=DARK_COLOR)]),
        Link(f'{p}_shoulder_r_link', f'{p}_shoulder_p_link',
             revolute(f'{side}_SHOULDER_R', X, *roll, DRIVE['shoulder']), (0.0, 0.0, 0.0), 0.8,
             [geom('cylinder', (0.045, 0.04), color=DARK_COLOR)]),
        Link(f'{p}_shoulder_y_link', f'{p}_shoulder_r_link',
             revolute(f'{side}_SHOULDER_Y', Z, -1.60, 1.60, DRIVE['shoulder']), (0.0, 0.0, 0.0),
             2.0, [geom('cylinder', (0.045, 0.13), (0.0, 0.0, -0.15))]),
        Link(f'{p}_elbow_p_link', f'{p}_shoulder_y_link',
             revolute(f'{side}_ELBOW_P', Y, -2.50, 0.00, DRIVE['elbow']), (0.0, 0.0, -0.30), 0.5,
             [geom('sphere', (0.042,), color=DARK_COLOR)]),
        Link(f'{p}_elbow_y_link', f'{p}_elbow_p_link',
             revolute(f'{side}_ELBOW_Y', Z, -1.60, 1.60, DRIVE['elbow']), (0.0, 0.0, 0.0), 1.2,
             [geom('cylinder', (0.04, 0.11), (0.0, 0.0, -0.13), collide=collide)]),
        Link(f'{p}_wrist_r_link', f'{p}_elbow_y_link',
             revolute(f'{side}_WRIST_R', X, -1.40, 1.40, DRIVE['wrist']), (0.0, 0.0, -0.26), 0.2,
             [geom('sphere', (0.03,), color=DARK_COLOR)]),
    ]
    if side == 'L':
        # Simple paddle hand: the left arm does not manipulate.
        links.append(Link('l_wrist_y_link', 'l_wrist_r_link',
                          revolute('L_WRIST_Y', Y, -1.75, 1.75, DRIVE['wrist']), (0.0, 0.0, 0.0),
                          0.5, [geom('box', (0.02, 0.045, 0.06), (0.0, 0.0, -0.08))]))
        return links
    links += [
        Link('r_wrist_y_link', 'r_wrist_r_link',
             revolute('R_WRIST_Y', Y, -1.75, 1.75, DRIVE['wrist']),
             (0.0, 0.0, 0.0), 0.3, [geom('cylinder', (0.035, 0.02), (0.0, 0.0, -0.02), collide=True,
                                         color=DARK_COLOR)]),
    ]
    links += parallel_gripper(HAND, 'r_wrist_y_link', (0.0, 0.0, -0.045), DRIVE['gripper'])
    return links


def robot_links():
    links = [Link('base_link', None, None, (0.0, 0.0, PELVIS_HEIGHT), 8.0,
                  [geom('box', (0.10, 0.14, 0.07), (0.0, 0.0, 0.0), color=DARK_COLOR)])]
    links += leg_links('R') + leg_links('L')
    links += [
        Link('waist_y_link', 'base_link', revolute('WAIST_Y', Z, -1.05, 1.05, DRIVE['waist']),
             (0.0, 0.0, 0.10), 1.0, [geom('cylinder', (0.06, 0.03), color=DARK_COLOR)]),
        Link('waist_p_link', 'waist_y_link', revolute('WAIST_P', Y, -0.35, 1.05, DRIVE['waist']),
             (0.0, 0.0, 0.0), 1.0, [geom('sphere', (0.06,), color=DARK_COLOR)]),
        Link('chest_link', 'waist_p_link', revolute('WAIST_R', X, -0.50, 0.50, DRIVE['waist']),
             (0.0, 0.0, 0.0), 12.0, [geom('box', (0.11, 0.16, 0.16), (0.0, 0.0, 0.22))]),
        Link('neck_y_link', 'chest_link', revolute('NECK_Y', Z, -1.20, 1.20, DRIVE['neck']),
             (0.0, 0.0, 0.44), 0.3,
             [geom('cylinder', (0.035, 0.03), (0.0, 0.0, 0.02), color=DARK_COLOR)]),
        Link('neck_r_link', 'neck_y_link', revolute('NECK_R', X, -0.50, 0.50, DRIVE['neck']),
             (0.0, 0.0, 0.0), 0.3, [geom('sphere', (0.03,), color=DARK_COLOR)]),
        Link('head_link', 'neck_r_link', revolute('NECK_P', Y, -0.60, 0.90, DRIVE['neck']),
             (0.0, 0.0, 0.0), 3.0, [geom('sphere', (0.11,), (0.01, 0.0, 0.15))]),
    ]
    links += arm_links('R') + arm_links('L')
    return links


def robot():
    return Robot('jvrc1_like', robot_links(), SENSORS, ft_frame=HAND.ft_frame,
                 imu=('imu', 'base_link'), finger_pads=HAND.finger_pads(), option_note=OPTION_NOTE)


def main(out_dir=HERE):
    """Writes the three model files into out_dir (default: next to this script; the consistency
    test writes them elsewhere and compares)."""
    generate(robot(), out_dir, SCENE_FILE)


if __name__ == '__main__':
    main(*sys.argv[1:])
