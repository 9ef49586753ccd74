#!/usr/bin/python3
"""rostest (third_robot.test): a third robot from files alone.

The test writes a robot description package of its own, mini_description, into a temporary
folder: a 6-DoF arm whose links, joints and sensors are named unlike jvrc1's and arm7's (j1..j6,
the shared parallel gripper of lfd_tools.robot_models under the names claw, jaw_left, jaw, ...,
the sensors wrench_f, wrench_t, tip_l, tip_r), its models generated from the link table below
through lfd_tools.robot_models.generate, its robot file (config/robot.yaml) and its
launch/upload.launch. With that folder first on ROS_PACKAGE_PATH, the headless pipeline records a
simulated grasp demonstration with `--robot mini` (the C++ bridge, demonstrator and recorder read
the robot from its files only) and the bag is checked: the demo succeeded physically (the task
file's criterion, judged from the bag) and holds the robot's own joints and sensors on the shared
topics (/wrist_ft, /touch, /gripper/state); then a skill library is learned from it (the
segmentation and the learner read the gripper's joint by the robot file's name). Nothing is built
and no project file changes: if anything in the project named a robot's link, joint or sensor,
this robot would not grasp. A broken robot file fails it with the nodes' own words (their errors and
warnings from the launch logs), e.g. a gripper joint the model lacks: "no actuated gripper joint".
"""
import glob
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospkg
import rostest
from lfd_tools import bags as lfd_bags
from lfd_tools import config as lfd_config
from lfd_tools import robot_models as rm

PIPELINE = os.path.join(rospkg.RosPack().get_path("lfd_launch"), "scripts", "pipeline.py")
ROBOT = "mini"
PACKAGE = ROBOT + "_description"
# s of wall time for each of the two runs (~10 s and ~15 s unloaded); with their stop (40 s at
# most) within the rostest's time-limit (360)
PIPELINE_TIMEOUT = 120

# ---- the arm ----------------------------------------------------------------------------------
# j1 turns about z at the base, j2, j3 and j4 pitch about y (shoulder, elbow, wrist), j5 rolls about
# x, j6 turns about z; in the zero pose the arm points straight up. The hand hangs from the flange
# turned by pi about y (fingers along the forearm), so with j2 + j3 + j4 = pi and j5 = 0 the fingers
# point down. Unlike arm7 (7 DoF, z/y alternating) it has no redundancy; unlike jvrc1 no waist.
SHOULDER = 0.30  # j2 above base_link
UPPER = 0.50     # j2 -> j3
FORE = 0.50      # j3 -> j4 (the wrist centre: j4, j5, j6)
FLANGE = 0.05    # the wrist centre -> the F/T frame
TCP_BELOW_FT = 0.083  # the shared hand: F/T frame -> TCP
DRIVE = {
    'shoulder': (10000.0, 300.0, 0.5, 2.0, 300.0),
    'elbow': (4000.0, 120.0, 0.4, 2.5, 150.0),
    'wrist': (400.0, 8.0, 0.05, 4.0, 30.0),
    'gripper': (1500.0, 40.0, 0.05, 0.15, 40.0),
}
HAND = rm.HandNames(ft_frame='flange_ft', ft_joint='flange_ft_fix', palm='claw',
                    palm_joint='claw_fix', finger_left='jaw_left', finger_right='jaw_right',
                    finger_joint='jaw', mimic_joint='jaw_follow', pad_left='jaw_left_pad',
                    pad_right='jaw_right_pad', touch_left='jaw_left_touch',
                    touch_right='jaw_right_touch', tcp='grip_point', tcp_joint='grip_point_fix')
SENSORS = [('force', 'wrench_f', HAND.ft_frame), ('torque', 'wrench_t', HAND.ft_frame),
           ('touch', 'tip_l', HAND.touch_left), ('touch', 'tip_r', HAND.touch_right)]
JOINTS = ['j1', 'j2', 'j3', 'j4', 'j5', 'j6']


