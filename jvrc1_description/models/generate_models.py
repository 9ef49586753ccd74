#!/usr/bin/python3
"""Single source of truth for the lfd robot and workcell models.

Writes, next to this file:
  jvrc1_like.urdf  plain URDF of a JVRC-1-like humanoid with a fixed pelvis and a right gripper
  jvrc1_like.xml   the same robot in MJCF (to be <include>d), with actuators, sites and sensors
  workcell.xml     the MuJoCo scene: robot, floor, table, the stick, the box, the block and the
                   drawer cabinet

The workcell's shared facts (table, the robot's placement, object sizes, park poses, the drawer's
joint and handle) are read from config/scene.yaml, which the task files and the demonstrator read
too; every other number lives in the tables below. Both robot files are emitted from the same link
list, so the URDF and MJCF cannot drift apart (lfd_sim_bridge/test/test_model_consistency.cpp
checks it, and that workcell.xml is what this script makes of scene.yaml).

Conventions: every joint frame is aligned with its parent (no rotation offsets), "P" joints turn
about y, "R" about x, "Y" about z. In the zero pose the robot stands upright with the arms hanging
and the gripper fingers pointing down. R_GRIPPER is the distance (m) of each finger pad from the
gripper centre plane: 0 = closed, 0.045 = fully open (gap = 2 * R_GRIPPER).
The robot's files and the scene it stands in are generated together because the scene includes the
robot (a relative MJCF <include>) and pairs its finger pads with the table; a second robot has its
own description package and its own scene of the same config/scene.yaml.
Run: /usr/bin/python3 jvrc1_description/models/generate_models.py
"""

import math
import os
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
# lfd_config's scene.yaml, beside this package in the source tree (the generator is a developer's
# tool, run there; the installed package ships only its output).
SCENE_FILE = os.path.join(HERE, '..', '..', 'config', 'scene.yaml')


def load_scene(path=SCENE_FILE):
    with open(path) as f:
        return yaml.safe_load(f)


SCENE = load_scene()
PELVIS_HEIGHT = SCENE['base_link_in_world'][2]  # world z of base_link (the pelvis is fixed)
TABLE_TOP = SCENE['table_top']  # world z of the table surface
TABLE_CENTER = tuple(SCENE['table']['center'])  # world xy of the table centre
TABLE_HALF = tuple(SCENE['table']['half_size'])  # half sizes of the table top
# Free objects: mass (kg), colour, contact dimension and friction (sliding, torsional, rolling).
# The stick and the block are grippy; the box slides under a push (the table's friction, 0.4,
# rules every contact with it, so a push or a wipe slides and stops on release).
FREE_OBJECTS = {
    'stick': (0.12, '0.85 0.55 0.15 1', 4, '1.2 0.02 0.001'),
    'box': (1.0, '0.2 0.7 0.3 1', 3, '0.4 0.005 0.0001'),
    'block': (0.10, '0.8 0.2 0.25 1', 4, '1.2 0.02 0.001'),
}
# The drawer: the tray and the handle fin (half sizes, m), the drawer's mass (kg) and its slide's
# damping (N s/m) and dry friction (N): a light pull opens it and it stops when let go. The fin is
# 3 cm thick like the stick: the gripper's position servo closing on it then reaches the effort
# limit (robot.yaml close_effort), where a 1.5 cm fin got half the squeeze.
DRAWER_TRAY_HALF = (0.085, 0.10, 0.035)
DRAWER_FRONT_HALF = (0.005, 0.105, 0.045)
DRAWER_FIN_HALF = (0.035, 0.015, 0.01)
DRAWER_MASS, DRAWER_DAMPING, DRAWER_FRICTION = 0.4, 8.0, 1.5
# The finger tips on the table (wiping): a soft, slippery contact, like a cloth on a wet table
# (MuJoCo impedance 0.5-0.9 over 5 mm: a 6 mm press of the stiff arm gives ~8 N; friction 0.05).
# With the rigid, grippy default the stiff arm hopped on one finger edge (the touch pads read
# 28 N and 0 N in turn), and table friction pushed the hand down by the stroke's speed (3-10 N
# with 0.4): the press must be steady for its touch-down and lift-off to stand out. No grasp
# touches the table with the fingers.
FINGER_TABLE_CONTACT = ('solref="0.02 1" solimp="0.5 0.9 0.005" friction="0.05 0.05 0.005 0.0001 0.0001" '
                        'condim="3"')
