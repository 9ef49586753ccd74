#!/usr/bin/python3
"""The learning client: segment each task's demonstrations and learn its skill library.

  learn_skills.py --dataset DIR [--mode sim] [--tasks grasp,push (default: every task)]
                  [--changepoints segmentation|ground_truth] [--library-dir DIR]
                  [--library-name '{task}_{mode}.json'] [--attach] [--out FILE.json]

Bags: DIR/<mode>_<task>/*.bag (lfd_sim_bridge/scripts/generate_datasets.py). Changepoints:
`segmentation` (default) calls /segmentation/segment (the paper's method of
config/segmentation.yaml); `ground_truth` uses the demonstrator's /lfd/phase boundaries (the start
of each expected transition's `to` phase, lfd_tools.tasks.expected_transitions of the task file)
and is labelled as such in the output.
/learner/learn learns the library from them, with the task's segment names
(lfd_tools.tasks.segment_names); the learner's majority vote on the changepoint counts decides the
number of segments and whether the names fit (otherwise they are left unnamed, with its warning).
Boundaries are never made up. Each segment's goal frame is learned from the demos' scenes; the
record lists, per segment, the frames chosen and their spread across the demos.

Starts a private master with lfd_launch/learn.launch for the run, or with --attach uses the services
running at ROS_MASTER_URI (the pipeline's learn stage, which runs learn.launch once).
Writes {"learning": {"<mode>_<task>": record}} (lfd_tools.report.learning_record) to --out, also
after an error or Ctrl-C with what was done. A task whose learning fails is reported with its error;
the other tasks still run. Exit status 0 only if every task was learned.
"""
import argparse
import json
import os
import sys

from lfd_tools import bags as lfd_bags
from lfd_tools import master, report, tasks


def changepoints_from(services, source, bags, expected, record):
    """[DemoSegmentation] of the bags, from the segmentation service or the ground truth."""
    from lfd_msgs.msg import DemoSegmentation
    if source == "ground_truth":
        return [DemoSegmentation(source=b,
                                 changepoint_times=lfd_bags.ground_truth_changepoints(b, expected))
                for b in bags], []
    seg = services["/segmentation/segment"](bag_paths=bags)
    if not seg.success:
        raise RuntimeError("segmentation failed: " + seg.error)
    record["segmentation_time_s"] = seg.elapsed
    return list(seg.demos), list(seg.selected_features)


def segment_goals(library):
    """Per segment of a learned library: the goal frames chosen and their spread across the
    demos."""
    with open(library) as f:
        lib = json.load(f)
    out = []
    for seg in lib["segments"]:
        g = seg.get("goal")
        if g is None:
            out.append({"segment": seg["name"], "position_frame": None})
            continue
        out.append({"segment": seg["name"],
                    "position_frame": g["position"]["frame"],
                    "position_spread_m": g["position"]["spread_m"],
                    "orientation_frame": g["orientation"]["frame"],
                    "orientation_spread_rad": g["orientation"]["spread_rad"],
                    "motion_frame": g["heading"]["frame"] or None,
                    "motion_spread_rad": g["heading"]["spread_rad"]})
    return out


def learn(services, task, bags, source, library):
    """Learns one library; returns its learning record (report.learning_record)."""
    from lfd_msgs.srv import LearnSkillsRequest
    names = tasks.segment_names(task)
    record = report.learning_record(task, len(names), bags, source)
    demos, features = changepoints_from(services, source, bags,
                                        tasks.expected_transitions(task), record)
    record["selected_features"] = features
    record["changepoint_counts"] = [len(d.changepoint_times) for d in demos]
    record["changepoint_times"] = [list(d.changepoint_times) for d in demos]
    res = services["/learner/learn"](LearnSkillsRequest(
        task=task, output_path=library, segmentations=demos, selected_features=features,
        segment_names=names))
    if not res.success:
        raise RuntimeError("learning %s failed: %s" % (task, res.error))
    record.update({"library": library, "segments": res.num_segments, "demos_used": res.num_demos,
                   "learn_time_s": res.elapsed, "warnings": list(res.warnings),
                   "segment_goals": segment_goals(library)})
    return record


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--dataset", required=True, help="folder of the <mode>_<task> bag folders")
    ap.add_argument("--mode", default="sim", help="sim | teleop")
    ap.add_argument("--tasks", default=None, help="comma-separated (default: every task)")
    ap.add_argument("--changepoints", choices=["segmentation", "ground_truth"],
                    default="segmentation")
    ap.add_argument("--library-dir", default=None, help="default: <dataset>/skills_<changepoints>")
    ap.add_argument("--library-name", default="{task}_{mode}.json",
                    help="{task} and {mode} are replaced")
    ap.add_argument("--out", default=None, help="default: <library-dir>/learning_<mode>.json")
    ap.add_argument("--attach", action="store_true",
                    help="use the nodes running at ROS_MASTER_URI (default: start a private master "
                         "and the launch)")
    args = ap.parse_args()
    dataset = os.path.abspath(args.dataset)
    lib_dir = os.path.abspath(args.library_dir
                              or os.path.join(dataset, "skills_" + args.changepoints))
    os.makedirs(lib_dir, exist_ok=True)
    out = args.out or os.path.join(lib_dir, "learning_%s.json" % args.mode)
    names = [t for t in args.tasks.split(",") if t] if args.tasks else tasks.names()
    from lfd_msgs.srv import LearnSkills, Segment
    services = {"/learner/learn": LearnSkills}
    if args.changepoints == "segmentation":
        services["/segmentation/segment"] = Segment
    results, status = {"learning": {}, "changepoint_source": args.changepoints}, 0
    with report.written_on_exit(out, results):
        with master.graph_for_this_process(["lfd_launch", "learn.launch", "output:=log"],
                                           args.attach):
            proxies = master.service_proxies("learn_skills", services)
            for task in names:
                key = "%s_%s" % (args.mode, task)
                library = os.path.join(lib_dir, args.library_name.format(task=task, mode=args.mode))
                try:
                    bags = lfd_bags.list_bags(os.path.join(dataset, key))
                    record = learn(proxies, task, bags, args.changepoints, library)
                except RuntimeError as exc:
                    print("%-5s: ERROR %s" % (task, exc), flush=True)
                    results["learning"][key] = dict(
                        report.learning_record(task, None, [], args.changepoints), error=str(exc))
                    status = 1
                    continue
                results["learning"][key] = record
                for w in record["warnings"]:
                    print("%-5s learn: warning: %s" % (task, w), flush=True)
                print("%-5s learn: %d segment(s) x %d demo(s), changepoints per demo %s -> %s"
                      % (task, record["segments"], record["demos_used"],
                         record["changepoint_counts"], library), flush=True)
                for g in record["segment_goals"]:
                    if g["position_frame"] is not None:
                        print("%-5s   %-10s ends in %s (spread %.1f mm) / %s (%.3f rad)%s" % (
                            task, g["segment"], g["position_frame"], 1e3 * g["position_spread_m"],
                            g["orientation_frame"], g["orientation_spread_rad"],
                            ", moves along " + g["motion_frame"] if g["motion_frame"] else ""),
                            flush=True)
    return status


if __name__ == "__main__":
    sys.exit(report.run_client(main))
