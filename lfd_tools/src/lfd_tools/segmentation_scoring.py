"""Scoring a segmenter's answers against the ground truth: demos whose bags carry /lfd/phase, or
demos of a ground-truth file, through one scorer (lfd_tools.judge). A segmenter is a callable
(inputs, method) -> {"demos": [{changepoint_times, rejected_times, pruned_times, zones}],
selected_features, selected_weights, warnings}; an input is one demo's bag paths, comma-joined.
A segmenter may also offer .methods(inputs, methods) -> {method: answer}: the evaluation of
several methods then calls it once (the feature selection does not depend on the method), and
the ground truth of a dataset is read once for all methods."""
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor

from lfd_tools import bags as lfd_bags
from lfd_tools import judge, tasks


def score_answer(res, method, inputs, truths, spans, tolerance, elapsed):
    """One segmenter answer scored demo by demo against the true windows (absolute seconds) over
    each demo's span (first, last stamp)."""
    if len(res["demos"]) != len(inputs):
        raise RuntimeError("segmenter returned %d demos for %d inputs"
                           % (len(res["demos"]), len(inputs)))
    scores = []
    for path, true_windows, (t_start, t_end), demo in zip(inputs, truths, spans, res["demos"]):
        found = list(demo["changepoint_times"])
        s = judge.score_demo(found, true_windows, t_start, t_end, tolerance)
        s.update({"bag": ",".join(os.path.basename(p) for p in path.split(",")),
                  "changepoints_s": found, "changepoints_rel_s": [c - t_start for c in found],
                  "rejected_s": demo["rejected_times"], "pruned_s": demo["pruned_times"],
                  "zones_s": demo["zones"]})
        scores.append(s)
    out = judge.summarize_scores(scores, tolerance)
    out.update({"method": method, "selected_features": res["selected_features"],
                "selected_weights": res["selected_weights"], "warnings": res["warnings"],
                "service_time_s": elapsed, "details": scores})
    return out


def run_and_score_methods(segment, methods, inputs, truths, spans, tolerance):
    """{method: scores}: one call of segment.methods when the segmenter has it (its time shared
    out evenly), else one call per method."""
    if hasattr(segment, "methods") and len(methods) > 1:
        start = time.time()
        answers = segment.methods(inputs, methods)
        elapsed = (time.time() - start) / len(methods)
        return {m: score_answer(answers[m], m, inputs, truths, spans,
                                tolerance, elapsed) for m in methods}
    out = {}
    for m in methods:
        start = time.time()
        res = segment(inputs, m)
        out[m] = score_answer(res, m, inputs, truths, spans, tolerance, time.time() - start)
    return out


def run_and_score(segment, method, inputs, truths, spans, tolerance):
    """Segment all demos at once (inputs: one path each, parts comma-joined) with one method."""
    return run_and_score_methods(segment, [method], inputs, truths, spans, tolerance)[method]


def dataset_truth(folder, config, phases=None):
    """(bags, true windows, spans, task) of a dataset folder whose bags carry /lfd/phase; the
    transitions to find are the task file's (`config`, the evaluation protocol, is not needed).
    phases: each bag's (task, phases) already read (dataset_phases)."""
    bags = lfd_bags.list_bags(folder)
    truth = phases or [lfd_bags.phase_transitions(b) for b in bags]
    task = truth[0][0]
    expected = tasks.expected_transitions(task)
    windows = [judge.expected_windows(p, expected, 0.0) for _, p in truth]
    return bags, windows, [lfd_bags.bag_span(b) for b in bags], task


def dataset_phases(folders, jobs=0):
    """{folder: [(task, phases) per bag] or its first error (RuntimeError or OSError)} of
    dataset folders, their bags read by `jobs` processes (0: one per core). Python's rosbag
    spends ~0.3 s of CPU on opening a 40,000-message bag (its per-message index), the ground
    truth of ten datasets ~25 s on one core. Call it before any thread starts (rospy's): the
    workers are forked."""
    listed = {}
    for folder in folders:
        try:
            listed[folder] = lfd_bags.list_bags(folder)
        except (RuntimeError, OSError) as exc:
            listed[folder] = exc
    paths = [b for bags in listed.values() if isinstance(bags, list) for b in bags]
    workers = min(len(paths), jobs or os.cpu_count() or 1)
    read = {}
    if paths:
        context = multiprocessing.get_context("fork")
        with ProcessPoolExecutor(max_workers=max(1, workers), mp_context=context) as pool:
            futures = {b: pool.submit(lfd_bags.phase_transitions, b) for b in paths}
            for b, future in futures.items():
                try:
                    read[b] = future.result()
                except Exception as exc:  # raised per folder by the caller, naming the bag
                    read[b] = RuntimeError("%s: %s" % (b, exc))
    out = {}
    for folder, bags in listed.items():
        errors = [read[b] for b in bags if isinstance(read[b], Exception)] if isinstance(
            bags, list) else [bags]
        out[folder] = errors[0] if errors else [read[b] for b in bags]
    return out


def evaluate_dataset_methods(segment, folder, methods, config, tolerance, phases=None):
    """{method: scores} of a dataset folder, its ground truth read once (or given: phases, as
    dataset_phases reads them)."""
    if isinstance(phases, Exception):
        raise phases
    bags, windows, spans, task = dataset_truth(folder, config, phases)
    out = run_and_score_methods(segment, methods, bags, windows, spans, tolerance)
    for r in out.values():
        r["task"] = task
    return out


def evaluate_dataset(segment, folder, method, config, tolerance):
    """A dataset folder whose bags carry /lfd/phase ground truth."""
    return evaluate_dataset_methods(segment, folder, [method], config, tolerance)[method]


def truth_file_windows(demos):
    """(inputs, true windows, spans) of the demos of a ground-truth file: times are relative to
    the first bag's start."""
    spans = []
    for _, bags, _ in demos:
        first, last = lfd_bags.bag_span(bags[0]), lfd_bags.bag_span(bags[-1])
        spans.append((first[0], last[1]))
    truths = [[(s[0] + t, s[0] + t) for t in cps] for (_, _, cps), s in zip(demos, spans)]
    return [",".join(bags) for _, bags, _ in demos], truths, spans


def evaluate_truth_file_methods(segment, demos, methods, tolerance):
    """{method: scores} of the demos listed in a ground-truth file."""
    inputs, truths, spans = truth_file_windows(demos)
    out = run_and_score_methods(segment, methods, inputs, truths, spans, tolerance)
    for r in out.values():
        for d, (name, _, cps) in zip(r["details"], demos):
            d.update({"name": name, "truth_rel_s": cps})
        r["task"] = "truth_file"
    return out


def evaluate_truth_file(segment, demos, method, tolerance):
    """Demos listed in a ground-truth file: times are relative to the first bag's start."""
    return evaluate_truth_file_methods(segment, demos, [method], tolerance)[method]