FINGERS = (('r_gripper_finger_l', 'r_finger_l_pad'), ('r_gripper_finger_r', 'r_finger_r_pad'))

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

ROBOT_COLOR = '0.75 0.78 0.82 1'
DARK_COLOR = '0.25 0.27 0.30 1'
FINGER_COLOR = '0.20 0.45 0.80 1'


def box_inertia(m, size):
    x, y, z = (2 * s for s in size)
    return (m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12)


def cyl_inertia(m, r, half_len):
    length = 2 * half_len
    ixx = m * (3 * r * r + length * length) / 12
    return (ixx, ixx, m * r * r / 2)


def sphere_inertia(m, r):
    i = 2 * m * r * r / 5
    return (i, i, i)


def geom(kind, size, pos=(0.0, 0.0, 0.0), collide=False, color=ROBOT_COLOR, name=None):
    """kind: box (half sizes), cylinder (radius, half length along z), sphere (radius)."""
    return {'kind': kind, 'size': size, 'pos': pos, 'collide': collide, 'color': color, 'name': name}


def inertia_of(mass, g):
    if g['kind'] == 'box':
        return box_inertia(mass, g['size'])
    if g['kind'] == 'cylinder':
        return cyl_inertia(mass, *g['size'])
    return sphere_inertia(mass, g['size'][0])


class Link:
    """One rigid link; `joint` connects it to `parent` (None for the root)."""

    def __init__(self, name, parent, joint, origin, mass=0.0, geoms=(), sites=()):
        self.name, self.parent, self.joint, self.origin = name, parent, joint, origin
        self.mass, self.geoms, self.sites = mass, list(geoms), list(sites)
        self.inertia = inertia_of(mass, self.geoms[0]) if mass > 0 else None
        self.com = self.geoms[0]['pos'] if mass > 0 else (0.0, 0.0, 0.0)


def revolute(name, axis, lo, hi, group):
    kp, damping, armature, vel, effort = DRIVE[group]
    return {'name': name, 'type': 'revolute', 'axis': axis, 'lo': lo, 'hi': hi, 'kp': kp,
            'damping': damping, 'armature': armature, 'vel': vel, 'effort': effort}


def prismatic(name, axis, lo, hi, group, mimic=None):
    j = revolute(name, axis, lo, hi, group)
    j['type'], j['mimic'] = 'prismatic', mimic
    return j


def fixed(name):
    return {'name': name, 'type': 'fixed'}


X, Y, Z = (1, 0, 0), (0, 1, 0), (0, 0, 1)
NY, NZ = (0, -1, 0), (0, 0, -1)


def leg_links(side):
    s = -1.0 if side == 'R' else 1.0
    p = side.lower()
    # Hip roll range is mirrored so that positive values always mean "towards the other leg" for L.
    roll = (-0.80, 0.35) if side == 'R' else (-0.35, 0.80)
    return [
        Link(f'{p}_hip_p_link', 'base_link', revolute(f'{side}_HIP_P', Y, -2.00, 0.60, 'hip'),
             (0.0, s * 0.096, -0.10), 1.0, [geom('sphere', (0.05,))]),
        Link(f'{p}_hip_r_link', f'{p}_hip_p_link', revolute(f'{side}_HIP_R', X, *roll, 'hip'),
             (0.0, 0.0, 0.0), 1.0, [geom('cylinder', (0.05, 0.04), color=DARK_COLOR)]),
        Link(f'{p}_hip_y_link', f'{p}_hip_r_link', revolute(f'{side}_HIP_Y', Z, -0.80, 0.80, 'hip'),
             (0.0, 0.0, 0.0), 5.0, [geom('cylinder', (0.06, 0.165), (0.0, 0.0, -0.165))]),
        Link(f'{p}_knee_link', f'{p}_hip_y_link', revolute(f'{side}_KNEE', Y, 0.0, 2.40, 'knee'),
             (0.0, 0.0, -0.33), 3.0, [geom('cylinder', (0.05, 0.165), (0.0, 0.0, -0.165))]),
        Link(f'{p}_ankle_r_link', f'{p}_knee_link', revolute(f'{side}_ANKLE_R', X, -0.50, 0.50, 'ankle'),
             (0.0, 0.0, -0.33), 0.5, [geom('sphere', (0.035,), color=DARK_COLOR)]),
        Link(f'{p}_ankle_p_link', f'{p}_ankle_r_link', revolute(f'{side}_ANKLE_P', Y, -1.20, 0.80, 'ankle'),
             (0.0, 0.0, 0.0), 1.5, [geom('box', (0.11, 0.05, 0.02), (0.03, 0.0, -0.068))]),
    ]


