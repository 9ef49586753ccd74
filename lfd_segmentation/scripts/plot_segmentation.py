#!/usr/bin/python3
"""The paper's figures as PNG, from the JSON of the `segment` CLI and from a pipeline report.

  plot_segmentation.py --segment-json SEG.json [--bags B0.bag ...] [--config segmentation.yaml]
                       --out DIR [--demo 0|0,3|all] [--prefix NAME_] [--no-ground-truth]
      skill_map.png           Fig. 7: every feature of one demo normalized to [0,1], sensors on top
      correlation_best.png    Fig. 3: correlation matrix of the most relevant feature across demos
      correlation_all.png     the same for every state feature (selected ones framed)
      relevance.png           Fig. 4: mean correlation vs. DTW-weighted score, threshold T x best
      clasp_profile.png       Fig. 5: combined ClaSP profile, Kaiser-penalized profile, candidates
      segmentation.png        Fig. 8: selected features and sensors, confidence zones, validated
                              changepoints (solid), rejected candidates (dashed), changepoints
                              pruned to the task's count (dotted), ground-truth
                              phases from /lfd/phase as background (evaluation only)

  plot_segmentation.py --dataset BAG_DIR [--config ...] --out DIR [--demo ...] [--prefix NAME_]
      the same, after running `segment --features --feature-profiles` on BAG_DIR/*.bag (JSON kept
      in DIR)

  plot_segmentation.py --report report.json --out DIR [--prefix NAME_]
      success_rates.png       Fig. 9: success rate per dataset and combination method, with the
                              paper's reference (~80 % simulation, ~50 % real robot)

SEG.json is what `segment --features --feature-profiles --output SEG.json FILES...` writes. The
feature samples (skill map, segmentation) are the JSON's feature_matrices: the very matrix the
segmentation read (the C++ bag reader's resampling), so a figure shows what was segmented. Only the
ground-truth phases behind Fig. 8 come from the demos' bags (/lfd/phase, evaluation only; --bags,
default: the JSON's demos[].source). Time axes are seconds from each demo's first sample. Prints the
path of each PNG written; exits 2 with a message on bad input.
"""
import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np
from lfd_tools import bags as lfd_bags
from lfd_tools import figures

plt = None  # matplotlib.pyplot, imported with the first figure: bad input fails fast without it

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_CONFIG = os.path.join(HERE, "..", "..", "config", "segmentation.yaml")
PAPER_RATE = {"sim": 0.8, "teleop": 0.5}  # Fig. 9: ~80 % in simulation, ~50 % on the real robot
METHOD_ORDER = ["average", "product", "weighted_average", "weighted_product"]
PHASE_COLOURS = ["#f2e2c4", "#c9dcf0", "#d5ecd0", "#ead3ea", "#f6d6d0", "#e0e0e0"]


class UserError(Exception):
    """Bad input: reported as one line, no traceback."""


def warn(msg):
    print("plot_segmentation: warning: %s" % msg, file=sys.stderr)


# ---------------------------------------------------------------------------------------------
# Input
# ---------------------------------------------------------------------------------------------

def load_json(path, what):
    if not os.path.isfile(path):
        raise UserError("%s '%s' does not exist" % (what, path))
    try:
        with open(path) as f:
            return json.load(f)
    except ValueError as e:
        raise UserError("%s '%s' is not valid JSON: %s" % (what, path, e))
    except OSError as e:
        raise UserError("cannot read %s '%s': %s" % (what, path, e))


def load_config(path):
    import yaml
    if not os.path.isfile(path):
        raise UserError("config '%s' does not exist" % path)
    try:
        with open(path) as f:
            config = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise UserError("cannot read config '%s': %s" % (path, e))
    if not isinstance(config, dict):
        raise UserError("config '%s' is not a YAML map" % path)
    for key in ("rate", "threshold"):  # the fallback clock of Fig. 5, the T of Fig. 4
        value = config.get(key, 1.0)
        if not isinstance(value, (int, float)) or not value > 0:
            raise UserError("config '%s': %s must be a positive number, got %r"
                            % (path, key, value))
    return config


