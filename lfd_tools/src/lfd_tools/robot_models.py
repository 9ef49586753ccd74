"""The robot-independent half of the robot description generators: one link table in, the URDF,
the MJCF robot (to be <include>d) and the MuJoCo workcell scene of config/scene.yaml out.

A robot description package (jvrc1_description, arm7_description, ...) keeps only its own data in
models/generate_models.py -- its links (Link, with revolute/prismatic/fixed joints and geom()s;
the parallel gripper every robot shares comes from parallel_gripper(), under the robot's own
names, HandNames), and a Robot naming what is robot-specific: the sensors, the massless frame
that becomes the force/torque site, the optional IMU site, the finger pads that get the soft
contact with the table, the include file name -- and calls generate(). The URDF and the MJCF
come from the same link list, so they cannot drift apart
(lfd_sim_bridge/test/test_model_consistency.cpp checks it for every robot, and that the committed
files are what its generator makes of config/scene.yaml).

Conventions: a link's frame is its joint's frame; a joint origin is a translation and, optionally,
a fixed rotation (rpy, URDF convention; most tables use none: every joint frame aligned with its
parent). A massless link on a fixed joint is a frame, not a body: in the MJCF it folds into its
parent (its children shift by its pose), and a leaf frame becomes a site. The root link is fixed in
the world at its origin (the mount point), no rotation.
Gripper mimic joints (a prismatic joint with `mimic`) become MJCF joint equality constraints named
<mimicked joint, lower case>_coupling and are not actuated; every other moving joint has a position
actuator named like it.
"""

import math
import os
from dataclasses import dataclass

import yaml

# ----------------------------------------------------------------------------------------------
# The scene (config/scene.yaml, shared with the task files and the demonstrator)


def scene_file_beside(models_dir):
    """config/scene.yaml of the source tree, for a generator in <repo>/<package>/models (the
    generator is a developer's tool, run there; the installed package ships only its output)."""
    return os.path.join(models_dir, '..', '..', 'config', 'scene.yaml')


def load_scene(path):
    with open(path) as f:
        return yaml.safe_load(f)


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
FINGER_TABLE_CONTACT = ('solref="0.02 1" solimp="0.5 0.9 0.005" '
                        'friction="0.05 0.05 0.005 0.0001 0.0001" condim="3"')

ROBOT_COLOR = '0.75 0.78 0.82 1'
DARK_COLOR = '0.25 0.27 0.30 1'
FINGER_COLOR = '0.20 0.45 0.80 1'

# ----------------------------------------------------------------------------------------------
# Links, geoms, inertia, joints


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
    """kind: box (half sizes), cylinder (radius, half length along z), sphere (radius).
    collide: the geom touches the world in the MJCF (never another robot geom)."""
    return {'kind': kind, 'size': size, 'pos': pos, 'collide': collide, 'color': color,
            'name': name}


def inertia_of(mass, g):
    if g['kind'] == 'box':
        return box_inertia(mass, g['size'])
    if g['kind'] == 'cylinder':
        return cyl_inertia(mass, *g['size'])
    return sphere_inertia(mass, g['size'][0])


class Link:
    """One rigid link; `joint` connects it to `parent` (None for the root, placed at `origin` in the
    world). `origin`: the joint frame in the parent frame (translation), `rpy` its fixed rotation
    (URDF roll-pitch-yaw; zero = aligned with the parent). The first geom carries the inertia.
    sites: (name, pos, box half sizes) of touch sites on this link."""

    def __init__(self, name, parent, joint, origin, mass=0.0, geoms=(), sites=(),
                 rpy=(0.0, 0.0, 0.0)):
        self.name, self.parent, self.joint, self.origin = name, parent, joint, origin
        self.rpy = tuple(rpy)
        self.mass, self.geoms, self.sites = mass, list(geoms), list(sites)
        self.inertia = inertia_of(mass, self.geoms[0]) if mass > 0 else None
        self.com = self.geoms[0]['pos'] if mass > 0 else (0.0, 0.0, 0.0)


