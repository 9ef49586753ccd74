"""The readers of recorded data: ground truth on /lfd/phase, ground-truth files (for recordings
without it), bag spans, and the physical outcome of a recording (what the task's success rules
need, measured from the bag and judged by lfd_tools.judge)."""
import glob
import json
import os

import rosbag

from lfd_tools import config, judge, stamps, tasks

PHASE_TOPIC = "/lfd/phase"
METADATA_TOPIC = "/lfd/metadata"


def list_bags(folder):
    bags = sorted(glob.glob(os.path.join(folder, "*.bag")))
    if not bags:
        raise RuntimeError("no .bag files in %s" % folder)
    return bags


def bags_of(paths):
    """Bags named, or found in the folders named."""
    for p in paths:
        if os.path.isdir(p):
            yield from sorted(glob.glob(os.path.join(p, "*.bag")))
        else:
            yield p


def bag_span(bag_path):
    """(first, last) message time of a bag, from its chunk records: rosbag reads them without the
    per-message index (skip_index; ~0.3 s per 40,000-message bag in Python), and its start and end
    times come from the chunks either way."""
    with rosbag.Bag(bag_path, skip_index=True) as bag:
        return bag.get_start_time(), bag.get_end_time()


def phase_transitions(bag_path):
    """(task, [(phase name, start time)]) from the ground-truth phase topic, in stamp order."""
    task, phases = None, []
    with rosbag.Bag(bag_path) as bag:
        for _, msg, stamp in stamps.read_in_stamp_order(bag, [PHASE_TOPIC],
                                                        keep_duplicates=True)[0]:
            task = task or msg.task
            if not phases or phases[-1][0] != msg.name:
                phases.append((msg.name, stamp))
    if not phases:
        raise RuntimeError("%s has no %s ground truth" % (bag_path, PHASE_TOPIC))
    return task, phases


def ground_truth_changepoints(bag_path, expected):
    """Bag times at which each expected transition's `to` phase starts (the demonstrator's segment
    boundaries: grasp, the start of move; push, of push and return)."""
    _, phases = phase_transitions(bag_path)
    firsts = {}
    for name, start in phases:
        firsts.setdefault(name, start)
    missing = [t["to"] for t in expected if t["to"] not in firsts]
    if missing:
        raise RuntimeError("%s: no %s message for phase(s) %s" % (bag_path, PHASE_TOPIC, missing))
    return [firsts[t["to"]] for t in expected]


# ---- ground-truth files ------------------------------------------------------------------------


def load_truth_file(path):
    """A ground-truth file (YAML or JSON: demos: [{name, bags, changepoints_s}]) as
    [(name, [bag paths], [changepoint seconds from the first bag's start])]."""
    return parse_truth(config.load_yaml(path), os.path.dirname(os.path.abspath(path)), path)


def parse_truth(data, base, path):
    """A ground-truth file's content; relative bag paths are taken from `base`."""
    if not isinstance(data, dict) or not isinstance(data.get("demos"), list) or not data["demos"]:
        raise RuntimeError("%s: expected a 'demos:' list (see evaluate_segmentation.py --help)"
                           % path)
    demos = []
    for i, d in enumerate(data["demos"]):
        if not isinstance(d, dict) or not d.get("bags") or "changepoints_s" not in d:
            raise RuntimeError("%s: demo %d needs 'bags' and 'changepoints_s'" % (path, i))
        bags = d["bags"] if isinstance(d["bags"], list) else [d["bags"]]
        bags = [b if os.path.isabs(b) else os.path.join(base, b) for b in bags]
        demos.append((str(d.get("name", i)), bags, sorted(float(t) for t in d["changepoints_s"])))
    return demos


def truth_from_labels(path, runs=None):
    """A labels.json of phase-split runs (the pr2_ikea format: runs.<name>.parts[].file in order,
    boundaries_rel = each next part's start from the run's first stamp) as a ground-truth file's
    content. Without `runs`, every run split into two parts or more, in the file's order (a
    single-part run has no labelled boundary)."""
    with open(path) as f:
        labels = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    names = runs or [n for n, r in labels["runs"].items() if len(r["parts"]) > 1]
    demos = []
    for name in names:
        run = labels["runs"][name]
        demos.append({"name": name, "bags": [os.path.join(base, p["file"]) for p in run["parts"]],
                      "changepoints_s": list(run["boundaries_rel"])})
    return {"demos": demos}


# ---- a recording's physical outcome -------------------------------------------------------------

EE_TOPIC = "/ee_pose"
# A scene object's joint (the drawer's slide) is on /objects/joint_states; bags recorded before
# the bridge split it from the robot's carry it on /joint_states.
JOINT_TOPICS = ("/objects/joint_states", "/joint_states")