def as_array(values):
    """JSON list (nulls for non-finite values) -> float array with NaN."""
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def as_matrix(rows):
    return np.array([[np.nan if v is None else v for v in row] for row in rows], dtype=float)


def require(obj, key, where):
    if not isinstance(obj, dict) or key not in obj:
        raise UserError("%s has no key '%s' (is it the output of the `segment` CLI?)"
                        % (where, key))
    return obj[key]


# ---------------------------------------------------------------------------------------------
# What was segmented: the JSON's feature matrices; the ground truth of a bag
# ---------------------------------------------------------------------------------------------

def feature_matrix(seg, d):
    """Demo d's features as the segmentation read them (`segment --features`): dict(time (s from
    its first sample), start (its clock's origin), names, roles, data (rows x features)); None when
    the JSON holds none."""
    if "feature_matrices" not in seg:
        return None
    where = "feature_matrices[%d]" % d
    m = seg["feature_matrices"][d]
    time = as_array(require(m, "time", where))
    features = require(m, "features", where)
    data = np.column_stack([as_array(require(f, "values", where)) for f in features])
    if data.shape[0] != len(time) or len(time) != seg["demos"][d].get("num_samples", len(time)):
        raise UserError("%s holds %d times and %d samples per feature for a demo of %s samples"
                        % (where, len(time), data.shape[0], seg["demos"][d].get("num_samples")))
    return {"time": time - time[0], "start": time[0], "names": [f["name"] for f in features],
            "roles": [f["role"] for f in features], "data": data}


def ground_truth_phases(args, seg, d, start):
    """[(phase, start s from the demo's first sample)] of demo d's /lfd/phase (evaluation only: the
    background of Fig. 8) in its bag (--bags, else the JSON's source); [] without one."""
    path = args.bags[d] if args.bags else seg["demos"][d].get("source", "")
    if not (path.endswith(".bag") and os.path.isfile(path)):
        warn("demo %d has no bag '%s' (pass --bags): no ground-truth phases" % (d, path))
        return []
    try:
        return [(name, t - start) for name, t in lfd_bags.phase_transitions(path)[1]]
    except RuntimeError:  # no /lfd/phase: no background
        return []
    except Exception as e:  # rosbag raises several exception types for corrupt bags
        raise UserError("cannot read bag '%s': %s" % (path, e))


def normalize01(x):
    lo, hi = np.nanmin(x), np.nanmax(x)
    if not hi - lo > 1e-12 * (1 + max(abs(lo), abs(hi))):
        return np.zeros_like(x)
    return (x - lo) / (hi - lo)


# ---------------------------------------------------------------------------------------------
# Figures
# ---------------------------------------------------------------------------------------------

def new_figure(kind, **kw):
    global plt
    if plt is None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot
        plt = matplotlib.pyplot
    return plt.figure(figsize=figures.SIZES[kind], dpi=figures.DPI, **kw)


def save(fig, out, prefix, kind, written, tag=""):
    path = os.path.join(out, "%s%s%s.png" % (prefix, kind, tag))
    fig.savefig(path, dpi=figures.DPI)
    plt.close(fig)
    written.append(path)
    print(path)


def short(name):
    # matplotlib's legend skips labels starting with "_" (CSV columns often do).
    return name.lstrip("/_")


def feature_colour(seg, name):
    """One colour per feature across figures: its rank among the selected features."""
    selected = seg.get("selected_features", [])
    k = selected.index(name) if name in selected else len(selected) + sum(map(ord, name)) % 10
    return plt.get_cmap("tab10")(k % 10)


def demo_label(seg, d):
    src = seg["demos"][d].get("source", "")
    return os.path.splitext(os.path.basename(src))[0] if src else "demo %d" % d