def arm_links(side):
    s = -1.0 if side == 'R' else 1.0
    p = side.lower()
    # Shoulder roll: negative moves the right arm outwards (away from the body), mirrored for L.
    roll = (-1.75, 0.35) if side == 'R' else (-0.35, 1.75)
    collide = side == 'R'  # only the working (right) forearm and hand touch the world
    links = [
        Link(f'{p}_shoulder_p_link', 'chest_link', revolute(f'{side}_SHOULDER_P', Y, -3.10, 1.00, 'shoulder'),
             (0.0, s * 0.21, 0.36), 0.8, [geom('sphere', (0.05,), color=DARK_COLOR)]),
        Link(f'{p}_shoulder_r_link', f'{p}_shoulder_p_link', revolute(f'{side}_SHOULDER_R', X, *roll, 'shoulder'),
             (0.0, 0.0, 0.0), 0.8, [geom('cylinder', (0.045, 0.04), color=DARK_COLOR)]),
        Link(f'{p}_shoulder_y_link', f'{p}_shoulder_r_link', revolute(f'{side}_SHOULDER_Y', Z, -1.60, 1.60, 'shoulder'),
             (0.0, 0.0, 0.0), 2.0, [geom('cylinder', (0.045, 0.13), (0.0, 0.0, -0.15))]),
        Link(f'{p}_elbow_p_link', f'{p}_shoulder_y_link', revolute(f'{side}_ELBOW_P', Y, -2.50, 0.00, 'elbow'),
             (0.0, 0.0, -0.30), 0.5, [geom('sphere', (0.042,), color=DARK_COLOR)]),
        Link(f'{p}_elbow_y_link', f'{p}_elbow_p_link', revolute(f'{side}_ELBOW_Y', Z, -1.60, 1.60, 'elbow'),
             (0.0, 0.0, 0.0), 1.2, [geom('cylinder', (0.04, 0.11), (0.0, 0.0, -0.13), collide=collide)]),
        Link(f'{p}_wrist_r_link', f'{p}_elbow_y_link', revolute(f'{side}_WRIST_R', X, -1.40, 1.40, 'wrist'),
             (0.0, 0.0, -0.26), 0.2, [geom('sphere', (0.03,), color=DARK_COLOR)]),
    ]
    if side == 'L':
        # Simple paddle hand: the left arm does not manipulate.
        links.append(Link('l_wrist_y_link', 'l_wrist_r_link', revolute('L_WRIST_Y', Y, -1.75, 1.75, 'wrist'),
                          (0.0, 0.0, 0.0), 0.5, [geom('box', (0.02, 0.045, 0.06), (0.0, 0.0, -0.08))]))
        return links
    links += [
        Link('r_wrist_y_link', 'r_wrist_r_link', revolute('R_WRIST_Y', Y, -1.75, 1.75, 'wrist'),
             (0.0, 0.0, 0.0), 0.3, [geom('cylinder', (0.035, 0.02), (0.0, 0.0, -0.02), collide=True,
                                         color=DARK_COLOR)]),
        # Massless frame of the wrist force/torque sensor (at the flange).
        Link('r_wrist_ft', 'r_wrist_y_link', fixed('R_WRIST_FT_JOINT'), (0.0, 0.0, -0.045)),
        # Palm; everything below it is the load seen by the F/T sensor.
        Link('r_gripper_palm', 'r_wrist_ft', fixed('R_GRIPPER_PALM_JOINT'), (0.0, 0.0, 0.0), 0.35,
             [geom('box', (0.03, 0.06, 0.0175), (0.0, 0.0, -0.0175), collide=True, color=DARK_COLOR)]),
        # Finger frames sit on the pad (inner face); the finger body extends outwards from it.
        Link('r_gripper_finger_l', 'r_gripper_palm', prismatic('R_GRIPPER', Y, 0.0, 0.045, 'gripper'),
             (0.0, 0.0, -0.035), 0.05,
             [geom('box', (0.012, 0.006, 0.03), (0.0, 0.006, -0.03), collide=True, color=FINGER_COLOR,
                   name='r_finger_l_pad')],
             [('r_touch_left_site', (0.0, 0.006, -0.03), (0.013, 0.007, 0.031))]),
        Link('r_gripper_finger_r', 'r_gripper_palm',
             prismatic('R_GRIPPER_MIMIC', NY, 0.0, 0.045, 'gripper', mimic='R_GRIPPER'),
             (0.0, 0.0, -0.035), 0.05,
             [geom('box', (0.012, 0.006, 0.03), (0.0, -0.006, -0.03), collide=True, color=FINGER_COLOR,
                   name='r_finger_r_pad')],
             [('r_touch_right_site', (0.0, -0.006, -0.03), (0.013, 0.007, 0.031))]),
        # Tool centre point: between the pads, 12 mm above the finger tips.
        Link('r_gripper_tcp', 'r_gripper_palm', fixed('R_GRIPPER_TCP_JOINT'), (0.0, 0.0, -0.083)),
    ]
    return links


