"""Processes found by what they carry: an environment marker (everything a pipeline stage started,
tagged LFD_PIPELINE_TAG=<pid>:<stage>) or a session id. For cleanup that a process group cannot do:
roslaunch's nodes leave their parent's group and outlive it when roslaunch is killed."""
import contextlib
import os
import signal
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
