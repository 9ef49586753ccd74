"""Headless rviz: an Xvfb of its own, lfd_launch/inspect.launch on a bag, screen grabs, and a
settled screenshot (lfd_launch/scripts/rviz_screenshot.py; test/integration/rviz_render.py uses the
parts)."""
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image, ImageGrab

from lfd_tools import master
from lfd_tools.processes import session_processes

RVIZ_BACKGROUND = (240, 240, 240)  # config/lfd.rviz Global Options / Background Color
SCREEN = "1280x1024x24"  # holds lfd.rviz's 1200x800 window


def start_xvfb():
    """Xvfb on a display number it picks itself; returns (process, ':N')."""
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write_fd), "-screen", "0", SCREEN,
                             "-nolisten", "tcp"], pass_fds=(write_fd,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    # Read up to the newline: Xvfb dies (EPIPE) if the pipe closes before it has written it all.
    reported, deadline = b"", time.time() + 20.0
    while not reported.endswith(b"\n") and time.time() < deadline:
        ready, _, _ = select.select([read_fd], [], [], max(0.0, deadline - time.time()))
        chunk = os.read(read_fd, 32) if ready else b""
        if not chunk:
            break
        reported += chunk
    os.close(read_fd)
    number = reported.decode().strip()
    if not number:
        stop_process(proc)
        raise RuntimeError("Xvfb did not report a display within 20 s")
    return proc, ":" + number


def stop_process(proc, timeout=10.0):
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def start_inspect(display, bag, log_path, extra_args=(), port=None):
    """`roslaunch lfd_launch inspect.launch` in a session of its own, rviz on `display`.
    port: start a private master there (None: use the running ROS_MASTER_URI)."""
    env = dict(os.environ, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE="1", QT_X11_NO_MITSHM="1",
               XDG_RUNTIME_DIR=os.path.dirname(os.path.abspath(log_path)))
    cmd = ["roslaunch"]
    if port is not None:
        env["ROS_MASTER_URI"] = "http://localhost:%d" % port
        cmd += ["-p", str(port)]
    cmd += ["lfd_launch", "inspect.launch", "bag:=" + bag, "rate:=0"] + list(extra_args)
    log = open(log_path, "w")
    proc = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)
    log.close()
    return proc


def stop_inspect(proc):
    """SIGINT (roslaunch's clean shutdown), then SIGKILL whatever of its session is left.
    Returns the pids still alive afterwards (none when all went well)."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(20.0)
        except subprocess.TimeoutExpired:
            pass
    for pid in session_processes(proc.pid):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    if proc.poll() is None:
        proc.wait(5.0)
    deadline = time.time() + 5.0
    while session_processes(proc.pid) and time.time() < deadline:
        time.sleep(0.1)
    return session_processes(proc.pid)


def grab(display):
    """The whole screen as an RGB numpy array."""
    return np.asarray(ImageGrab.grab(xdisplay=display).convert("RGB"))


def render_area(rgb):
    """Row and column slices of rviz's 3-D view: where its background colour dominates."""
    bg = np.all(rgb == RVIZ_BACKGROUND, axis=-1)
    cols = np.where(bg.mean(axis=0) > 0.3)[0]
    if cols.size == 0:
        return None
    rows = np.where(bg[:, cols[0]:cols[-1] + 1].mean(axis=1) > 0.3)[0]
    if rows.size == 0 or cols[-1] - cols[0] < 200 or rows[-1] - rows[0] < 200:
        return None
    return slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1)


def screenshot(bag, out, extra_args=(), timeout=120.0):
    if not os.path.isfile(bag):
        raise RuntimeError("bag '%s' does not exist" % bag)
    workdir = tempfile.mkdtemp(prefix="lfd_rviz_screenshot_")
    log_path = os.path.join(workdir, "inspect_launch.log")
    xvfb, display = start_xvfb()
    launch = None
    try:
        launch = start_inspect(display, os.path.abspath(bag), log_path, extra_args,
                               master.free_port())
        deadline, previous = time.time() + timeout, None
        while time.time() < deadline:
            if launch.poll() is not None:
                raise RuntimeError("inspect.launch exited; see %s" % log_path)
            rgb = grab(display)
            area = render_area(rgb)
            view = rgb[area] if area is not None else None
            # Drawn and settled: the 3-D view has content and did not change over 2 s.
            if (view is not None and previous is not None and view.shape == previous.shape
                    and np.array_equal(view, previous)
                    and np.mean(np.all(view == RVIZ_BACKGROUND, axis=-1)) < 0.95):
                Image.fromarray(rgb).save(out)
                shutil.rmtree(workdir, ignore_errors=True)  # kept (with the log) on failure
                return out
            previous = view
            time.sleep(2.0)
        raise RuntimeError("rviz did not draw a settled view within %.0f s; see %s"
                           % (timeout, log_path))
    finally:
        left = stop_inspect(launch) if launch is not None else []
        stop_process(xvfb)
        if left:
            print("rviz_screenshot: processes %s survived" % left, file=sys.stderr)
