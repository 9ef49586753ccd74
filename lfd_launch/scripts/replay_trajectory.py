#!/usr/bin/python3
"""Replays one demonstration or reproduction bag for inspection in rviz (lfd_launch/inspect.launch).

Reads the bag once, then
  - publishes the whole end-effector path (/ee_pose) as one latched nav_msgs/Path on ~path_topic
    (default /executor/executed_path, the orange "Executed path" display of config/lfd.rviz);
  - republishes the bag's own /executor/planned_path and /executor/segment_markers (latched) when
    the bag recorded a reproduction; otherwise draws the segment boundaries as a MarkerArray on
    /executor/segment_markers: a sphere at the hand's position and a label at each boundary;
  - adds to those markers the table and the free objects (/objects/<name>/pose, last pose) as
    cubes sized and coloured from the MJCF scene (~scene_model);
  - replays /joint_states (re-stamped with the current time) at ~rate x the recorded speed, so
    robot_state_publisher moves the robot model; at the end it holds the last state (or loops).

Segment boundaries, first match wins: ~changepoints (list of seconds), ~segmentation_json (the
`segment` CLI output; the demo whose "source" names this bag, else ~demo_index), the bag's ground
truth /lfd/phase transitions (~use_phases). Times are bag time (the recorded stamps, as the
`segment` CLI reports changepoint_times); ~relative_times: seconds from the bag's first message.

Wall time on purpose (/use_sim_time false): a looping replay would move a /clock backwards, and
every tf buffer would reset at each loop.

Private parameters: ~bag (required), ~rate (1.0; <= 0: jump to the last state), ~loop (false),
~changepoints, ~relative_times (false), ~segmentation_json, ~demo_index (0), ~use_phases (true),
~path_topic (/executor/executed_path), ~scene_model (MJCF file for the object sizes; '' = no
objects), ~hold_rate (10 Hz: how often the held last state is republished).
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

import rosbag
import rospy
from geometry_msgs.msg import Point, PoseStamped
from nav_msgs.msg import Path
from sensor_msgs.msg import JointState
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

BOUNDARY_COLOR = ColorRGBA(0.1, 0.75, 0.2, 1.0)


class BagContent:
    """Everything the replay needs, read in one pass over the bag."""

    def __init__(self, path):
        if not os.path.isfile(path):
            raise ValueError("bag '%s' does not exist" % path)
        self.joint_states = []  # (bag time s, JointState)
        self.ee_poses = []  # (bag time s, PoseStamped)
        self.object_poses = {}  # name -> last PoseStamped
        self.phases = []  # (bag time s, phase name)
        self.planned_path = None
        self.segment_markers = None
        self.start = None
        with rosbag.Bag(path) as bag:
            for topic, msg, t in bag.read_messages():
                sec = t.to_sec()
                self.start = sec if self.start is None else min(self.start, sec)
                if topic == "/joint_states":
                    self.joint_states.append((sec, msg))
                elif topic == "/ee_pose":
                    self.ee_poses.append((sec, msg))
                elif topic.startswith("/objects/") and topic.endswith("/pose"):
                    self.object_poses.setdefault(topic.split("/")[2], []).append((sec, msg))
                elif topic == "/lfd/phase":
                    if not self.phases or self.phases[-1][1] != msg.name:
                        self.phases.append((msg.header.stamp.to_sec() or sec, msg.name))
                elif topic == "/executor/planned_path":
                    self.planned_path = msg
                elif topic == "/executor/segment_markers":
                    self.segment_markers = msg
        if not self.joint_states and not self.ee_poses:
            raise ValueError("bag '%s' has neither /joint_states nor /ee_pose" % path)


def boundary_times(content, bag_path):
    """Segment boundaries in bag time, with a label each."""
    times = rospy.get_param("~changepoints", [])
    labels = []
    source = "~changepoints"
    seg_json = rospy.get_param("~segmentation_json", "")
    if not times and seg_json:
        with open(seg_json) as f:
            demos = json.load(f).get("demos", [])
        if not demos:
            raise ValueError("'%s' has no \"demos\"" % seg_json)
        index = rospy.get_param("~demo_index", 0)
        for i, demo in enumerate(demos):
            if os.path.basename(str(demo.get("source", ""))) == os.path.basename(bag_path):
                index = i
        if index >= len(demos):
            raise ValueError("~demo_index %d: '%s' has %d demos" % (index, seg_json, len(demos)))
        times = demos[index].get("changepoint_times", [])
        source = "%s demo %d" % (seg_json, index)
    if not times and rospy.get_param("~use_phases", True) and len(content.phases) > 1:
        times = [t for t, _ in content.phases[1:]]
        labels = ["%s>%s" % (a[1], b[1]) for a, b in zip(content.phases, content.phases[1:])]
        source = "ground-truth /lfd/phase"
    times = [float(t) for t in times]
    if source == "~changepoints" and rospy.get_param("~relative_times", False):
        times = [t + content.start for t in times]
    if not labels:
        labels = ["cp %d" % (i + 1) for i in range(len(times))]
    rospy.loginfo("replay: %d segment boundaries from %s", len(times), source)
    return times, labels


def pose_at(stamped, t):
    """The pose of the (time, PoseStamped) sample nearest to t."""
    return min(stamped, key=lambda s: abs(s[0] - t))[1]


def boundary_markers(content, times, labels):
    markers = MarkerArray()
    clear = Marker(action=Marker.DELETEALL)
    clear.ns = "segments"
    markers.markers.append(clear)
    if not content.ee_poses:
        return markers
    for i, (t, label) in enumerate(zip(times, labels)):
        pose = pose_at(content.ee_poses, t)
        for kind in (Marker.SPHERE, Marker.TEXT_VIEW_FACING):
            m = Marker()
            m.header.frame_id = pose.header.frame_id or "base_link"
            m.ns = "segments"
            m.id = 2 * i + (kind == Marker.TEXT_VIEW_FACING)
            m.type = kind
            m.action = Marker.ADD
            m.pose.position = Point(pose.pose.position.x, pose.pose.position.y,
                                    pose.pose.position.z + (0.06 if kind != Marker.SPHERE else 0))
            m.pose.orientation.w = 1.0
            m.scale.x = m.scale.y = m.scale.z = 0.035 if kind == Marker.SPHERE else 0.04
            m.color = BOUNDARY_COLOR
            m.text = label if kind == Marker.TEXT_VIEW_FACING else ""
            markers.markers.append(m)
    return markers


def scene_boxes(model_path):
    """name -> (half sizes, rgba, body position) of the table top and free objects of the MJCF."""
    boxes = {}
    if not model_path:
        return boxes
    root = ET.parse(model_path).getroot()
    for body in root.iter("body"):
        name = body.get("name", "")
        geom = body.find("geom[@name='%s_geom']" % name)
        if name == "table":
            geom = body.find("geom[@name='table_top']")
        if geom is None or geom.get("type") != "box":
            continue
        size = [float(v) for v in geom.get("size").split()]
        rgba = [float(v) for v in geom.get("rgba", "0.5 0.5 0.5 1").split()]
        pos = [float(v) for v in body.get("pos", "0 0 0").split()]
        offset = [float(v) for v in geom.get("pos", "0 0 0").split()]
        boxes[name] = (size, rgba, [p + o for p, o in zip(pos, offset)])
    return boxes


def object_markers(content, boxes):
    """Cubes for the table (fixed) and each object at its last recorded pose."""
    markers = MarkerArray()
    for i, (name, (size, rgba, pos)) in enumerate(sorted(boxes.items())):
        m = Marker()
        m.header.frame_id = "world"
        m.ns = "objects"
        m.id = i
        m.type = Marker.CUBE
        m.action = Marker.ADD
        m.scale.x, m.scale.y, m.scale.z = (2 * s for s in size)
        m.color = ColorRGBA(*rgba)
        if name in content.object_poses:
            pose = content.object_poses[name][-1][1]
            m.header.frame_id = pose.header.frame_id or "world"
            m.pose = pose.pose
        elif name == "table":
            m.pose.position = Point(*pos)
            m.pose.orientation.w = 1.0
        else:
            continue
        markers.markers.append(m)
    return markers


def ee_path(content):
    path = Path()
    path.header.frame_id = "base_link"
    if content.ee_poses and content.ee_poses[0][1].header.frame_id:
        path.header.frame_id = content.ee_poses[0][1].header.frame_id
    path.header.stamp = rospy.Time.now()
    for _, pose in content.ee_poses:
        ps = PoseStamped()
        ps.header.frame_id = path.header.frame_id
        ps.header.stamp = path.header.stamp
        ps.pose = pose.pose
        path.poses.append(ps)
    return path


def replay_joints(pub, content, rate, loop, hold_rate):
    states = content.joint_states
    if not states:
        rospy.spin()
        return
    while not rospy.is_shutdown():
        if rate > 0:
            wall0, bag0 = rospy.Time.now().to_sec(), states[0][0]
            for t, msg in states:
                wait = wall0 + (t - bag0) / rate - rospy.Time.now().to_sec()
                if wait > 0:
                    rospy.sleep(wait)
                if rospy.is_shutdown():
                    return
                msg.header.stamp = rospy.Time.now()
                pub.publish(msg)
        if not loop or rate <= 0:
            break
    last = states[-1][1]
    hold = rospy.Rate(hold_rate)
    while not rospy.is_shutdown():
        last.header.stamp = rospy.Time.now()
        pub.publish(last)
        try:
            hold.sleep()
        except rospy.ROSInterruptException:
            return


def main():
    rospy.init_node("replay_trajectory")
    bag_path = rospy.get_param("~bag", "")
    try:
        if not bag_path:
            raise ValueError("~bag is not set")
        content = BagContent(bag_path)
        times, labels = boundary_times(content, bag_path)
        boxes = scene_boxes(rospy.get_param("~scene_model", ""))
    except (ValueError, OSError, ET.ParseError, rosbag.ROSBagException) as e:
        rospy.logfatal("replay_trajectory: %s", e)
        sys.exit(1)

    path_pub = rospy.Publisher(rospy.get_param("~path_topic", "/executor/executed_path"), Path,
                               queue_size=1, latch=True)
    planned_pub = rospy.Publisher("/executor/planned_path", Path, queue_size=1, latch=True)
    segment_pub = rospy.Publisher("/executor/segment_markers", MarkerArray, queue_size=1,
                                  latch=True)
    joint_pub = rospy.Publisher("/joint_states", JointState, queue_size=50)

    if content.ee_poses:
        path_pub.publish(ee_path(content))
    if content.planned_path is not None:
        planned_pub.publish(content.planned_path)
    # One latched MarkerArray topic (the rviz config shows one): segments first, then the scene.
    markers = content.segment_markers or boundary_markers(content, times, labels)
    markers.markers.extend(object_markers(content, boxes).markers)
    segment_pub.publish(markers)
    rospy.loginfo("replay: %s: %d joint states, %d path poses, %.1f s", bag_path,
                  len(content.joint_states), len(content.ee_poses),
                  content.joint_states[-1][0] - content.joint_states[0][0] if content.joint_states
                  else 0.0)
    replay_joints(joint_pub, content, rospy.get_param("~rate", 1.0),
                  rospy.get_param("~loop", False), max(1.0, rospy.get_param("~hold_rate", 10.0)))


if __name__ == "__main__":
    main()