def plot_skill_map(features, seg, d, out, prefix, written, tag=""):
    roles = features["roles"]
    order = ([k for k, r in enumerate(roles) if r == "sensor"] +
             [k for k, r in enumerate(roles) if r == "state"] +
             [k for k, r in enumerate(roles) if r == "context"])
    image = np.array([normalize01(features["data"][:, k]) for k in order])
    duration = features["time"][-1]
    selected = set(seg.get("selected_features", []))
    fig = new_figure("skill_map", layout="constrained")
    ax = fig.add_subplot(111)
    im = ax.imshow(image, aspect="auto", cmap="gray", vmin=0, vmax=1, interpolation="nearest",
                   extent=[0, duration, len(order), 0])
    labels = []
    for k in order:
        name = features["names"][k]
        labels.append(("* " if name in selected else "") + short(name))
    ax.set_yticks(np.arange(len(order)) + 0.5)
    ax.set_yticklabels(labels, fontsize=7)
    for tick, k in zip(ax.get_yticklabels(), order):
        if features["names"][k] in selected:
            tick.set_fontweight("bold")
    row = 0
    for role in ("sensor", "state", "context"):
        count = sum(1 for k in order if roles[k] == role)
        if not count:
            continue
        if row:
            ax.axhline(row, color="red", lw=2)
        ax.text(duration * 1.005, row + count / 2, role, rotation=90, va="center", ha="left",
                fontsize=9, color="red", clip_on=False)
        row += count
    cps = seg["demos"][d].get("changepoints", [])
    for i, cp in enumerate(cps):
        ax.axvline(at(features["time"], cp), color="cyan", ls="--", lw=1.2,
                   label="validated changepoint" if i == 0 else None)
    if cps:
        ax.legend(loc="lower right", fontsize=8)
    ax.set_xlabel("time (s)")
    ax.set_title("Skill map of %s: features normalized to [0, 1] (sensors on top; * = selected)"
                 % demo_label(seg, d))
    fig.colorbar(im, ax=ax, pad=0.04, label="normalized value")
    save(fig, out, prefix, "skill_map", written, tag)


def relevance_features(seg):
    if not seg.get("relevance_computed") or "relevance" not in seg:
        return None
    feats = require(seg["relevance"], "features", "relevance")
    if not feats:
        return None
    return feats


def best_feature(feats):
    scores = [f["score"] if f.get("score") is not None else -np.inf for f in feats]
    return feats[int(np.argmax(scores))]


def draw_correlation(ax, f, labels, annotate):
    c = as_matrix(f["correlation"])
    im = ax.imshow(c, cmap="coolwarm", vmin=-1, vmax=1, interpolation="nearest")
    if annotate:
        for i in range(c.shape[0]):
            for j in range(c.shape[1]):
                v = c[i, j]
                ax.text(j, i, "nan" if np.isnan(v) else "%.3f" % v, ha="center", va="center",
                        fontsize=7, color="white" if abs(np.nan_to_num(v)) > 0.6 else "black")
    if labels is not None:
        ax.set_xticks(range(len(labels)))
        ax.set_xticklabels(labels, rotation=60, ha="right", fontsize=7)
        ax.set_yticks(range(len(labels)))
        ax.set_yticklabels(labels, fontsize=7)
    else:
        ax.set_xticks([])
        ax.set_yticks([])
    return im


