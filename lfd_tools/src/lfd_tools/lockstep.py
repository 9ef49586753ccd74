"""A client of the simulated work cell and the executor's action that drives the simulation in
lockstep: the bridge stays paused, and the client steps it (/bridge/step) while a goal of
/executor/execute moves, from the motion start the action's feedback announces. A goal then costs
its physics and planning, not its duration in wall time, and runs the same whatever the load. The
executor knows no simulator (it follows sim time); this client does.

No rospy timeout is used while paused: rospy's run on sim time, which stands still until this
client steps. Every wait here is bounded in wall time.
"""
import collections
import contextlib
import time

STEP_CHUNK = 50  # physics steps (1 ms) per /bridge/step call while a goal moves
PLANNING_TIMEOUT_S = 120.0  # wall s for the executor to plan (it sends feedback meanwhile)
# wall s the client holds the clock before a motion's start until the bridge has taken in its
# trajectory; then it steps anyway (a trajectory that never comes must not hang the goal)
TRAJECTORY_WAIT_S = 5.0
GOAL_TIMEOUT_S = 600.0      # wall s for a whole goal; then it is cancelled


def pose_msg(p):
    """geometry_msgs/Pose of a lfd_tools.tasks pose {position, orientation [w, x, y, z]}."""
    from geometry_msgs.msg import Point, Pose, Quaternion
    w, x, y, z = p["orientation"]
    return Pose(position=Point(*p["position"]), orientation=Quaternion(w=w, x=x, y=y, z=z))


def stamped(p, frame="world"):
    from geometry_msgs.msg import PoseStamped
    msg = PoseStamped(pose=pose_msg(p))
    msg.header.frame_id = frame
    return msg


def message_type(topic):
    """The message type of a topic of the work cell's contract (DESIGN.md)."""
    from geometry_msgs.msg import PoseStamped
    from lfd_msgs.msg import Touch
    from sensor_msgs.msg import JointState
    from lfd_tools import config
    types = {"/joint_states": JointState, "/objects/joint_states": JointState,
             config.sensor_topic("lfd_msgs/Touch"): Touch}
    if topic in types:
        return types[topic]
    if topic.startswith("/objects/") or topic == "/ee_pose":  # /objects/<body>/pose
        return PoseStamped
    raise RuntimeError("no message type known for topic %s" % topic)


class LiveRecording(object):
    """The messages of some topics from now on, read like a rosbag (lfd_tools.bags.measure judges
    them as it judges a recorded demonstration): one judge for demonstrations and reproductions,
    without a bag file per goal."""

    def __init__(self, topics, since):
        import rospy
        self.since, self.messages = since, {t: [] for t in topics}
        self.subs = [rospy.Subscriber(t, message_type(t), self._on, t, queue_size=10000)
                     for t in topics]

    def _on(self, msg, topic):
        if msg.header.stamp.to_sec() >= self.since:
            self.messages[topic].append(msg)

    def wait_until(self, stamp, timeout=30.0):
        """Every topic has delivered a message stamped at or after `stamp` (sim s): the last
        published state is in (False after `timeout` wall s)."""
        deadline = time.time() + timeout
        while time.time() < deadline:
            if all(m and m[-1].header.stamp.to_sec() >= stamp - 1e-6
                   for m in self.messages.values()):
                return True
            time.sleep(0.005)
        return False

    def close(self):
        for sub in self.subs:
            sub.unregister()

    def read_messages(self, topics=None):
        """(topic, message, stamp) in arrival order, as rosbag.Bag.read_messages (its readers put
        them in stamp order: lfd_tools.stamps)."""
        for topic, ms in self.messages.items():
            if topics is None or topic in topics:
                for m in ms:
                    yield topic, m, m.header.stamp


def execute_goal(library, scene, duration_scale=1.0, allow_extrapolation=False, dry_run=False,
                 follow=False):
    """An lfd_msgs/ExecuteTaskGoal for a scene {"objects": {name: pose}, "goal": pose} (world).
    follow: each object's pose is given as the origin of its own tf frame (the bridge publishes
    one per object, as a tracker would), so the executor follows an object that moves while the
    robot approaches it; else in the world frame (fixed)."""
    from lfd_msgs.msg import ExecuteTaskGoal
    origin = {"position": [0.0, 0.0, 0.0], "orientation": [1.0, 0.0, 0.0, 0.0]}
    poses = [stamped(origin, name) if follow else stamped(p)
             for name, p in scene["objects"].items()]
    return ExecuteTaskGoal(library=library, object_names=list(scene["objects"]),
                           object_poses=poses,
                           goal=stamped(scene["goal"]), duration_scale=duration_scale,
                           allow_extrapolation=allow_extrapolation, dry_run=dry_run)


