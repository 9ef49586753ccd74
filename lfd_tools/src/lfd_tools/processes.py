"""Processes found by what they carry: an environment marker (everything a pipeline stage started,
tagged LFD_PIPELINE_TAG=<pid>:<stage>) or a session id. For cleanup that a process group cannot do:
roslaunch's nodes leave their parent's group and outlive it when roslaunch is killed."""
import contextlib
import os
import signal
import threading
import time

TAG_VAR = "LFD_PIPELINE_TAG"  # <pipeline pid>:<stage>, inherited by everything a stage starts


def processes_with(marker):
    """PIDs (other than this one) whose environment holds `marker` (bytes, e.g. b"NAME=value")."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        with contextlib.suppress(OSError):
            with open("/proc/%s/environ" % entry, "rb") as f:
                if marker in b"\0" + f.read():
                    pids.append(int(entry))
    return pids


def tagged_processes(prefix):
    """Every process started under LFD_PIPELINE_TAG=<prefix>..., including what roslaunch started
    in sessions of their own and what outlived its parent."""
    return processes_with(("\0%s=%s" % (TAG_VAR, prefix)).encode())


def kill_tagged(prefix, grace=5.0):
    """Ends every process started under the tag: SIGTERM, then SIGKILL after `grace` seconds.
    Returns the command names of those that were still running."""
    pids = tagged_processes(prefix)
    names = []
    for pid in pids:
        with contextlib.suppress(OSError):
            with open("/proc/%d/comm" % pid) as f:
                names.append(f.read().strip())
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGTERM)
    deadline = time.time() + grace
    while pids and time.time() < deadline:
        time.sleep(0.1)
        pids = [p for p in pids if os.path.exists("/proc/%d" % p) and not zombie(p)]
    for pid in pids:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    return names


def zombie(pid):
    with contextlib.suppress(OSError):
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    return True


def session_processes(sid):
    """Pids of live (non-zombie) processes of session sid."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            pids.append(int(entry))
    return pids


def tree_cpu(root_pid):
    """{pid: (command name, user s, system s)} of root_pid and every process below it now."""
    ticks = os.sysconf("SC_CLK_TCK")
    children, stats = {}, {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                text = f.read()
        except OSError:
            continue
        name = text[text.index("(") + 1:text.rindex(")")]
        fields = text[text.rindex(")") + 2:].split()
        children.setdefault(int(fields[1]), []).append(int(entry))
        stats[int(entry)] = (name, int(fields[11]) / ticks, int(fields[12]) / ticks)
    tree, todo = {}, [root_pid]
    while todo:
        pid = todo.pop()
        if pid in stats:
            tree[pid] = stats[pid]
        todo.extend(children.get(pid, []))
    return tree


class CpuSampler(threading.Thread):
    """The CPU time of every process of a tree, sampled until stop(): each process's last reading
    is kept (a process that exits loses at most one period of it)."""

    def __init__(self, root_pid, period=0.2):
        threading.Thread.__init__(self, daemon=True)
        self.root_pid, self.period, self.last = root_pid, period, {}
        self._done = threading.Event()

    def run(self):
        while not self._done.is_set():
            self.last.update(tree_cpu(self.root_pid))
            self._done.wait(self.period)

    def stop(self):
        self._done.set()
        self.join()

    def by_name(self):
        """{command name: [user s, system s]}, largest total first."""
        totals = {}
        for name, user, system in self.last.values():
            t = totals.setdefault(name, [0.0, 0.0])
            t[0] += user
            t[1] += system
        return dict(sorted(totals.items(), key=lambda kv: -sum(kv[1])))