def plot_correlations(seg, feats, out, prefix, written, feature=None):
    labels = [demo_label(seg, d) for d in range(len(seg["demos"]))]
    best = best_feature(feats)
    if feature:
        chosen = [f for f in feats if f["name"] == feature]
        if not chosen:
            raise UserError("--correlation-feature %s is not a state feature of the JSON (%s)"
                            % (feature, ", ".join(f["name"] for f in feats)))
        best = chosen[0]
    n = len(best["correlation"])
    if len(labels) != n:
        labels = ["demo %d" % d for d in range(n)]
    fig = new_figure("correlation_best", layout="constrained")
    ax = fig.add_subplot(111)
    im = draw_correlation(ax, best, labels, annotate=n <= 12)
    ax.set_title("%s across the %d demonstrations\nmean r = %.3f, DTW-weighted score = %.3f"
                 % (short(best["name"]), n, best["mean_correlation"], best["score"]), fontsize=10)
    fig.colorbar(im, ax=ax, label="correlation coefficient (aligned by DTW)")
    save(fig, out, prefix, "correlation_best", written)

    cols = int(math.ceil(math.sqrt(len(feats))))
    rows = int(math.ceil(len(feats) / cols))
    fig = new_figure("correlation_all", layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    for k, ax in enumerate(axes.flat):
        if k >= len(feats):
            ax.axis("off")
            continue
        f = feats[k]
        im = draw_correlation(ax, f, None, annotate=False)
        ax.set_title("%s\nr=%.2f score=%.2f"
                     % (short(f["name"]), f["mean_correlation"], f["score"]),
                     fontsize=7, fontweight="bold" if f.get("selected") else "normal")
        if f.get("selected"):
            for spine in ax.spines.values():
                spine.set_edgecolor("tab:green")
                spine.set_linewidth(3)
    fig.colorbar(im, ax=axes, shrink=0.6, label="correlation coefficient")
    fig.suptitle("Per-feature correlation matrices across %d demonstrations (green = selected)" % n)
    save(fig, out, prefix, "correlation_all", written)


def plot_relevance(seg, feats, threshold, out, prefix, written):
    names = [short(f["name"]) for f in feats]
    y = np.arange(len(feats))
    fig = new_figure("relevance", layout="constrained")
    axes = fig.subplots(1, 2, sharey=True)
    panels = [("mean_correlation", "selected_correlation_only",
               "(a) mean correlation coefficient only"),
              ("score", "selected", "(b) weighted by the normalized DTW distance")]
    for ax, (key, flag, title) in zip(axes, panels):
        values = np.array([np.nan if f.get(key) is None else f[key] for f in feats], dtype=float)
        chosen = [bool(f.get(flag)) for f in feats]
        colours = ["tab:orange" if c else "tab:gray" for c in chosen]
        ax.barh(y, np.nan_to_num(values), color=colours, edgecolor="black", lw=0.5)
        for yi, v in zip(y, values):
            ax.text(max(np.nan_to_num(v), 0) + 0.01, yi, "n/a" if np.isnan(v) else "%.3f" % v,
                    va="center", fontsize=7)
        if np.any(np.isfinite(values)):
            best = np.nanmax(values)
            ax.axvline(threshold * best, color="red", ls="--", lw=1.5,
                       label="T x best = %.2f x %.3f" % (threshold, best))
            ax.legend(loc="lower right", fontsize=8)
        ax.set_title(title, fontsize=10)
        ax.set_xlim(min(0.0, np.nanmin(np.append(values, 0)) - 0.05), 1.15)
        ax.set_xlabel(key.replace("_", " "))
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels(names, fontsize=8)
    axes[0].invert_yaxis()
    fig.suptitle("Feature relevance across %d demonstrations (orange = selected)"
                 % len(feats[0].get("correlation", [])))
    save(fig, out, prefix, "relevance", written)


def at(seconds, index):
    """Time of a sample index of the JSON on a demo's clock (a zone ends one past its last
    sample)."""
    return seconds[min(int(index), len(seconds) - 1)]


def shade_zones(ax, demo, seconds, label=True):
    for i, z in enumerate(demo.get("zones", [])):
        ax.axvspan(at(seconds, z["begin"]), at(seconds, z["end"]), color="red", alpha=0.12, lw=0,
                   label="confidence zone" if label and i == 0 else None)
        for edge in (z["begin"], z["end"]):
            ax.axvline(at(seconds, edge), color="red", lw=0.8)


def mark_changepoints(ax, demo, seconds, label=True):
    for i, cp in enumerate(demo.get("changepoints", [])):
        ax.axvline(at(seconds, cp), color="black", lw=2.2,
                   label="validated changepoint" if label and i == 0 else None)
    for i, cp in enumerate(demo.get("rejected", [])):
        ax.axvline(at(seconds, cp), color="dimgray", lw=1.4, ls="--",
                   label="rejected candidate" if label and i == 0 else None)
    for i, cp in enumerate(demo.get("pruned", [])):
        ax.axvline(at(seconds, cp), color="purple", lw=1.4, ls=":",
                   label="pruned to the task's count" if label and i == 0 else None)


def plot_profile(seg, d, seconds, out, prefix, written, tag=""):
    demo = seg["demos"][d]
    if "profile" not in demo:
        warn("the JSON holds no ClaSP profile (segment ran with --no-profiles): "
             "clasp_profile skipped")
        return
    profile = as_array(demo["profile"])
    penalized = as_array(demo.get("profile_penalized", []))
    t = seconds[:len(profile)]
    per_feature = demo.get("feature_profiles", {})
    fig = new_figure("clasp_profile", layout="constrained")
    axes = fig.subplots(2 if per_feature else 1, 1, sharex=True, squeeze=False)[:, 0]
    ax = axes[0]
    shade_zones(ax, demo, seconds)
    ax.plot(t, profile, color="tab:blue", lw=1.2, label="combined ClaSP profile")
    twin = None
    if len(penalized) == len(profile):
        ax.plot(t, penalized, color="tab:orange", lw=1.8, label="after the Kaiser filter")
        with np.errstate(divide="ignore", invalid="ignore"):
            window = np.where(np.abs(profile) > 1e-9, penalized / profile, np.nan)
        if np.any(np.isfinite(window)):
            twin = ax.twinx()
            twin.plot(t, window, color="gray", lw=0.8, ls=":", label="Kaiser window (ratio)")
            twin.set_ylim(0, 1.05)
            twin.set_ylabel("Kaiser window", color="gray")
    cands = demo.get("candidates", [])
    for accepted in (True, False):
        pts = [(at(seconds, c["index"]), c["score"]) for c in cands
               if c.get("score") is not None and bool(c.get("accepted_by_clasp")) == accepted]
        if pts:
            xs, ys = zip(*pts)
            ax.scatter(xs, ys, marker="v" if accepted else "x", s=60, zorder=5,
                       color="tab:green" if accepted else "tab:red",
                       label=("candidate (significant)" if accepted
                              else "candidate (not significant)"))
    mark_changepoints(ax, demo, seconds)
    ax.set_ylabel("score")
    handles, labels = ax.get_legend_handles_labels()
    if twin is not None:
        more = twin.get_legend_handles_labels()
        handles, labels = handles + more[0], labels + more[1]
    ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.06, 1.0), fontsize=8)
    ax.set_title("ClaSP profile of %s (first recursion), Kaiser-penalized; %d candidate(s)"
                 % (demo_label(seg, d), len(cands)))
    if per_feature:
        ax2 = axes[1]
        for name, values in per_feature.items():
            v = as_array(values)
            ax2.plot(seconds[:len(v)], v, lw=1, label=short(name), color=feature_colour(seg, name))
        mark_changepoints(ax2, demo, seconds, label=False)
        ax2.set_ylabel("per-feature score")
        ax2.legend(loc="upper left", bbox_to_anchor=(1.06, 1.0), fontsize=7)
    axes[-1].set_xlabel("time (s)")
    save(fig, out, prefix, "clasp_profile", written, tag)


