"""Tool runs side by side: a stage whose work splits into independent parts (datasets, tasks,
figures) runs them on every core, each part with a ROS graph of its own when it needs one (a
private master from lfd_tools.master). Ctrl-C interrupts every running tool the way roslaunch
expects (SIGINT to its session, SIGKILL if it hangs), so recorders close their bags and nothing
recorded is lost, then re-raises in the caller."""
import collections
import concurrent.futures
import os
import subprocess
import sys
import threading

from lfd_tools.master import stop_group

STDERR_TAIL_LINES = 3  # of a failed tool's stderr, quoted in the caller's error
INTERRUPT_TIMEOUT_S = 30.0

_live = set()  # tool processes running now, for interruption
_interrupted = threading.Event()  # set by interrupt_all: no job starts another tool
_live_lock = threading.Lock()
_print_lock = threading.Lock()


def workers(requested=0):
    """How many jobs run at once: `requested` when > 0, else one per core."""
    return requested if requested > 0 else max(1, os.cpu_count() or 1)


def _echo(line, label):
    with _print_lock:
        sys.stderr.write(("[%s] %s" % (label, line)) if label else line)
        sys.stderr.flush()


def run_tool(cmd, env=None, label=None):
    """Runs a tool; returns (exit status, its last stderr lines). Its stderr still shows, each
    line prefixed with [label] when several tools run at once."""
    if _interrupted.is_set():
        raise KeyboardInterrupt
    _echo("$ " + " ".join(cmd) + "\n", label)
    proc = subprocess.Popen(cmd, env=env, start_new_session=True, stderr=subprocess.PIPE,
                            universal_newlines=True, errors="replace")
    with _live_lock:
        _live.add(proc)
    tail = collections.deque(maxlen=STDERR_TAIL_LINES)
    try:
        for line in proc.stderr:
            _echo(line, label)
            if line.strip() and not line[0].isspace():  # a traceback's code lines are indented
                tail.append(line.rstrip())
        rc = proc.wait()
    except KeyboardInterrupt:  # Ctrl-C in this (main) thread: the tool shuts down cleanly first
        stop_group(proc, INTERRUPT_TIMEOUT_S)
        raise
    finally:
        with _live_lock:
            _live.discard(proc)
    if _interrupted.is_set():
        raise KeyboardInterrupt  # the job unwinds (its master and launch stop) instead of going on
    return rc, "\n".join(tail)


def interrupt_all():
    """SIGINT every running tool's session (SIGKILL after a grace period); no job starts another."""
    _interrupted.set()
    with _live_lock:
        running = list(_live)
    threads = [threading.Thread(target=stop_group, args=(p, INTERRUPT_TIMEOUT_S)) for p in running]
    for t in threads:
        t.start()
    for t in threads:
        t.join()


def run_parallel(jobs, count=0):
    """Runs the callables `jobs` on `workers(count)` threads; returns their results in order. The
    first exception of a job is raised after every job has ended. Ctrl-C interrupts every tool,
    waits for the jobs to unwind (their masters and launches stop) and re-raises."""
    _interrupted.clear()
    if len(jobs) <= 1 or workers(count) == 1:
        return [job() for job in jobs]
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=workers(count))
    futures = [pool.submit(job) for job in jobs]
    try:
        concurrent.futures.wait(futures)
    except KeyboardInterrupt:
        interrupt_all()
        pool.shutdown(wait=True)  # the jobs' own KeyboardInterrupts stay in their futures
        raise
    pool.shutdown(wait=True)
    return [f.result() for f in futures]


def split(items, parts):
    """`items` dealt round-robin into at most `parts` non-empty lists (order kept within each)."""
    parts = max(1, min(parts, len(items)))
    return [items[i::parts] for i in range(parts)] if items else []