def robot_links():
    links = [Link('base_link', None, None, (0.0, 0.0, PELVIS_HEIGHT), 8.0,
                  [geom('box', (0.10, 0.14, 0.07), (0.0, 0.0, 0.0), color=DARK_COLOR)])]
    links += leg_links('R') + leg_links('L')
    links += [
        Link('waist_y_link', 'base_link', revolute('WAIST_Y', Z, -1.05, 1.05, 'waist'),
             (0.0, 0.0, 0.10), 1.0, [geom('cylinder', (0.06, 0.03), color=DARK_COLOR)]),
        Link('waist_p_link', 'waist_y_link', revolute('WAIST_P', Y, -0.35, 1.05, 'waist'),
             (0.0, 0.0, 0.0), 1.0, [geom('sphere', (0.06,), color=DARK_COLOR)]),
        Link('chest_link', 'waist_p_link', revolute('WAIST_R', X, -0.50, 0.50, 'waist'),
             (0.0, 0.0, 0.0), 12.0, [geom('box', (0.11, 0.16, 0.16), (0.0, 0.0, 0.22))]),
        Link('neck_y_link', 'chest_link', revolute('NECK_Y', Z, -1.20, 1.20, 'neck'),
             (0.0, 0.0, 0.44), 0.3, [geom('cylinder', (0.035, 0.03), (0.0, 0.0, 0.02), color=DARK_COLOR)]),
        Link('neck_r_link', 'neck_y_link', revolute('NECK_R', X, -0.50, 0.50, 'neck'),
             (0.0, 0.0, 0.0), 0.3, [geom('sphere', (0.03,), color=DARK_COLOR)]),
        Link('head_link', 'neck_r_link', revolute('NECK_P', Y, -0.60, 0.90, 'neck'),
             (0.0, 0.0, 0.0), 3.0, [geom('sphere', (0.11,), (0.01, 0.0, 0.15))]),
    ]
    links += arm_links('R') + arm_links('L')
    return links


# ----------------------------------------------------------------------------------------------
# URDF


def fmt(v):
    return ' '.join(f'{x:.6g}' for x in v)