def plot_segmentation(features, phases, seg, d, out, prefix, written, tag=""):
    demo = seg["demos"][d]
    t = features["time"]
    selected = seg.get("selected_features", [])
    weights = seg.get("feature_weights", [])
    sensors = [k for k, r in enumerate(features["roles"]) if r == "sensor"]
    fig = new_figure("segmentation", layout="constrained")
    axes = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    for ax_i, ax in enumerate(axes):
        for k, (name, start) in enumerate(phases):
            end = phases[k + 1][1] if k + 1 < len(phases) else t[-1]
            ax.axvspan(start, end, color=PHASE_COLOURS[k % len(PHASE_COLOURS)], alpha=0.7, lw=0,
                       label="phase: %s (ground truth)" % name if ax_i == 0 else None)
        shade_zones(ax, demo, t, label=ax_i == 0)
        mark_changepoints(ax, demo, t, label=ax_i == 0)
    for k, name in enumerate(selected):
        w = " (w=%.3f)" % weights[k] if k < len(weights) else ""
        axes[0].plot(t, normalize01(features["data"][:, features["names"].index(name)]), lw=1.5,
                     label=short(name) + w, color=feature_colour(seg, name))
    axes[0].set_ylabel("selected features (normalized)")
    axes[0].set_ylim(-0.05, 1.05)
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    for k in sensors:
        axes[1].plot(t, features["data"][:, k], lw=1.2, label=short(features["names"][k]))
    events = demo.get("events", [])
    if events:
        axes[1].plot([at(t, e) for e in events], np.zeros(len(events)), "|", color="red",
                     markersize=14, mew=1.5, label="sensory event")
    axes[1].set_ylabel("sensor signals")
    axes[1].set_xlabel("time (s)")
    if sensors or events:
        axes[1].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    cps = ", ".join("%.2f s" % at(t, c) for c in demo.get("changepoints", [])) or "none"
    axes[0].set_title("Segmentation of %s: validated changepoint(s) %s; %d rejected"
                      % (demo_label(seg, d), cps, len(demo.get("rejected", []))))
    save(fig, out, prefix, "segmentation", written, tag)