class Cell(object):
    """The work cell (the simulation's services, the objects' poses) and the executor's action.
    `lockstep`: pause the bridge and step it; otherwise it runs on its own (e.g. paced at
    real time for rviz). Starts this process's rospy node."""

    def __init__(self, lockstep=True, node_name="lockstep_client"):
        import actionlib
        import rospy
        from lfd_msgs.msg import ExecuteTaskAction, ExecuteTaskActionFeedback
        from lfd_msgs.srv import ResetSim, SetScene, StepSim
        from std_srvs.srv import SetBool
        from lfd_tools import master
        self.rospy, self.lockstep = rospy, lockstep
        master.wait_for_param("/use_sim_time", 120)  # rospy reads it once, at init
        # Persistent: a reproduction steps the bridge thousands of times (profile-reproduction).
        self.srv = master.service_proxies(node_name, {
            "/bridge/reset": ResetSim, "/bridge/set_scene": SetScene, "/bridge/pause": SetBool,
            "/bridge/step": StepSim}, persistent=True)
        # The plain client: SimpleActionClient drops a result that arrives before send_goal has
        # returned (a refusal answered within the caller's time slice), and its timeouts run on
        # sim time, which stands still while paused.
        self.action = actionlib.ActionClient("/executor/execute", ExecuteTaskAction)
        # Every feedback of a goal, by goal id, from the topic itself: the action client drops
        # feedback that arrives after its goal's result, and the executor's last feedback (the
        # settle's, with the final progress) and its result travel on two connections, so a
        # loaded machine may deliver them in either order (executor_action, fresh root).
        self._feedback_by_goal = collections.defaultdict(list)
        self._goal_id = None
        self._feedback_sub = rospy.Subscriber(
            "/executor/execute/feedback", ExecuteTaskActionFeedback,
            lambda m: self._feedback_by_goal[m.status.goal_id.id].append(m.feedback),
            queue_size=1000)
        deadline = time.time() + 120
        while not self._server_ready():
            if time.time() > deadline:
                raise RuntimeError("the executor's action /executor/execute did not come up in "
                                   "120 s")
            time.sleep(0.01)
        self.goal_handle = None
        # Wall s and calls by activity since the last take_wall()
        # (bench/pipeline/profile_reproduction.py).
        self.wall, self.calls = collections.Counter(), collections.Counter()
        self.srv["/bridge/pause"](data=lockstep)
        self.sim_time = self.step(1) if lockstep else None
        while rospy.Time.now().is_zero():
            time.sleep(0.01)

    def _server_ready(self):
        """ActionClient.wait_for_server's test, without its sim-time timeout: the server's status
        arrived and every topic to and from it is connected (a goal sent earlier is lost)."""
        a = self.action
        if not a.last_status_msg:
            return False
        server = a.last_status_msg._connection_header["callerid"]
        return (a.pub_goal.impl.has_connection(server) and a.pub_cancel.impl.has_connection(server)
                and any(c.callerid_pub == server for c in a.result_sub.impl.connections)
                and any(c.callerid_pub == server for c in a.feedback_sub.impl.connections)
                and any(c.callerid_pub == server for c in self._feedback_sub.impl.connections))

    @property
    def feedback(self):
        """The feedback of the last goal sent, in arrival order (also after its result)."""
        return self._feedback_by_goal[self._goal_id] if self._goal_id else []

    @contextlib.contextmanager
    def timed(self, activity):
        """Counts the block's wall time under `activity` (nested blocks count in both)."""
        start = time.perf_counter()
        try:
            yield
        finally:
            self.wall[activity] += time.perf_counter() - start
            self.calls[activity] += 1

    def take_wall(self):
        """({activity: wall s}, {activity: calls}) since the last call; the counters restart."""
        taken = dict(self.wall), dict(self.calls)
        self.wall.clear()
        self.calls.clear()
        return taken

    def step(self, steps):
        with self.timed("step_calls"):
            r = self.srv["/bridge/step"](steps=steps)
        if not r.success:
            raise RuntimeError("/bridge/step: " + r.message)
        self.sim_time = r.sim_time
        self.trajectory_stamp = r.last_trajectory_stamp  # as the call found it
        return r.sim_time

    def now(self):
        return self.sim_time if self.lockstep else self.rospy.get_time()

    def advance(self, seconds):
        """Lets `seconds` of sim time pass: stepped in lockstep, waited for otherwise."""
        if self.lockstep:
            left = int(round(seconds * 1000))
            while left > 0:
                self.step(min(10 * STEP_CHUNK, left))
                left -= 10 * STEP_CHUNK
            return
        end = self.rospy.get_time() + seconds
        while self.rospy.get_time() < end and not self.rospy.is_shutdown():
            time.sleep(0.002)

    def set_scene(self, placed, settle, joints=None):
        """Resets the robot and the objects (the articulated joints {name: value} at their start),
        places {name: pose}, lets them settle (sim s)."""
        joints = joints or {}
        with self.timed("scene_calls"):
            r = self.srv["/bridge/reset"](joint_names=list(joints),
                                          positions=[float(v) for v in joints.values()],
                                          reset_objects=True)
        if not r.success:
            raise RuntimeError("reset failed: " + r.message)
        with self.timed("scene_calls"):
            s = self.srv["/bridge/set_scene"](object_names=list(placed),
                                              poses=[pose_msg(p) for p in placed.values()])
        if not s.success:
            raise RuntimeError("set_scene failed: " + s.message)
        self.advance(settle)

    def record(self, topics):
        """A LiveRecording of `topics` from the current sim time on."""
        return LiveRecording(topics, self.now())

    def send(self, goal):
        """Sends a goal; its feedback is collected in self.feedback."""
        self._feedback_by_goal.clear()  # the earlier goals' (a run sends hundreds)
        self.goal_handle = self.action.send_goal(goal)
        self._goal_id = self.goal_handle.comm_state_machine.action_goal.goal_id.id

    def cancel(self):
        self.goal_handle.cancel()

    def moving(self):
        """The feedback says the motion was sent (it starts at feedback.motion_start)."""
        from lfd_msgs.msg import ExecuteTaskFeedback
        return any(f.state != ExecuteTaskFeedback.PLANNING for f in self.feedback)

    def replanning(self):
        """The executor plans the rest of the motion anew (an object moved). In lockstep the clock
        is held meanwhile: the new motion starts ~follow_objects/lead (sim s) after the look that
        saw the move, which covers the planning on a robot's clock, but a client stepping ~9x
        faster than real time would run past it while the plan is computed."""
        from lfd_msgs.msg import ExecuteTaskFeedback
        return bool(self.feedback) and self.feedback[-1].state == ExecuteTaskFeedback.REPLANNING

    def done(self):
        from actionlib import CommState
        return self.goal_handle.get_comm_state() == CommState.DONE

    def trajectory_pending(self):
        """The motion is sent but the bridge has not taken in its trajectory, and the next chunk
        would step past the motion's start. The executor publishes the trajectory, then the
        feedback that says it moves; on a loaded machine the feedback can arrive first, and a
        trajectory taken in after its start runs late: the arm starts behind it (measured on a
        fresh root: 9.24 s for a motion planned for 8.66 s)."""
        # the latest motion's feedback, searched from the end: this runs at every step
        sent = next((f for f in reversed(self.feedback) if f.state != f.PLANNING), None)
        if sent is None:
            return False
        start = sent.motion_start.to_sec()
        return (self.trajectory_stamp < start - 1e-6 and
                self.sim_time + STEP_CHUNK * 1e-3 > start)

    def drive(self, until=None, timeout=GOAL_TIMEOUT_S):
        """Steps the simulation while the goal moves, until it is done (or `until()` is true):
        True when it ended (or `until` held), False after `timeout` wall s. The clock is held
        before a motion's start until the bridge has its trajectory (TRAJECTORY_WAIT_S at most)."""
        started = time.time()
        held = None  # wall time the clock was first held for the current trajectory
        while not self.done() and not (until and until()):
            wall = time.time() - started
            if wall > timeout or (not self.moving() and wall > PLANNING_TIMEOUT_S):
                return False
            if self.lockstep and self.moving() and not self.replanning():
                if self.trajectory_pending():
                    held = held or time.time()
                    if time.time() - held < TRAJECTORY_WAIT_S:
                        self.step(0)  # asks the bridge what it has taken in; steps nothing
                        time.sleep(0.002)
                        continue
                held = None
                self.step(STEP_CHUNK)
            else:
                time.sleep(0.002)
        return True

    def result(self):
        """The finished goal's result and final status (actionlib_msgs/GoalStatus); the goal
        handle is released."""
        gh, self.goal_handle = self.goal_handle, None
        return gh.get_result(), gh.get_goal_status()

    def execute(self, goal, timeout=GOAL_TIMEOUT_S, on_moving=None):
        """Sends the goal and drives it to its end: (result, wall s); cancelled after `timeout`.
        on_moving(feedback): called once the motion is sent (feedback.motion_start), before any
        of it is stepped (e.g. to schedule faults on its clock)."""
        started = time.time()
        # until the executor has planned and sent the motion (or ended)
        with self.timed("planning"):
            self.send(goal)
            driven = self.drive(until=self.moving, timeout=timeout)
        if driven and on_moving and not self.done():
            on_moving(next(f for f in self.feedback if f.state != f.PLANNING))
        stepped_before = self.wall["step_calls"]
        with self.timed("motion"):
            driven = driven and self.drive(timeout=max(1.0, timeout - (time.time() - started)))
        self.wall["motion_step_calls"] += self.wall["step_calls"] - stepped_before
        if not driven:
            self.cancel()
            raise RuntimeError("the goal took over %.0f s of wall time; cancelled"
                               % (time.time() - started))
        return self.result()[0], time.time() - started