def quat_of_yaw(yaw):
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def free_box(name, park, mass, half, rgba, condim, friction):
    """MJCF of a free-floating box-shaped object (solid inertia) that the robot manipulates, at its
    park pose [x, y, z, yaw]."""
    return f'''    <body name="{name}" pos="{fmt(park[:3])}" quat="{fmt(quat_of_yaw(park[3]))}">
      <joint name="{name}_free" type="free" damping="0.0005"/>
      <inertial pos="0 0 0" mass="{mass}" diaginertia="{fmt(box_inertia(mass, half))}"/>
      <geom name="{name}_geom" type="box" size="{fmt(half)}" rgba="{rgba}"
            contype="1" conaffinity="1" condim="{condim}" friction="{friction}"/>
    </body>'''


def drawer_cabinet(name, spec):
    """MJCF of the drawer cabinet (a mocap body: placed, never pushed) with its sliding drawer and
    the handle fin (body drawer_handle, framed at the grip point of config/scene.yaml). The drawer
    slides through the solid cabinet (their contact is excluded, write_workcell)."""
    half, park = spec['half_size'], spec['park']
    (joint, j), = spec['joints'].items()
    hx, hy, hz = half
    handle = spec['frames']['handle']
    grip = handle['pose'][:3]
    tray = (round(hx - DRAWER_TRAY_HALF[0] - 0.005, 6) + 0.0, 0.0, 0.01 + DRAWER_TRAY_HALF[2])
    front = (hx + DRAWER_FRONT_HALF[0], 0.0, DRAWER_FRONT_HALF[2] + 0.005)
    fin_x = hx + 2 * DRAWER_FRONT_HALF[0] + DRAWER_FIN_HALF[0]  # the fin starts at the front
    fin = (fin_x - grip[0], 0.0, 0.0)
    wood = 'rgba="0.55 0.4 0.3 1" contype="1" conaffinity="1" condim="3"'
    return f'''    <body name="{name}" mocap="true" pos="{fmt(park[:3])}" quat="{fmt(quat_of_yaw(park[3]))}">
      <geom name="drawer_cabinet" type="box" size="{fmt(half)}" pos="0 0 {hz:.6g}" {wood}/>
      <body name="{name}_tray" pos="0 0 0">
        <joint name="{joint}" type="slide" axis="{fmt(j['axis'])}" limited="true" range="{fmt(j['range'])}"
               damping="{DRAWER_DAMPING}" frictionloss="{DRAWER_FRICTION}" armature="0.05"/>
        <inertial pos="{fmt(tray)}" mass="{DRAWER_MASS}" diaginertia="{fmt(box_inertia(DRAWER_MASS, DRAWER_TRAY_HALF))}"/>
        <geom name="drawer_tray" type="box" size="{fmt(DRAWER_TRAY_HALF)}" pos="{fmt(tray)}" {wood}/>
        <geom name="drawer_front" type="box" size="{fmt(DRAWER_FRONT_HALF)}" pos="{fmt(front)}"
              rgba="0.7 0.55 0.4 1" contype="1" conaffinity="1" condim="3"/>
        <body name="{handle['body']}" pos="{fmt(grip)}">
          <geom name="drawer_fin" type="box" size="{fmt(DRAWER_FIN_HALF)}" pos="{fmt(fin)}"
                rgba="0.3 0.3 0.35 1" contype="1" conaffinity="1" condim="4" friction="1.2 0.02 0.001"/>
        </body>
      </body>
    </body>'''


def urdf_geometry(g):
    if g['kind'] == 'box':
        return f'<box size="{fmt(2 * s for s in g["size"])}"/>'
    if g['kind'] == 'cylinder':
        return f'<cylinder radius="{g["size"][0]:.6g}" length="{2 * g["size"][1]:.6g}"/>'
    return f'<sphere radius="{g["size"][0]:.6g}"/>'