def report_rates(report):
    """{dataset: {method: rate or None}} from a pipeline report.json or evaluate_segmentation.py
    output (the same segmentation records, lfd_tools.report)."""
    if isinstance(report, dict) and isinstance(report.get("segmentation"), dict):
        rates, tol = {}, None
        for name, entry in report["segmentation"].items():
            methods = require(entry, "methods", "report segmentation.%s" % name)
            rates[name] = dict(methods)
            tol = entry.get("tolerance_s", tol)
        return rates, tol
    raise UserError("the report has no 'segmentation' section (run the pipeline's segment stage)")


def plot_success_rates(report, out, prefix, written):
    rates, tol = report_rates(report)
    if not rates:
        raise UserError("the report's segmentation section is empty")
    known = ["sim_grasp", "sim_push", "teleop_grasp", "teleop_push"]
    datasets = [n for n in known if n in rates] + sorted(n for n in rates if n not in known)
    methods = [m for m in METHOD_ORDER if any(m in rates[n] for n in datasets)]
    methods += sorted({m for n in datasets for m in rates[n]} - set(methods))
    fig = new_figure("success_rates", layout="constrained")
    ax = fig.add_subplot(111)
    bars = len(methods) + 1
    width = 0.8 / bars
    x = np.arange(len(datasets))
    colours = plt.get_cmap("tab10")
    for k, m in enumerate(methods):
        values = [rates[n].get(m) for n in datasets]
        pos = x - 0.4 + width * (k + 0.5)
        ax.bar(pos, [100 * (v or 0) for v in values], width, color=colours(k), label=m,
               edgecolor="black", lw=0.5)
        for p, v in zip(pos, values):
            ax.text(p, 100 * (v or 0) + 1, "err" if v is None else "%.0f" % (100 * v), ha="center",
                    fontsize=7)
    paper = [PAPER_RATE.get(n.split("_")[0]) for n in datasets]
    pos = x - 0.4 + width * (bars - 0.5)
    ax.bar(pos, [100 * (p or 0) for p in paper], width, color="white", edgecolor="black",
           hatch="//", lw=0.8, label="paper, weighted product (~80 % sim, ~50 % real)")
    counts = report.get("datasets", {}) if isinstance(report.get("datasets"), dict) else {}
    ax.set_xticks(x)
    ax.set_xticklabels(["%s\n(%s demos)" % (n, counts[n]["demos"])
                        if isinstance(counts.get(n), dict) and "demos" in counts[n] else n
                        for n in datasets])
    ax.set_ylim(0, 110)
    ax.set_ylabel("correctly segmented demonstrations (%)")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, fontsize=8)
    ax.set_title("Segmentation success rate per dataset and profile combination"
                 + (" (changepoint tolerance %.2f s)" % tol if tol is not None else ""))
    save(fig, out, prefix, "success_rates", written)