def mini_robot(mount):
    Y, Z, X = rm.Y, rm.Z, rm.X
    height = mount[2]
    links = [
        rm.Link('base_link', None, None, tuple(mount), 5.0, [
            rm.geom('cylinder', (0.08, 0.05), (0.0, 0.0, 0.05), color=rm.DARK_COLOR),
            rm.geom('cylinder', (0.05, height / 2), (0.0, 0.0, -height / 2))]),
        rm.Link('turret', 'base_link', rm.revolute('j1', Z, -2.9, 2.9, DRIVE['shoulder']),
                (0.0, 0.0, 0.10), 3.0, [rm.geom('cylinder', (0.065, 0.09), (0.0, 0.0, 0.09))]),
        rm.Link('upper', 'turret', rm.revolute('j2', Y, -2.0, 2.0, DRIVE['shoulder']),
                (0.0, 0.0, SHOULDER - 0.10), 3.0,
                [rm.geom('cylinder', (0.05, 0.2), (0.0, 0.0, 0.25))]),
        rm.Link('fore', 'upper', rm.revolute('j3', Y, -0.3, 3.0, DRIVE['elbow']),
                (0.0, 0.0, UPPER), 2.0, [rm.geom('cylinder', (0.045, 0.2), (0.0, 0.0, 0.25))]),
        rm.Link('wrist_pitch', 'fore', rm.revolute('j4', Y, -2.1, 2.1, DRIVE['wrist']),
                (0.0, 0.0, FORE), 0.5, [rm.geom('sphere', (0.04,), color=rm.DARK_COLOR)]),
        rm.Link('wrist_roll', 'wrist_pitch', rm.revolute('j5', X, -2.0, 2.0, DRIVE['wrist']),
                (0.0, 0.0, 0.0), 0.3, [rm.geom('sphere', (0.035,), color=rm.DARK_COLOR)]),
        rm.Link('flange', 'wrist_roll', rm.revolute('j6', Z, -2.9, 2.9, DRIVE['wrist']),
                (0.0, 0.0, 0.0), 0.3, [rm.geom('cylinder', (0.035, 0.02), (0.0, 0.0, 0.025),
                                               collide=True, color=rm.DARK_COLOR)]),
    ]
    links += rm.parallel_gripper(HAND, 'flange', (0.0, 0.0, FLANGE), DRIVE['gripper'],
                                 ft_rpy=(0.0, math.pi, 0.0))
    return rm.Robot('mini_arm', links, SENSORS, ft_frame=HAND.ft_frame,
                    finger_pads=HAND.finger_pads())


def fingers_down(x, y, z, yaw=0.0):
    """The joint angles (elbow up) holding the TCP at (x, y, z) in base_link, fingers down, the
    pads closing along y turned by yaw: the arm has no redundancy, so this is the posture the
    project's IK finds too."""
    j1 = math.atan2(y, x)
    r, h = math.hypot(x, y), z + FLANGE + TCP_BELOW_FT - SHOULDER  # the wrist centre from j2
    c3 = (r * r + h * h - UPPER ** 2 - FORE ** 2) / (2 * UPPER * FORE)
    j3 = math.acos(max(-1.0, min(1.0, c3)))
    j2 = math.atan2(r, h) - math.atan2(FORE * math.sin(j3), UPPER + FORE * math.cos(j3))
    return dict(zip(JOINTS, (j1, j2, j3, math.pi - j2 - j3, 0.0, j1 - yaw)))


def posture_yaml(posture, extra=None, indent='  '):
    items = dict(posture, **(extra or {}))
    return ''.join('%s%s: %.4f\n' % (indent, k, v) for k, v in items.items())


def write_package(root):
    """mini_description in root: package.xml, models/ (generated), config/robot.yaml,
    launch/upload.launch. Returns the package folder."""
    pkg = os.path.join(root, PACKAGE)
    for sub in ('models', 'config', 'launch'):
        os.makedirs(os.path.join(pkg, sub))
    with open(os.path.join(pkg, 'package.xml'), 'w') as f:
        f.write('<?xml version="1.0"?>\n<package format="2">\n  <name>%s</name>\n  '
                '<version>0.0.1</version>\n'
                '  <description>A test robot (test/integration/third_robot.py).</description>\n'
                '  <maintainer email="lfd@example.org">lfd maintainers</maintainer>\n'
                '  <license>BSD-3-Clause</license>\n  <buildtool_depend>catkin</buildtool_depend>\n'
                '</package>\n' % PACKAGE)
    scene_path = lfd_config.config_path('scene.yaml')
    robot = mini_robot(rm.load_scene(scene_path)['base_link_in_world'])
    rm.generate(robot, os.path.join(pkg, 'models'), scene_path)
    with open(os.path.join(pkg, 'launch', 'upload.launch'), 'w') as f:
        f.write('<launch>\n  <param name="robot_description" '
                'textfile="$(find %s)/models/%s.urdf"/>\n'
                '</launch>\n' % (PACKAGE, robot.name))
    # Ready: the TCP 10 cm above the table's near edge; preferred: 8 cm above the workspace's centre
    scene = rm.load_scene(scene_path)
    table = scene['table_top'] - scene['base_link_in_world'][2]  # the table top's z in base_link
    ready = fingers_down(0.30, -0.28, table + 0.10)
    preferred = fingers_down(0.50, -0.28, table + 0.08)
    values = {'name': ROBOT, 'tcp': HAND.tcp, 'jaw': HAND.finger_joint, 'ft': HAND.ft_frame,
              'palm': HAND.palm, 'preferred': posture_yaml(preferred, indent='    '),
              'ready': posture_yaml(ready, {HAND.finger_joint: 0.03}).rstrip('\n')}
    with open(os.path.join(pkg, 'config', 'robot.yaml'), 'w') as f:
        f.write('''name: %(name)s
ik:
  base_link: base_link
  tip_link: %(tcp)s
  joint_costs: {}
  preferred_posture:
%(preferred)s  tolerance: {position: 0.002, orientation: 0.03}
  min_limit_margin: 0.05
gripper:
  joint: %(jaw)s
  open_opening: 0.08
  close_opening: 0.0
  close_effort: 20.0
  opening_scale: 2.0
initial_posture:
%(ready)s
sensors:
  - topic: /wrist_ft
    type: geometry_msgs/WrenchStamped
    frame: %(ft)s
    fields: {force: wrench_f, torque: wrench_t}
  - topic: /touch
    type: lfd_msgs/Touch
    frame: %(palm)s
    fields: {values: [tip_l, tip_r]}
''' % values)
    return pkg


