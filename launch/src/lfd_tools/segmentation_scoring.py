"""Scoring a segmenter's answers against the ground truth: demos whose bags carry /lfd/phase, or
demos of a ground-truth file, through one scorer (lfd_tools.judge). A segmenter is a callable
(inputs, method) -> {"demos": [{changepoint_times, rejected_times, pruned_times, zones}],
selected_features, selected_weights, warnings}; an input is one demo's bag paths, comma-joined."""
import os
import time

from lfd_tools import bags as lfd_bags
from lfd_tools import judge, tasks


def run_and_score(segment, method, inputs, truths, spans, tolerance):
    """Segment all demos at once (inputs: one path each, parts comma-joined), score each against
    its true windows (absolute seconds) over its span (first, last stamp)."""
    start = time.time()
    res = segment(inputs, method)
    elapsed = time.time() - start
    if len(res["demos"]) != len(inputs):
        raise RuntimeError("segmenter returned %d demos for %d inputs" % (len(res["demos"]), len(inputs)))
    scores = []
    for path, true_windows, (t_start, t_end), demo in zip(inputs, truths, spans, res["demos"]):
        found = list(demo["changepoint_times"])
        s = judge.score_demo(found, true_windows, t_start, t_end, tolerance)
        s.update({"bag": ",".join(os.path.basename(p) for p in path.split(",")), "changepoints_s": found,
                  "changepoints_rel_s": [c - t_start for c in found],
                  "rejected_s": demo["rejected_times"], "pruned_s": demo["pruned_times"],
                  "zones_s": demo["zones"]})
        scores.append(s)
    out = judge.summarize_scores(scores, tolerance)
    out.update({"method": method, "selected_features": res["selected_features"],
                "selected_weights": res["selected_weights"], "warnings": res["warnings"],
                "service_time_s": elapsed, "details": scores})
    return out


def evaluate_dataset(segment, folder, method, config, tolerance):
    """A dataset folder whose bags carry /lfd/phase ground truth; the transitions to find are the
    task file's (`config`, the evaluation protocol, is not needed for them)."""
    bags = lfd_bags.list_bags(folder)
    truth = [lfd_bags.phase_transitions(b) for b in bags]
    task = truth[0][0]
    expected = tasks.expected_transitions(task)
    windows = [judge.expected_windows(phases, expected, 0.0) for _, phases in truth]
    spans = [lfd_bags.bag_span(b) for b in bags]
    out = run_and_score(segment, method, bags, windows, spans, tolerance)
    out["task"] = task
    return out


def evaluate_truth_file(segment, demos, method, tolerance):
    """Demos listed in a ground-truth file: times are relative to the first bag's start."""
    spans = []
    for _, bags, _ in demos:
        first, last = lfd_bags.bag_span(bags[0]), lfd_bags.bag_span(bags[-1])
        spans.append((first[0], last[1]))
    truths = [[(s[0] + t, s[0] + t) for t in cps] for (_, _, cps), s in zip(demos, spans)]
    out = run_and_score(segment, method, [",".join(bags) for _, bags, _ in demos], truths, spans, tolerance)
    for d, (name, _, cps) in zip(out["details"], demos):
        d.update({"name": name, "truth_rel_s": cps})
    out["task"] = "truth_file"
    return out