# ---------------------------------------------------------------------------------------------

def parse_demos(spec, count):
    """--demo: an index, a comma list of indices, or 'all'."""
    if spec.strip() == "all":
        return list(range(count))
    try:
        picked = [int(x) for x in spec.split(",") if x.strip()]
    except ValueError:
        raise UserError("--demo takes an index, a comma list of indices or 'all', got '%s'" % spec)
    for d in picked:
        if not 0 <= d < count:
            raise UserError("--demo %d out of range: the JSON holds %d demonstration(s)"
                            % (d, count))
    if not picked:
        raise UserError("--demo is empty")
    return picked


def demo_figures(args, seg, config, d, tag, written):
    """Fig. 5, 7 and 8 of demonstration d."""
    features = feature_matrix(seg, d)
    # Without the matrix (an older JSON) Fig. 5 falls back to the config's clock.
    seconds = features["time"] if features else \
        np.arange(seg["demos"][d].get("num_samples", 0)) / float(config.get("rate", 50.0))
    plot_profile(seg, d, seconds, args.out, args.prefix, written, tag)
    if features is None:
        warn("the JSON holds no feature matrices (run segment with --features): skill map and "
             "segmentation skipped")
        return
    phases = [] if args.no_ground_truth else ground_truth_phases(args, seg, d, features["start"])
    plot_skill_map(features, seg, d, args.out, args.prefix, written, tag)
    plot_segmentation(features, phases, seg, d, args.out, args.prefix, written, tag)


def find_segment_cli():
    try:
        from catkin.find_in_workspaces import find_in_workspaces
        found = find_in_workspaces(search_dirs=["libexec"], project="lfd_segmentation",
                                   path="segment")
    except ImportError:
        found = []
    if not found:
        raise UserError("the `segment` CLI is not in the sourced catkin workspace: "
                        "pass --segment-cli")
    return found[0]


def segment_dataset(args):
    """--dataset DIR: run the `segment` CLI on DIR/*.bag; returns the JSON's path."""
    if not os.path.isdir(args.dataset):
        raise UserError("--dataset '%s' is not a folder" % args.dataset)
    bags = sorted(os.path.join(args.dataset, f) for f in os.listdir(args.dataset)
                  if f.endswith(".bag"))
    if not bags:
        raise UserError("no .bag files in --dataset '%s'" % args.dataset)
    cli = args.segment_cli or find_segment_cli()
    out = os.path.join(args.out, "%ssegment.json" % args.prefix)
    cmd = [cli, "--config", args.config, "--features", "--feature-profiles", "--output", out] + bags
    try:
        run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    except OSError as e:
        raise UserError("cannot run %s: %s" % (cli, e))
    if run.returncode != 0:
        raise UserError("segment failed (exit %d): %s"
                        % (run.returncode, run.stderr.strip()[-2000:]))
    return out


