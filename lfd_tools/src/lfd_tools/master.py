"""A private ROS master for a stage, a client or a test, and clean shutdown of what it started."""
import contextlib
import os
import signal
import socket
import subprocess
import time

START_TIMEOUT_S = 30.0
START_ATTEMPTS = 5
PARAM_SERVER_GRACE_S = 1.0  # the parameter server answers a little after the port opens


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def master_uri(port):
    return "http://localhost:%d" % port


def port_open(port):
    with socket.socket() as s:
        return s.connect_ex(("localhost", port)) == 0


def stop_group(proc, timeout):
    """SIGINT a process group (roslaunch/roscore shut down cleanly on it), SIGKILL if it hangs."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def master_online(env=None):
    """Whether a master answers at ROS_MASTER_URI of `env` (default: this process's)."""
    import rosgraph
    uri = (env or os.environ).get("ROS_MASTER_URI")
    return bool(uri) and rosgraph.is_master_online(uri)


def roscore_on(port, env):
    """A roscore on `port` with `env` once its port is open, or None when it exited at start (the
    port was taken)."""
    core = subprocess.Popen(["roscore", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + START_TIMEOUT_S
    while not port_open(port) and core.poll() is None:
        if time.time() > deadline:
            stop_group(core, 15)
            raise RuntimeError("roscore did not come up on port %d" % port)
        time.sleep(0.2)
    return core if core.poll() is None else None


def start_roscore():
    """(process, env) of a roscore on a free port. The port is free when chosen, but another
    process (a second master's servers, starting at the same time) may take it before roscore
    binds it: then roscore exits at once, and another port is tried."""
    for _ in range(START_ATTEMPTS):
        port = free_port()
        env = dict(os.environ, ROS_MASTER_URI=master_uri(port))
        core = roscore_on(port, env)
        if core is not None:
            return core, env
    raise RuntimeError("roscore exited at start %d times (last port %d)" % (START_ATTEMPTS, port))


@contextlib.contextmanager
def private_master():
    """A roscore on a free port; yields a copy of os.environ whose ROS_MASTER_URI points to it.
    The master (and whatever it started) is stopped on exit."""
    core, env = start_roscore()
    try:
        time.sleep(PARAM_SERVER_GRACE_S)
        yield env
    finally:
        stop_group(core, 15)


@contextlib.contextmanager
def master_for_this_process():
    """The master of ROS_MASTER_URI when one answers, else a private one that this process (and
    what it starts) uses until the block ends."""
    if master_online():
        yield os.environ
        return
    previous = os.environ.get("ROS_MASTER_URI")
    with private_master() as env:
        os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
        try:
            yield os.environ
        finally:
            if previous is None:
                os.environ.pop("ROS_MASTER_URI", None)
            else:
                os.environ["ROS_MASTER_URI"] = previous


@contextlib.contextmanager
def background_launch(cmd, env, stdout=subprocess.DEVNULL):
    """A roslaunch (or any command) in the background, in a session of its own, for the block."""
    print("[lfd] $ %s &" % " ".join(cmd), flush=True)
    proc = subprocess.Popen(cmd, env=env, start_new_session=True, stdout=stdout)
    try:
        yield proc
    finally:
        stop_group(proc, 20)


@contextlib.contextmanager
def graph_for_this_process(launch_args, attach):
    """With `attach`, the nodes running at ROS_MASTER_URI (an error when no master answers); else a
    private master with `roslaunch <launch_args>` on it, used by this process until the block ends
    (never another run's master that happens to answer on the default port)."""
    if attach:
        if not master_online():
            raise RuntimeError("no ROS master answers at %s (--attach)"
                               % os.environ.get("ROS_MASTER_URI"))
        yield
        return
    previous = os.environ.get("ROS_MASTER_URI")
    with private_master() as env:
        os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
        try:
            with background_launch(["roslaunch"] + list(launch_args), env):
                yield
        finally:
            os.environ.pop("ROS_MASTER_URI", None)
            if previous is not None:
                os.environ["ROS_MASTER_URI"] = previous


def wait_for_param(name, timeout):
    """Waits until the parameter exists (e.g. /use_sim_time, which rospy reads once, at init)."""
    import rosgraph
    master, deadline = rosgraph.Master("/lfd_tools_probe"), time.time() + timeout
    while not master.hasParam(name):
        if time.time() > deadline:
            raise RuntimeError("parameter %s never set (is the launch running?)" % name)
        time.sleep(0.2)


def service_proxies(node_name, services, timeout=120.0, persistent=False):
    """Starts this process's rospy node and returns {name: ServiceProxy} once every service of
    {name: type} answers. Ctrl-C raises KeyboardInterrupt (signals stay Python's).
    persistent: keep one connection per service (for a service called thousands of times: a
    plain proxy asks the master where the service is and opens a new connection on every call,
    0.9 ms more per call here, and the master's CPU with it). A persistent proxy whose server went
    away raises rospy.ServiceException on its next call; it is not reconnected (a retried call
    could act twice)."""
    import rospy
    rospy.init_node(node_name, anonymous=True, disable_signals=True)
    proxies = {}
    for name, typ in services.items():
        try:
            rospy.wait_for_service(name, timeout=timeout)
        except rospy.ROSException:
            raise RuntimeError("service %s did not come up within %.0f s" % (name, timeout))
        proxies[name] = rospy.ServiceProxy(name, typ, persistent=persistent)
    return proxies


def inbound_topics(node):
    """The topics `node` receives on a live connection (its bus info; the master's registration of
    a subscription comes before the publishers connect)."""
    import xmlrpc.client
    import rosgraph
    uri = rosgraph.Master("/lfd_tools_probe").lookupNode(node)
    code, _, info = xmlrpc.client.ServerProxy(uri).getBusInfo("/lfd_tools_probe")
    # roscpp: [id, peer, direction i/o, transport, topic, connected, ...]
    return {c[4] for c in info if c[2] == "i" and (len(c) < 6 or c[5])} if code == 1 else set()


def wait_for_inbound(node, topics, timeout, proc=None):
    """Waits until `node` is connected to every topic of `topics` that has a publisher. Returns the
    published topics it still misses after `timeout`, or as soon as `proc` (the node's process)
    has ended (empty: all connected)."""
    import rosgraph
    master, deadline = rosgraph.Master("/lfd_tools_probe"), time.time() + timeout
    while True:
        missing = set()
        try:
            published = {t for t, nodes in master.getSystemState()[0] if nodes}
            missing = (set(topics) & published) - inbound_topics(node)
        except (rosgraph.MasterError, OSError) as exc:  # the node is not up yet
            missing = {"(%s)" % exc}
        if proc is not None and proc.poll() is not None:
            return sorted(missing | {"(its process ended, exit %d)" % proc.returncode})
        if not missing or time.time() > deadline:
            return sorted(missing)
        time.sleep(0.05)
