"""The timestamp policy of lfd_core/io/stamp_order.hpp for the Python readers of recorded messages
(the judge's bag readers, lfd_tools.bags): messages are taken in the order of their stamps, never of
their arrival; out-of-order and duplicate stamps are counted, and so are gaps, and the reader passes
the warning on, worded as the C++ readers word it. Nothing is dropped silently (a late
message arriving last was taken as an object's final pose, and judged the demo by it)."""
import bisect
import sys

# lfd::kStampGapFactor: a step over 10 typical steps is a gap (a stall, lost messages)
GAP_FACTOR = 10.0


def stamp_of(msg, bag_time):
    """A message's header stamp (s), or the time it was recorded when it has none (or a zero
    one)."""
    header = getattr(msg, "header", None)
    stamp = header.stamp.to_sec() if header is not None else 0.0
    return stamp if stamp > 0 else bag_time.to_sec()


def _out_of_order(stamps):
    """Messages that had to move: all but the longest run already in stamp order."""
    tails = []  # tails[k]: least last stamp of an in-order run of k + 1 messages
    for t in stamps:
        k = bisect.bisect_right(tails, t)
        if k == len(tails):
            tails.append(t)
        else:
            tails[k] = t
    return len(stamps) - len(tails)


def _gaps(ordered, report):
    if len(ordered) < 3:
        return
    steps = [b - a for a, b in zip(ordered, ordered[1:])]
    report["typical_step"] = sorted(steps)[len(steps) // 2]
    if not report["typical_step"] > 0:
        return  # mostly duplicates: no clock to judge gaps by
    for start, step in zip(ordered, steps):
        if step > GAP_FACTOR * report["typical_step"] and step > report["largest_gap"]:
            report["largest_gap"], report["gap_start"] = step, start


def order_by_stamp(stamps, keep_duplicates):
    """(indices of `stamps` in stamp order, report) as lfd::orderByStamp: stable (equal stamps keep
    their arrival order); without keep_duplicates only the first message of each stamp is kept."""
    order = sorted(range(len(stamps)), key=lambda i: stamps[i])
    report = {"messages": len(stamps), "out_of_order": _out_of_order(stamps), "duplicates": 0,
              "dropped": 0, "typical_step": 0.0, "largest_gap": 0.0, "gap_start": 0.0}
    kept = []
    for i in order:
        duplicate = bool(kept) and stamps[i] == stamps[kept[-1]]
        report["duplicates"] += duplicate
        if duplicate and not keep_duplicates:
            report["dropped"] += 1
            continue
        kept.append(i)
    _gaps([stamps[i] for i in kept], report)
    return kept, report


def warning(topic, report):
    """lfd::stampWarning: the counts of `report` for `topic`, or "" when all was in order."""
    if not (report["out_of_order"] or report["duplicates"] or report["largest_gap"]):
        return ""
    text = "%s: of %d messages" % (topic, report["messages"])
    if report["out_of_order"]:
        text += ", %d stamped out of order (put in order)" % report["out_of_order"]
    if report["duplicates"]:
        text += ", %d with a duplicate stamp (%s)" % (
            report["duplicates"], "the first of each kept" if report["dropped"] else "all kept")
    if report["largest_gap"]:
        text += ", a gap of %g s at t = %g (typical step %g s)" % (
            report["largest_gap"], report["gap_start"], report["typical_step"])
    return text


def read_in_stamp_order(bag, topics, keep_duplicates=False):
    """([(topic, message, stamp)] of `topics` read from `bag` (anything with rosbag's
    read_messages), each topic in stamp order, all of them merged by stamp; [warning]). Each warning
    is also written to stderr. A duplicate stamp says nothing new of a state: by default the first
    message of each stamp is kept, as the learner keeps it."""
    per_topic = {}
    for topic, msg, t in bag.read_messages(topics=topics):
        per_topic.setdefault(topic, []).append((msg, stamp_of(msg, t)))
    merged, warnings = [], []
    for topic in sorted(per_topic):
        messages = per_topic[topic]
        kept, report = order_by_stamp([s for _, s in messages], keep_duplicates)
        merged += [(topic, messages[i][0], messages[i][1]) for i in kept]
        text = warning(topic, report)
        if text:
            warnings.append(text)
            print("warning: %s" % text, file=sys.stderr)
    merged.sort(key=lambda m: m[2])  # stable: each topic's own order holds
    return merged, warnings