def write_urdf(links, path):
    out = ['<?xml version="1.0"?>',
           '<!-- GENERATED by generate_models.py; edit the generator, not this file. -->',
           '<robot name="jvrc1_like">',
           '  <material name="robot"><color rgba="0.75 0.78 0.82 1"/></material>',
           '  <link name="world"/>',
           '  <joint name="world_to_base_link" type="fixed">',
           '    <parent link="world"/><child link="base_link"/>',
           f'    <origin xyz="0 0 {PELVIS_HEIGHT}" rpy="0 0 0"/>',
           '  </joint>']
    for link in links:
        out.append(f'  <link name="{link.name}">')
        if link.mass > 0:
            ixx, iyy, izz = link.inertia
            out += ['    <inertial>',
                    f'      <origin xyz="{fmt(link.com)}" rpy="0 0 0"/>',
                    f'      <mass value="{link.mass:.6g}"/>',
                    f'      <inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{iyy:.6g}" iyz="0" izz="{izz:.6g}"/>',
                    '    </inertial>']
        for g in link.geoms:
            for tag in ('visual', 'collision'):
                out += [f'    <{tag}>', f'      <origin xyz="{fmt(g["pos"])}" rpy="0 0 0"/>',
                        f'      <geometry>{urdf_geometry(g)}</geometry>']
                if tag == 'visual':
                    out.append(f'      <material name="robot"><color rgba="{g["color"]}"/></material>')
                out.append(f'    </{tag}>')
        out.append('  </link>')
        if link.parent is None:
            continue
        j = link.joint
        out += [f'  <joint name="{j["name"]}" type="{j["type"]}">',
                f'    <parent link="{link.parent}"/><child link="{link.name}"/>',
                f'    <origin xyz="{fmt(link.origin)}" rpy="0 0 0"/>']
        if j['type'] != 'fixed':
            out += [f'    <axis xyz="{fmt(j["axis"])}"/>',
                    f'    <limit lower="{j["lo"]:.6g}" upper="{j["hi"]:.6g}" effort="{j["effort"]:.6g}" '
                    f'velocity="{j["vel"]:.6g}"/>',
                    f'    <dynamics damping="{j["damping"]:.6g}"/>']
            if j.get('mimic'):
                out.append(f'    <mimic joint="{j["mimic"]}" multiplier="1" offset="0"/>')
        out.append('  </joint>')
    out.append('</robot>')
    with open(path, 'w') as f:
        f.write('\n'.join(out) + '\n')


# ----------------------------------------------------------------------------------------------
# MJCF


def mj_geom(g, indent):
    size = fmt(g['size'])
    kind = g['kind']
    # Collision on the right forearm/hand only (contype 2 never meets itself: no self-collision).
    cls = 'collide' if g['collide'] else 'visual'
    name = f' name="{g["name"]}"' if g['name'] else ''
    return f'{indent}<geom{name} class="{cls}" type="{kind}" size="{size}" pos="{fmt(g["pos"])}" rgba="{g["color"]}"/>'