def revolute(name, axis, lo, hi, drive):
    """drive: (kp, damping, armature, velocity limit, effort limit) of its position actuator."""
    kp, damping, armature, vel, effort = drive
    return {'name': name, 'type': 'revolute', 'axis': axis, 'lo': lo, 'hi': hi, 'kp': kp,
            'damping': damping, 'armature': armature, 'vel': vel, 'effort': effort}


def prismatic(name, axis, lo, hi, drive, mimic=None):
    """mimic: the joint this one follows (multiplier 1): a MuJoCo equality, no actuator."""
    j = revolute(name, axis, lo, hi, drive)
    j['type'], j['mimic'] = 'prismatic', mimic
    return j


def fixed(name):
    return {'name': name, 'type': 'fixed'}


X, Y, Z = (1, 0, 0), (0, 1, 0), (0, 0, 1)
NY, NZ = (0, -1, 0), (0, 0, -1)


# ----------------------------------------------------------------------------------------------
# The parallel gripper every robot carries (the grasps of the task files are tuned for it)


@dataclass(frozen=True)
class HandNames:
    """The names of one robot's parallel gripper (parallel_gripper()): its links, joints, pad geoms
    and touch sites. Only the names differ from robot to robot; the hand is the same."""
    ft_frame: str       # massless frame of the wrist F/T sensor (a site of the palm in MJCF)
    ft_joint: str       # its fixed joint to the parent link (the flange)
    palm: str           # the palm body: everything from it down is the F/T sensor's load
    palm_joint: str     # fixed, at the F/T frame's origin
    finger_left: str    # finger bodies, framed on their pad's inner face
    finger_right: str
    finger_joint: str   # the driven prismatic joint (left finger, +y): half the pads' opening
    mimic_joint: str    # the right finger's joint (-y), following finger_joint (an MJCF equality)
    pad_left: str       # the pads' collision geoms (soft contact with the table)
    pad_right: str
    touch_left: str     # the pads' touch sites
    touch_right: str
    tcp: str            # tool centre point frame: between the pads, 12 mm above the finger tips
    tcp_joint: str

    def finger_pads(self):
        """Robot(finger_pads=...): (finger body, pad geom) of both fingers."""
        return ((self.finger_left, self.pad_left), (self.finger_right, self.pad_right))


def parallel_gripper(names, parent, ft_origin, drive, ft_rpy=(0.0, 0.0, 0.0)):
    """The links of the parallel gripper hanging from `parent`: the massless F/T frame at
    `ft_origin` (translation in the parent frame) turned by `ft_rpy` (URDF rpy), the palm fixed at
    it, two prismatic fingers (0 = closed to 0.045 m = open, each pad from the centre plane, the
    pads closing along the palm's y; finger_joint drives, mimic_joint follows) with their pads and
    touch sites, and the TCP. The fingers point along the F/T frame's -z. drive: the fingers'
    (kp, damping, armature, velocity limit, effort limit) (revolute())."""
    n = names
    return [
        # Massless frame of the wrist force/torque sensor (at the flange).
        Link(n.ft_frame, parent, fixed(n.ft_joint), tuple(ft_origin), rpy=tuple(ft_rpy)),
        # Palm; everything below it is the load seen by the F/T sensor.
        Link(n.palm, n.ft_frame, fixed(n.palm_joint), (0.0, 0.0, 0.0), 0.35,
             [geom('box', (0.03, 0.06, 0.0175), (0.0, 0.0, -0.0175), collide=True,
                   color=DARK_COLOR)]),
        # Finger frames sit on the pad (inner face); the finger body extends outwards from it.
        Link(n.finger_left, n.palm, prismatic(n.finger_joint, Y, 0.0, 0.045, drive),
             (0.0, 0.0, -0.035), 0.05,
             [geom('box', (0.012, 0.006, 0.03), (0.0, 0.006, -0.03), collide=True,
                   color=FINGER_COLOR, name=n.pad_left)],
             [(n.touch_left, (0.0, 0.006, -0.03), (0.013, 0.007, 0.031))]),
        Link(n.finger_right, n.palm,
             prismatic(n.mimic_joint, NY, 0.0, 0.045, drive, mimic=n.finger_joint),
             (0.0, 0.0, -0.035), 0.05,
             [geom('box', (0.012, 0.006, 0.03), (0.0, -0.006, -0.03), collide=True,
                   color=FINGER_COLOR, name=n.pad_right)],
             [(n.touch_right, (0.0, -0.006, -0.03), (0.013, 0.007, 0.031))]),
        # Tool centre point: between the pads, 12 mm above the finger tips.
        Link(n.tcp, n.palm, fixed(n.tcp_joint), (0.0, 0.0, -0.083)),
    ]