def segment_figures(args, written):
    seg = load_json(args.segment_json, "segment JSON")
    if not isinstance(seg, dict):
        raise UserError("'%s' is not a JSON object" % args.segment_json)
    if seg.get("success") is False:
        raise UserError("'%s' records a failed segmentation: %s"
                        % (args.segment_json, seg.get("error")))
    demos = require(seg, "demos", args.segment_json)
    if not isinstance(demos, list) or not demos:
        raise UserError("'%s' holds no demonstrations" % args.segment_json)
    picked = parse_demos(args.demo, len(demos))
    if args.bags and len(args.bags) != len(demos):
        raise UserError("%d --bags for %d demonstrations in the JSON "
                        "(give them in the JSON's order)" % (len(args.bags), len(demos)))
    for d in picked if args.bags else []:  # before any figure: no half-written set on a typo
        if not os.path.isfile(args.bags[d]):
            raise UserError("bag '%s' does not exist" % args.bags[d])
    config = load_config(args.config)
    threshold = (args.threshold if args.threshold is not None
                 else float(config.get("threshold", 0.9)))

    feats = relevance_features(seg)
    if feats:
        plot_correlations(seg, feats, args.out, args.prefix, written, args.correlation_feature)
        plot_relevance(seg, feats, threshold, args.out, args.prefix, written)
    else:
        warn("the JSON holds no feature relevance (one demo, or fixed features): Fig. 3/4 skipped")
    for d in picked:
        # One demo: plain names; several: suffixed with each demo's name.
        tag = "_" + demo_label(seg, d).replace(" ", "_") if len(picked) > 1 else ""
        demo_figures(args, seg, config, d, tag, written)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--segment-json",
                    help="output of `segment --features --feature-profiles --output`")
    ap.add_argument("--dataset", help="folder of bags: run `segment` on DIR/*.bag first (the JSON "
                                      "is kept as OUT/<prefix>segment.json), then draw")
    ap.add_argument("--segment-cli",
                    help="the `segment` executable (default: the catkin workspace's)")
    ap.add_argument("--bags", nargs="+", help="the demos' bags for the ground-truth phases, in the "
                                              "JSON's order (default: the JSON's demos[].source)")
    ap.add_argument("--config", default=DEFAULT_CONFIG,
                    help="segmentation.yaml (given to segment with --dataset; T of Fig. 4)")
    ap.add_argument("--demo", default="0",
                    help="demo(s) of the per-demo figures: index, comma list or 'all' (names then "
                         "get the demo's name as suffix)")
    ap.add_argument("--correlation-feature",
                    help="feature of correlation_best.png (default: the best DTW-weighted score)")
    ap.add_argument("--threshold", type=float,
                    help="T of the relevance figure (default: the config's)")
    ap.add_argument("--no-ground-truth", action="store_true", help="do not read /lfd/phase")
    ap.add_argument("--report",
                    help="pipeline report.json (or evaluate_segmentation.py --out JSON)")
    ap.add_argument("--out", required=True, help="folder for the PNG files (created)")
    ap.add_argument("--prefix", default="", help="prefix of every PNG name, e.g. sim_grasp_")
    args = ap.parse_args(argv)
    if not (args.segment_json or args.dataset or args.report):
        ap.error("give --segment-json, --dataset and/or --report")
    if args.segment_json and args.dataset:
        ap.error("--segment-json and --dataset exclude each other")
    written = []
    try:
        try:
            os.makedirs(args.out, exist_ok=True)
        except OSError as e:
            raise UserError("cannot create --out '%s': %s" % (args.out, e))
        if args.report:
            plot_success_rates(load_json(args.report, "report"), args.out, args.prefix, written)
        if args.dataset:
            args.segment_json = segment_dataset(args)
        if args.segment_json:
            segment_figures(args, written)
    except UserError as e:
        print("plot_segmentation: error: %s" % e, file=sys.stderr)
        return 2
    except (KeyError, TypeError, ValueError, IndexError) as e:
        # A JSON with the right top-level keys but a wrong inner layout.
        print("plot_segmentation: error: unexpected JSON layout (%s: %s)" % (type(e).__name__, e),
              file=sys.stderr)
        return 2
    if not written:
        print("plot_segmentation: error: no figure could be drawn from this input", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