def write_mjcf_robot(links, path):
    children = {}
    for link in links:
        children.setdefault(link.parent, []).append(link)
    actuated = [l.joint for l in links if l.joint and l.joint['type'] != 'fixed' and not l.joint.get('mimic')]

    body_lines = []

    def emit(link, depth, frame_offset):
        ind = '  ' * depth
        pos = tuple(a + b for a, b in zip(link.origin, frame_offset))
        j = link.joint
        if j is not None and j['type'] == 'fixed':
            # Massless frames fold into their parent as sites; their children shift by the offset.
            if link.mass == 0:
                # A leaf frame becomes a site; r_wrist_ft (which has the palm below it) is emitted as a
                # site of the palm body instead, because a MuJoCo force sensor measures the wrench
                # between the site's body and its parent.
                if not children.get(link.name):
                    body_lines.append(f'{ind}<site name="{link.name}" pos="{fmt(pos)}" size="0.01" group="3"/>')
                for child in children.get(link.name, []):
                    emit(child, depth, pos)
                return
        body_lines.append(f'{ind}<body name="{link.name}" pos="{fmt(pos)}">')
        ixx, iyy, izz = link.inertia
        body_lines.append(f'{ind}  <inertial pos="{fmt(link.com)}" mass="{link.mass:.6g}" '
                          f'diaginertia="{ixx:.6g} {iyy:.6g} {izz:.6g}"/>')
        if j is not None and j['type'] != 'fixed':
            kind = 'hinge' if j['type'] == 'revolute' else 'slide'
            body_lines.append(
                f'{ind}  <joint name="{j["name"]}" type="{kind}" axis="{fmt(j["axis"])}" limited="true" '
                f'range="{j["lo"]:.6g} {j["hi"]:.6g}" damping="{j["damping"]:.6g}" armature="{j["armature"]:.6g}"/>')
        if link.name == 'base_link':
            body_lines.append(f'{ind}  <site name="imu" pos="0 0 0" size="0.01" group="3"/>')
        if link.name == 'r_gripper_palm':
            # The wrench between the palm and the wrist carries the gripper and any grasped load.
            body_lines.append(f'{ind}  <site name="r_wrist_ft" pos="0 0 0" size="0.01" group="3"/>')
        for g in link.geoms:
            body_lines.append(mj_geom(g, ind + '  '))
        for name, spos, ssize in link.sites:
            body_lines.append(f'{ind}  <site name="{name}" type="box" pos="{fmt(spos)}" size="{fmt(ssize)}" '
                              f'rgba="1 0.3 0.3 0.3" group="3"/>')
        for child in children.get(link.name, []):
            emit(child, depth + 1, (0.0, 0.0, 0.0))
        body_lines.append(f'{ind}</body>')

    for root in children[None]:
        emit(root, 2, (0.0, 0.0, 0.0))

    out = ['<!-- GENERATED by generate_models.py; edit the generator, not this file. -->',
           '<mujoco model="jvrc1_like">',
           '  <compiler angle="radian" inertiafromgeom="false"/>',
           '  <default>',
           '    <default class="visual">',
           '      <geom contype="0" conaffinity="0" group="1"/>',
           '    </default>',
           '    <default class="collide">',
           # contype 2 / conaffinity 1: touches the world (type 1) but never another robot geom.
           '      <geom contype="2" conaffinity="1" group="2" condim="4" friction="1.5 0.02 0.001" '
           'solref="0.004 1" solimp="0.95 0.99 0.001"/>',
           '    </default>',
           '  </default>',
           '  <worldbody>']
    out += body_lines
    out += ['  </worldbody>',
            '  <equality>',
            '    <joint name="r_gripper_coupling" joint1="R_GRIPPER_MIMIC" joint2="R_GRIPPER" '
            'polycoef="0 1 0 0 0" solref="0.004 1"/>',
            '  </equality>',
            '  <actuator>']
    for j in actuated:
        out.append(f'    <position name="{j["name"]}" joint="{j["name"]}" kp="{j["kp"]:.6g}" ctrllimited="true" '
                   f'ctrlrange="{j["lo"]:.6g} {j["hi"]:.6g}" forcelimited="true" '
                   f'forcerange="{-j["effort"]:.6g} {j["effort"]:.6g}"/>')
    out += ['  </actuator>',
            '  <sensor>',
            '    <force name="r_wrist_force" site="r_wrist_ft"/>',
            '    <torque name="r_wrist_torque" site="r_wrist_ft"/>',
            '    <touch name="r_touch_left" site="r_touch_left_site"/>',
            '    <touch name="r_touch_right" site="r_touch_right_site"/>',
            '    <gyro name="imu_gyro" site="imu"/>',
            '    <accelerometer name="imu_accel" site="imu"/>',
            '    <framequat name="imu_quat" objtype="site" objname="imu"/>',
            '  </sensor>',
            '</mujoco>']
    with open(path, 'w') as f:
        f.write('\n'.join(out) + '\n')