class Robot:
    """What the writers need to know about one robot besides its links.

    name        the URDF robot / MJCF model name; the MJCF robot file is <include> (default
                <name>.xml), included by the workcell
    links       the link table, parents before children, the root first
    sensors     MJCF sensors in order: (kind, sensor name, site), kind one of force, torque, touch,
                gyro, accelerometer, framequat (framequat of the site)
    ft_frame    the massless fixed frame of the wrist force/torque sensor: emitted as a site (same
                name) of its child body, because a MuJoCo force sensor measures the wrench between
                the site's body and its parent
    imu         (site name, link) of an IMU site at the link's origin, or None
    finger_pads (finger body, pad geom) pairs: the pads' contact with the table is the soft
                FINGER_TABLE_CONTACT pair instead of the default one
    option_note the comment above the workcell's physics options
    """

    def __init__(self, name, links, sensors, ft_frame=None, imu=None, finger_pads=(), include=None,
                 option_note=None):
        self.name, self.links, self.sensors = name, list(links), list(sensors)
        self.ft_frame, self.imu, self.finger_pads = ft_frame, imu, tuple(finger_pads)
        self.include = include or f'{name}.xml'
        self.option_note = option_note or (
            '1 kHz physics. Elliptic friction cones with a high impratio keep a pinch grasp from '
            'creeping;\n'
            '       the Euler integrator treats the (large) joint damping implicitly.')
        names = [link.name for link in self.links]
        if len(set(names)) != len(names):
            raise ValueError(f'{name}: duplicate link names')
        roots = [link for link in self.links if link.parent is None]
        if len(roots) != 1:
            raise ValueError(f'{name}: needs exactly one root link')
        self.root = roots[0]
        if any(self.root.rpy):
            raise ValueError(f'{name}: the root link is mounted without rotation')
        by_name = {link.name: link for link in self.links}
        if ft_frame is not None:
            ft = by_name[ft_frame]
            kids = [link for link in self.links if link.parent == ft_frame]
            if ft.mass != 0 or ft.joint['type'] != 'fixed' or len(kids) != 1 or kids[0].mass == 0 \
                    or kids[0].joint['type'] != 'fixed' or any(kids[0].origin) or any(kids[0].rpy):
                raise ValueError(f'{name}: the F/T frame {ft_frame} must be a massless fixed frame '
                                 'with one body fixed at its origin below it')
            self.ft_body = kids[0].name
        else:
            self.ft_body = None

    def total_mass(self):
        return sum(link.mass for link in self.links)

    def mimic_joints(self):
        return [link.joint for link in self.links if link.joint and link.joint.get('mimic')]


# ----------------------------------------------------------------------------------------------
# Small math and formatting


def fmt(v):
    return ' '.join(f'{x:.6g}' for x in v)


def fmt_exact(v):
    """Angles and quaternions of fixed rotations, to full precision (a rounded pi would tilt the
    tool by micro-radians between the URDF and the MJCF); tiny rounding residues print as 0."""
    return ' '.join('0' if abs(x) < 1e-12 else f'{x:.17g}' for x in v)


def quat_of_yaw(yaw):
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


IDENTITY = (1.0, 0.0, 0.0, 0.0)