def touch_topic():
    """The pads' topic: the robot file's lfd_msgs/Touch sensor row."""
    return config.sensor_topic("lfd_msgs/Touch")


def topics_for(criterion):
    """The topics a criterion's rules read."""
    topics = set()
    for rule in criterion["rules"]:
        if "object" in rule:
            topics.add("/objects/%s/pose" % tasks.body_of(rule["object"]))
        if rule["rule"] == "joint":
            topics.update(JOINT_TOPICS)
        if rule["rule"] == "contact_path":
            topics.update((touch_topic(), EE_TOPIC))
    return sorted(topics)


def measure(bag, criterion, base_in_world):
    """What the rules of `criterion` judge, from an open bag: the last pose of each judged object
    (by its name in the task file), the last value of each judged joint, and for a contact path
    every (time, the pads' mean force, TCP world position) at the same stamp. Last by stamp, not by
    arrival (lfd_tools.stamps); "warnings" tells what had to be put in order."""
    wanted = topics_for(criterion)
    names = {"/objects/%s/pose" % tasks.body_of(r["object"]): r["object"]
             for r in criterion["rules"] if "object" in r}
    joint_names = {r["joint"] for r in criterion["rules"] if r["rule"] == "joint"}
    messages, warnings = stamps.read_in_stamp_order(bag, wanted)
    out = {"objects": {}, "joints": {}, "contact": [], "warnings": warnings}
    touch, tcp = {}, {}
    for topic, msg, stamp in messages:
        if topic in names:
            p, q = msg.pose.position, msg.pose.orientation
            out["objects"][names[topic]] = {"position": [p.x, p.y, p.z],
                                            "orientation": [q.w, q.x, q.y, q.z]}
        elif topic in JOINT_TOPICS:
            for name, value in zip(msg.name, msg.position):
                if name in joint_names:
                    out["joints"][name] = value
        elif topic == touch_topic() and msg.values:
            touch[round(stamp, 4)] = sum(msg.values) / len(msg.values)
        elif topic == EE_TOPIC:
            p = msg.pose.position
            tcp[round(stamp, 4)] = [p.x + base_in_world[0], p.y + base_in_world[1],
                                    p.z + base_in_world[2]]
    out["contact"] = [(stamp, touch[stamp], tcp[stamp]) for stamp in sorted(touch) if stamp in tcp]
    return out


def physical_outcome(path, task, scene):
    """Physical success of any recording of `task` (a demonstration or a reproduction) toward
    `scene` (tasks.scenes: its goal), judged with the task's rules from the bag at `path`.
    Raises rosbag/OS errors for an unreadable bag."""
    criterion = tasks.success_criterion(task)
    with rosbag.Bag(path) as bag:
        measured = measure(bag, criterion, tasks.base_in_world())
    return dict(judge.judge_rules(criterion, measured, scene, tasks.table_top()),
                warnings=measured["warnings"])


def demo_outcome(path):
    """Physical success of a recorded demonstration, from its bag alone: the task and the scene
    (goal) from its metadata (the first message, /lfd/metadata extra_json), judged with the task
    file's criterion. A dict: bag, task, mode, configuration, speed, success, distance_m, height_m,
    rules, duration, topics (name -> count), reason, warnings (stamps put in order)."""
    result = {"bag": path, "success": False, "reason": "", "warnings": []}
    try:
        with rosbag.Bag(path) as bag:
            info = bag.get_type_and_topic_info().topics
            result["topics"] = {name: t.message_count for name, t in info.items()}
            result["duration"] = bag.get_end_time() - bag.get_start_time()
            first = next(bag.read_messages(), None)
            if first is None or first.topic != METADATA_TOPIC:
                result["reason"] = "the first message is not %s" % METADATA_TOPIC
                return result
            meta = first.message
            scene = json.loads(meta.extra_json)["scene"]
            result.update(task=meta.task, mode=meta.mode, configuration=meta.configuration,
                          speed=meta.speed)
            criterion = tasks.success_criterion(meta.task)
            measured = measure(bag, criterion, tasks.base_in_world())
    except (rosbag.ROSBagException, OSError, ValueError, KeyError, RuntimeError) as exc:
        result["reason"] = "unreadable: %s" % exc
        return result
    outcome = judge.judge_rules(criterion, measured, scene, tasks.table_top())
    result.update(success=outcome["success"], distance_m=outcome["distance_m"],
                  height_m=outcome["height_m"], rules=outcome["rules"], reason=outcome["reason"],
                  warnings=measured["warnings"])
    return result