def pipeline(env, *args, timeout):
    """Runs pipeline.py; returns (exit status, combined output). Stops its group on timeout."""
    proc = subprocess.Popen(['/usr/bin/python3', PIPELINE] + list(args), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGINT)  # the pipeline stops its masters on SIGINT
        try:
            out, _ = proc.communicate(timeout=40)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, _ = proc.communicate()
        sys.stdout.write(out)
        raise AssertionError('pipeline %s did not finish within %d s' % (' '.join(args), timeout))
    sys.stdout.write(out)
    sys.stdout.flush()
    return proc.returncode, out


def node_complaints(out, limit=15):
    """The nodes' errors and warnings in the datasets' launch logs (a robot file naming what its
    model lacks is reported there, e.g. by the bridge), to show with a failure."""
    lines = []
    for log in sorted(glob.glob(os.path.join(out, 'datasets', 'logs', '*.log'))):
        with open(log, errors='replace') as f:
            for line in f:
                # colours, times
                line = re.sub(r'\x1b\[[0-9;]*m| \[[0-9.]+(, [0-9.]+)?\]', '', line).strip()
                if re.match(r'\[(FATAL|ERROR| WARN)\]', line) and line not in lines:
                    lines.append(line)
    return '\n'.join(lines[:limit])


class ThirdRobot(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix='lfd_third_robot_')
        cls.pkg = write_package(cls.root)
        cls.env = dict(os.environ)
        cls.env['ROS_PACKAGE_PATH'] = ':'.join([cls.root] + [p for p in os.environ.get(
            'ROS_PACKAGE_PATH', '').split(':') if p])
        cls.env.pop('LFD_ROBOT', None)
        cls.out = os.path.join(cls.root, 'out')
        cls.status, cls.log = pipeline(cls.env, '--robot', ROBOT, '--out', cls.out, '--stages',
                                       'datasets', '--datasets', 'sim_grasp', '--demos', '1',
                                       timeout=PIPELINE_TIMEOUT)
        cls.report = cls.read_report()
        if cls.status != 0:
            cls.log += '\nthe nodes said:\n' + node_complaints(cls.out)
        cls.bags = sorted(os.path.join(d, f)
                          for d, _, files in os.walk(os.path.join(cls.out, 'datasets'))
                          for f in files if f.endswith('.bag'))

        # The skill library of that demo (segmentation, then the learner: both read the gripper's
        # joint, whatever the robot names it).
        cls.learn_status, cls.learn_log, cls.learn_report = None, 'no demo to learn from', {}
        if cls.bags:
            cls.learn_status, cls.learn_log = pipeline(cls.env, '--robot', ROBOT, '--out', cls.out,
                                                       '--stages', 'learn', '--datasets',
                                                       'sim_grasp', timeout=PIPELINE_TIMEOUT)
            cls.learn_report = cls.read_report()

    @classmethod
    def read_report(cls):
        path = os.path.join(cls.out, 'report.json')
        if not os.path.exists(path):
            return {}
        with open(path) as f:
            return json.load(f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def test_0_its_names_are_its_own(self):
        """No link, joint or MJCF name of mini is one of the other robots' (but base_link, the
        Cartesian frame's conventional name, and the generated world_to_base_link): a name
        hard-coded anywhere cannot serve it."""
        def names(package):
            found = set()
            folder = self.pkg if package == PACKAGE else rospkg.RosPack().get_path(package)
            models = os.path.join(folder, 'models')
            for f in os.listdir(models):
                if f.endswith(('.urdf', '.xml')) and f != 'workcell.xml':
                    with open(os.path.join(models, f)) as text:
                        found |= set(re.findall(
                            r'<(?:link|joint|body|site|geom|force|torque|touch|position)'
                            r'\b[^>]*?\bname="([^"]+)"', text.read()))
            return found - {'base_link', 'world', 'world_to_base_link'}
        mine = names(PACKAGE)
        self.assertTrue({'j1', HAND.finger_joint, HAND.tcp, 'wrench_f', 'tip_l'} <= mine, mine)
        for other in ('jvrc1_description', 'arm7_description'):
            self.assertEqual(mine & names(other), set(), other)

    def test_1_the_package_is_found(self):
        found = subprocess.run(['rospack', 'find', PACKAGE], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, env=self.env)
        self.assertEqual(found.stdout.strip(), self.pkg, found.stdout)

    def test_2_the_demo_is_recorded_and_succeeds(self):
        self.assertEqual(self.status, 0,
                         'pipeline --robot %s failed:\n%s' % (ROBOT, self.log[-6000:]))
        self.assertEqual(self.report.get('robot'), ROBOT, self.report)
        self.assertEqual(self.report.get('datasets', {}).get('sim_grasp', {}).get('demos'), 1,
                         self.report)
        self.assertEqual(self.report.get('stage_errors'), {}, self.report)
        self.assertEqual(len(self.bags), 1, self.bags)
        outcome = lfd_bags.demo_outcome(self.bags[0])
        self.assertEqual((outcome.get('task'), outcome.get('mode')), ('grasp', 'sim'), outcome)
        self.assertTrue(outcome['success'], '%s: %s' % (self.bags[0], outcome['reason']))

    def test_3_the_bag_holds_the_robots_own_names(self):
        self.assertEqual(len(self.bags), 1, 'no bag:\n%s' % self.log[-4000:])
        first = {}
        with rosbag.Bag(self.bags[0]) as bag:
            counts = {t: i.message_count for t, i in bag.get_type_and_topic_info().topics.items()}
            for topic, msg, _ in bag.read_messages(topics=['/joint_states', '/gripper/state',
                                                           '/touch', '/wrist_ft', '/ee_pose']):
                first.setdefault(topic, msg)
                if topic == '/touch' and max(msg.values, default=0.0) > 0.5:
                    first['touched'] = msg
                if topic == '/wrist_ft':
                    f = msg.wrench.force
                    first['max_force'] = max(first.get('max_force', 0.0),
                                             math.sqrt(f.x ** 2 + f.y ** 2 + f.z ** 2))
        for topic in ('/wrist_ft', '/touch', '/joint_states', '/gripper/state', '/ee_pose'):
            self.assertGreater(counts.get(topic, 0), 100, '%s: %s' % (topic, counts))
        self.assertNotIn('/imu', counts)  # the robot file has no IMU row
        self.assertEqual(list(first['/joint_states'].name),
                         JOINTS + [HAND.finger_joint, HAND.mimic_joint])
        self.assertEqual(list(first['/gripper/state'].name), [HAND.finger_joint])
        self.assertEqual(first['/wrist_ft'].header.frame_id, HAND.ft_frame)
        self.assertEqual(first['/touch'].header.frame_id, HAND.palm)
        self.assertEqual(len(first['/touch'].values), 2)
        self.assertIn('touched', first, 'the pads never touched the stick')
        # The hand's weight (0.45 kg) at least: the F/T sensor is read, not a row of zeros.
        self.assertGreater(first['max_force'], 3.0)
        self.assertEqual(first['/ee_pose'].header.frame_id, 'base_link')

    def test_4_a_skill_is_learned_from_it(self):
        self.assertEqual(self.learn_status, 0,
                         'pipeline --stages learn failed:\n%s' % self.learn_log[-4000:])
        entry = self.learn_report.get('learning', {}).get('sim_grasp', {})
        self.assertNotIn('error', entry, entry)
        self.assertEqual(entry.get('segments'), entry.get('expected_segments'), entry)
        with open(entry['library']) as f:
            library = json.load(f)
        # config/segmentation.yaml's gripper feature (position/*) expanded over this robot's joint.
        self.assertIn('/gripper/state/position/' + HAND.finger_joint, library['features'])


if __name__ == '__main__':
    rostest.rosrun('lfd_test', 'third_robot', ThirdRobot)