def quat_of_rpy(rpy):
    """URDF rpy (fixed axes x, y, z in turn: R = Rz(y) Ry(p) Rx(r)) as a quaternion (w, x, y, z)."""
    if not any(rpy):
        return IDENTITY
    r, p, y = (a / 2 for a in rpy)
    cr, sr = math.cos(r), math.sin(r)
    cp, sp = math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def quat_mul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def quat_rotate(q, v):
    if q == IDENTITY:
        return tuple(v)
    w, x, y, z = q
    vx, vy, vz = v
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    ddx, ddy, ddz = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return (vx + 2 * (w * cx + ddx), vy + 2 * (w * cy + ddy), vz + 2 * (w * cz + ddz))


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
    # The template is the generated file's text: its long lines are the file's (hence the noqa).
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
    </body>'''  # noqa: E501


# ----------------------------------------------------------------------------------------------
# URDF


def urdf_geometry(g):
    if g['kind'] == 'box':
        return f'<box size="{fmt(2 * s for s in g["size"])}"/>'
    if g['kind'] == 'cylinder':
        return f'<cylinder radius="{g["size"][0]:.6g}" length="{2 * g["size"][1]:.6g}"/>'
    return f'<sphere radius="{g["size"][0]:.6g}"/>'


def urdf_rpy(rpy):
    return fmt_exact(rpy) if any(rpy) else '0 0 0'


def write_urdf(robot, path):
    root = robot.root
    out = ['<?xml version="1.0"?>',
           '<!-- GENERATED by generate_models.py; edit the generator, not this file. -->',
           f'<robot name="{robot.name}">',
           '  <material name="robot"><color rgba="0.75 0.78 0.82 1"/></material>',
           '  <link name="world"/>',
           f'  <joint name="world_to_{root.name}" type="fixed">',
           f'    <parent link="world"/><child link="{root.name}"/>',
           f'    <origin xyz="{fmt(root.origin)}" rpy="0 0 0"/>',
           '  </joint>']
    for link in robot.links:
        out.append(f'  <link name="{link.name}">')
        if link.mass > 0:
            ixx, iyy, izz = link.inertia
            out += ['    <inertial>',
                    f'      <origin xyz="{fmt(link.com)}" rpy="0 0 0"/>',
                    f'      <mass value="{link.mass:.6g}"/>',
                    f'      <inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{iyy:.6g}" iyz="0" '
                    f'izz="{izz:.6g}"/>',
                    '    </inertial>']
        for g in link.geoms:
            for tag in ('visual', 'collision'):
                out += [f'    <{tag}>', f'      <origin xyz="{fmt(g["pos"])}" rpy="0 0 0"/>',
                        f'      <geometry>{urdf_geometry(g)}</geometry>']
                if tag == 'visual':
                    out.append(f'      <material name="robot">'
                               f'<color rgba="{g["color"]}"/></material>')
                out.append(f'    </{tag}>')
        out.append('  </link>')
        if link.parent is None:
            continue
        j = link.joint
        out += [f'  <joint name="{j["name"]}" type="{j["type"]}">',
                f'    <parent link="{link.parent}"/><child link="{link.name}"/>',
                f'    <origin xyz="{fmt(link.origin)}" rpy="{urdf_rpy(link.rpy)}"/>']
        if j['type'] != 'fixed':
            out += [f'    <axis xyz="{fmt(j["axis"])}"/>',
                    f'    <limit lower="{j["lo"]:.6g}" upper="{j["hi"]:.6g}" '
                    f'effort="{j["effort"]:.6g}" velocity="{j["vel"]:.6g}"/>',
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
    # Collision on the geoms marked collide only (contype 2 never meets itself: no self-collision).
    cls = 'collide' if g['collide'] else 'visual'
    name = f' name="{g["name"]}"' if g['name'] else ''
    return (f'{indent}<geom{name} class="{cls}" type="{kind}" size="{size}" pos="{fmt(g["pos"])}" '
            f'rgba="{g["color"]}"/>')


def mj_quat(q):
    return '' if q == IDENTITY else f' quat="{fmt_exact(q)}"'


def mj_sensor(kind, name, site):
    if kind == 'framequat':
        return f'    <framequat name="{name}" objtype="site" objname="{site}"/>'
    return f'    <{kind} name="{name}" site="{site}"/>'


def write_mjcf_robot(robot, path):
    links = robot.links
    children = {}
    for link in links:
        children.setdefault(link.parent, []).append(link)
    actuated = [link.joint for link in links
                if link.joint and link.joint['type'] != 'fixed' and not link.joint.get('mimic')]

    body_lines = []

    def emit(link, depth, offset_pos, offset_quat):
        ind = '  ' * depth
        # The link's frame in the emitting body: the folded frames' offset, then its own origin.
        if offset_quat == IDENTITY:
            pos = tuple(a + b for a, b in zip(link.origin, offset_pos))
        else:
            pos = tuple(a + b for a, b in zip(quat_rotate(offset_quat, link.origin), offset_pos))
        quat = quat_mul(offset_quat, quat_of_rpy(link.rpy)) if any(link.rpy) else offset_quat
        j = link.joint
        if j is not None and j['type'] == 'fixed':
            # Massless frames fold into their parent as sites; their children shift by the offset.
            if link.mass == 0:
                # A leaf frame becomes a site; the F/T frame (which has the palm below it) is
                # emitted as a site of that body instead (see Robot.ft_frame).
                if not children.get(link.name):
                    body_lines.append(f'{ind}<site name="{link.name}" '
                                      f'pos="{fmt(pos)}"{mj_quat(quat)} '
                                      'size="0.01" group="3"/>')
                for child in children.get(link.name, []):
                    emit(child, depth, pos, quat)
                return
        body_lines.append(f'{ind}<body name="{link.name}" pos="{fmt(pos)}"{mj_quat(quat)}>')
        ixx, iyy, izz = link.inertia
        body_lines.append(f'{ind}  <inertial pos="{fmt(link.com)}" mass="{link.mass:.6g}" '
                          f'diaginertia="{ixx:.6g} {iyy:.6g} {izz:.6g}"/>')
        if j is not None and j['type'] != 'fixed':
            kind = 'hinge' if j['type'] == 'revolute' else 'slide'
            body_lines.append(
                f'{ind}  <joint name="{j["name"]}" type="{kind}" axis="{fmt(j["axis"])}" '
                f'limited="true" range="{j["lo"]:.6g} {j["hi"]:.6g}" '
                f'damping="{j["damping"]:.6g}" armature="{j["armature"]:.6g}"/>')
        if robot.imu and link.name == robot.imu[1]:
            body_lines.append(f'{ind}  <site name="{robot.imu[0]}" pos="0 0 0" size="0.01" '
                              'group="3"/>')
        if link.name == robot.ft_body:
            # The wrench between this body and its parent carries the gripper and any grasped load.
            body_lines.append(f'{ind}  <site name="{robot.ft_frame}" pos="0 0 0" size="0.01" '
                              'group="3"/>')
        for g in link.geoms:
            body_lines.append(mj_geom(g, ind + '  '))
        for name, spos, ssize in link.sites:
            body_lines.append(f'{ind}  <site name="{name}" type="box" pos="{fmt(spos)}" '
                              f'size="{fmt(ssize)}" rgba="1 0.3 0.3 0.3" group="3"/>')
        for child in children.get(link.name, []):
            emit(child, depth + 1, (0.0, 0.0, 0.0), IDENTITY)
        body_lines.append(f'{ind}</body>')

    emit(robot.root, 2, (0.0, 0.0, 0.0), IDENTITY)

    out = ['<!-- GENERATED by generate_models.py; edit the generator, not this file. -->',
           f'<mujoco model="{robot.name}">',
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
    out.append('  </worldbody>')
    mimics = robot.mimic_joints()
    if mimics:
        out.append('  <equality>')
        for j in mimics:
            out.append(f'    <joint name="{j["mimic"].lower()}_coupling" joint1="{j["name"]}" '
                       f'joint2="{j["mimic"]}" polycoef="0 1 0 0 0" solref="0.004 1"/>')
        out.append('  </equality>')
    out.append('  <actuator>')
    for j in actuated:
        out.append(f'    <position name="{j["name"]}" joint="{j["name"]}" kp="{j["kp"]:.6g}" '
                   f'ctrllimited="true" ctrlrange="{j["lo"]:.6g} {j["hi"]:.6g}" '
                   f'forcelimited="true" forcerange="{-j["effort"]:.6g} {j["effort"]:.6g}"/>')
    out += ['  </actuator>', '  <sensor>']
    out += [mj_sensor(*s) for s in robot.sensors]
    out += ['  </sensor>', '</mujoco>']
    with open(path, 'w') as f:
        f.write('\n'.join(out) + '\n')


def write_workcell(robot, scene, path):
    """The MuJoCo scene of `scene` (config/scene.yaml, loaded) with the robot's MJCF included."""
    table_top = scene['table_top']
    tx, ty = tuple(scene['table']['center'])
    hx, hy, hz = tuple(scene['table']['half_size'])
    top_center_z = table_top - hz
    leg_half = (table_top - 2 * hz) / 2
    legs = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            legs.append(f'      <geom type="box" size="0.025 0.025 {leg_half:.4g}" '
                        f'pos="{sx * (hx - 0.05):.4g} {sy * (hy - 0.05):.4g} {-hz - leg_half:.4g}" '
                        'rgba="0.45 0.32 0.2 1" contype="0" conaffinity="0"/>')
    objects = []
    for name, spec in scene['objects'].items():
        if spec.get('fixed'):
            objects.append(drawer_cabinet(name, spec))
        else:
            mass, rgba, condim, friction = FREE_OBJECTS[name]
            objects.append(free_box(name, spec['park'], mass, spec['half_size'], rgba,
                                    condim, friction))
    objects = '\n'.join(objects)
    # A mocap body counts as welded to the world, so MuJoCo's parent filter does not keep its
    # child from colliding with it: the drawer slides through its solid cabinet by exclusion.
    excludes = [f'    <exclude body1="{name}" body2="{name}_tray"/>'
                for name, spec in scene['objects'].items() if spec.get('fixed')]
    # the tips' own contact with the table replaces the default one
    for body, geom_name in robot.finger_pads:
        excludes.append(f'    <exclude body1="{body}" body2="table"/>')
        excludes.append(f'    <pair geom1="{geom_name}" geom2="table_top" {FINGER_TABLE_CONTACT}/>')
    excludes = '\n'.join(excludes)
    # The template is the generated file's text: its long lines are the file's (hence the noqa).
    out = f'''<!-- GENERATED by generate_models.py from config/scene.yaml; edit those, not this file. -->
<mujoco model="lfd_workcell">
  <include file="{robot.include}"/>
  <!-- {robot.option_note} -->
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
    <!-- Table: top surface at z = {table_top} m, spans x [{tx - hx:.2f}, {tx + hx:.2f}], y [{ty - hy:.2f}, {ty + hy:.2f}]. -->
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
'''  # noqa: E501
    with open(path, 'w') as f:
        f.write(out)


def generate(robot, out_dir, scene_path, urdf_name=None):
    """Writes <name>.urdf, the MJCF robot (robot.include) and workcell.xml into out_dir."""
    urdf_name = urdf_name or f'{robot.name}.urdf'
    write_urdf(robot, os.path.join(out_dir, urdf_name))
    write_mjcf_robot(robot, os.path.join(out_dir, robot.include))
    write_workcell(robot, load_scene(scene_path), os.path.join(out_dir, 'workcell.xml'))
    print(f'wrote {urdf_name}, {robot.include}, workcell.xml ({len(robot.links)} links, '
          f'{robot.total_mass():.1f} kg)')