def write_workcell(path):
    tx, ty = TABLE_CENTER
    hx, hy, hz = TABLE_HALF
    top_center_z = TABLE_TOP - hz
    leg_half = (TABLE_TOP - 2 * hz) / 2
    legs = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            legs.append(f'      <geom type="box" size="0.025 0.025 {leg_half:.4g}" '
                        f'pos="{sx * (hx - 0.05):.4g} {sy * (hy - 0.05):.4g} {-hz - leg_half:.4g}" '
                        'rgba="0.45 0.32 0.2 1" contype="0" conaffinity="0"/>')
    objects = []
    for name, spec in SCENE['objects'].items():
        if spec.get('fixed'):
            objects.append(drawer_cabinet(name, spec))
        else:
            mass, rgba, condim, friction = FREE_OBJECTS[name]
            objects.append(free_box(name, spec['park'], mass, spec['half_size'], rgba, condim, friction))
    objects = '\n'.join(objects)
    # A mocap body counts as welded to the world, so MuJoCo's parent filter does not keep its
    # child from colliding with it: the drawer slides through its solid cabinet by exclusion.
    excludes = [f'    <exclude body1="{name}" body2="{name}_tray"/>'
                for name, spec in SCENE['objects'].items() if spec.get('fixed')]
    for body, geom in FINGERS:  # the tips' own contact with the table replaces the default one
        excludes.append(f'    <exclude body1="{body}" body2="table"/>')
        excludes.append(f'    <pair geom1="{geom}" geom2="table_top" {FINGER_TABLE_CONTACT}/>')
    excludes = '\n'.join(excludes)
    out = f'''<!-- GENERATED by generate_models.py from config/scene.yaml; edit those, not this file. -->
<mujoco model="lfd_workcell">
  <include file="jvrc1_like.xml"/>
  <!-- 1 kHz physics. Elliptic friction cones with a high impratio keep a pinch grasp from creeping;
       the Euler integrator treats the (large) joint damping implicitly; sparse Jacobians are a
       little faster for this 46-DoF tree. -->
  <option timestep="0.001" integrator="Euler" cone="elliptic" impratio="10" iterations="50"
          tolerance="1e-8" noslip_iterations="0" jacobian="sparse"/>
  <size njmax="600" nconmax="150"/>
  <visual>
    <global offwidth="1280" offheight="720"/>
    <quality shadowsize="2048"/>
  </visual>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1="0.2 0.3 0.4" rgb2="0.3 0.4 0.5" width="256" height="256"/>
    <material name="floor" texture="grid" texrepeat="8 8" reflectance="0.1"/>
  </asset>
  <worldbody>
    <light name="sun" pos="0.5 -1 3" dir="-0.2 0.3 -1" directional="true" diffuse="0.8 0.8 0.8"/>
    <camera name="overview" pos="1.9 -1.4 1.7" xyaxes="0.6 0.8 0 -0.35 0.26 0.9"/>
    <geom name="floor" type="plane" size="3 3 0.1" material="floor" contype="1" conaffinity="1"/>
    <!-- Table: top surface at z = {TABLE_TOP} m, spans x [{tx - hx:.2f}, {tx + hx:.2f}], y [{ty - hy:.2f}, {ty + hy:.2f}]. -->
    <body name="table" pos="{tx} {ty} {top_center_z:.4g}">
      <geom name="table_top" type="box" size="{hx} {hy} {hz}" rgba="0.6 0.45 0.3 1" contype="1" conaffinity="1"
            friction="0.4 0.005 0.0001" condim="3" priority="1"/>
{chr(10).join(legs)}
    </body>
    <!-- The objects of config/scene.yaml at their park poses (far left of the table, out of the
         robot's way): the stick (a square bar that cannot roll), the box, the block, the drawer. -->
{objects}
  </worldbody>
  <contact>
{excludes}
  </contact>
</mujoco>
'''
    with open(path, 'w') as f:
        f.write(out)


def main(out_dir=HERE):
    """Writes the three model files into out_dir (default: next to this script; the consistency
    test writes them elsewhere and compares)."""
    links = robot_links()
    total = sum(l.mass for l in links)
    write_urdf(links, os.path.join(out_dir, 'jvrc1_like.urdf'))
    write_mjcf_robot(links, os.path.join(out_dir, 'jvrc1_like.xml'))
    write_workcell(os.path.join(out_dir, 'workcell.xml'))
    print(f'wrote jvrc1_like.urdf, jvrc1_like.xml, workcell.xml ({len(links)} links, {total:.1f} kg)')


if __name__ == '__main__':
    main(*sys.argv[1:])
