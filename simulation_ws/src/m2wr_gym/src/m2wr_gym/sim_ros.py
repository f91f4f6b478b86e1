"""A running simulator driven in lockstep over ROS, with the interface of sim_inprocess:
what the environments use when backend="ros" (ids M2wrAvoidRos-v0, M2wrGoalRos-v0).

Needs a master and the stand-in started with lockstep, e.g.
    roslaunch my_worlds launch_world.launch world:=world02 gui:=false real_time_factor:=0 \
        lockstep:=true contacts:=true
m2wr is spawned if it is not in the world (with laser_noise when given).

Per environment step (exact: each step is dt of sim time and the action reaches the drive at
the same sim time as in process):
  publish the action on /cmd_vel, /gazebo/unpause_physics; the scan callback answers every
  intermediate scan of /m2wr/laser/scan with the same command, and at the scan stamped dt
  after the last one calls /gazebo/pause_physics and hands that scan to the main thread as
  the observation, so the agent may think as long as it likes (an agent that computes for
  long would otherwise be stepped past after lockstep_timeout).
Reset: pause, subscribe to the scans and /odom anew (a message from before the reset could
carry the stamp of one after it), /gazebo/reset_simulation (sim time 0),
/gazebo/set_model_state to the start pose, unpause; the callback pauses at the first scan
(stamped one physics step).
Lockstep waits for this process by its reports (the handshake), as for any controller: for
each scan and odometry to be taken in, and, at an unpause, for the command published before
it. The answers and the pause are made in the scan callback itself, not by the main thread,
because lockstep counts a callback as work until it returns: what a callback hands to
another thread is waited for only while that thread is known to read it, which a queue made
at the reset is not until its first wait.
The pose is /odom's (the drive's odometrySource world: the true pose) stamped with the scan's
sim time (after a reset both are first due at the first physics step, then every 0.05 s);
contacts come from /gazebo/contacts. The environment's turning must be the simulator's
(legacy_mode:=true for turning="legacy"), else RosSimError says which to change.
The laser noise follows the simulator's own `seed`, not reset(seed=...).
"""
import math
import queue
import threading

import numpy as np

from pybullet_gazebo.engine.transforms import yaw_from_quaternion

from .sim_inprocess import REST_Z, ROBOT, Snapshot, robot_urdf

SCAN_TOPIC = "/m2wr/laser/scan"
COMMAND_TOPIC = "/cmd_vel"
ODOM_TOPIC = "/odom"
CONTACTS_TOPIC = "/gazebo/contacts"
_SLACK = 1e-6               # [s] stamps are whole nanoseconds of whole physics steps


class RosSimError(RuntimeError):
    pass


class RosSim:
    def __init__(self, world_path, physics_step=0.005, laser_noise=None, timeout=30.0,
                 legacy_mode=False):
        import rospy
        from geometry_msgs.msg import Twist
        from gazebo_msgs.msg import ContactsState
        from std_srvs.srv import Empty
        from gazebo_msgs.srv import (GetPhysicsProperties, GetWorldProperties, SetModelState,
                                     SpawnModel)
        self._rospy, self._Twist = rospy, Twist
        self.physics_step = physics_step
        self.timeout = timeout                         # [s] wall, for each answer awaited
        if not rospy.core.is_initialized():
            rospy.init_node("m2wr_gym_env", anonymous=True, disable_signals=True)
        try:
            for name in ("reset_simulation", "pause_physics", "unpause_physics",
                         "set_model_state", "get_physics_properties", "get_world_properties",
                         "spawn_urdf_model"):
                rospy.wait_for_service("/gazebo/" + name, timeout=timeout)
        except rospy.ROSException:
            raise RosSimError("no simulator answers /gazebo/%s within %g s; start "
                              "one: roslaunch my_worlds launch_world.launch gui:=false "
                              "real_time_factor:=0 lockstep:=true contacts:=true"
                              % (name, timeout)) from None
        if not rospy.get_param("/gazebo/lockstep", False):
            raise RosSimError("the simulator runs without lockstep, so steps would not be exact;"
                              " start it with lockstep:=true")
        if not rospy.get_param("/gazebo/contacts", False):
            raise RosSimError("the simulator does not publish /gazebo/contacts, so a touch would "
                              "go unseen (no crash penalty, no end of episode, unlike in "
                              "process); start it with contacts:=true")
        running = bool(rospy.get_param("/gazebo/legacy_mode", False))
        if running != bool(legacy_mode):
            raise RosSimError(
                "the simulator runs with legacy_mode:=%s but the environment's turning is %r: "
                "a positive angular.z would turn m2wr the other way than the environment "
                "means; start the simulator with legacy_mode:=%s or make the environment with "
                "turning=%r" % (str(running).lower(), "legacy" if legacy_mode else "gazebo",
                                str(bool(legacy_mode)).lower(),
                                "legacy" if running else "gazebo"))
        call = lambda name, kind: rospy.ServiceProxy("/gazebo/" + name, kind, persistent=True)
        self._pause, self._unpause = call("pause_physics", Empty), call("unpause_physics", Empty)
        self._reset_sim = call("reset_simulation", Empty)
        self._set_state = call("set_model_state", SetModelState)
        step = call("get_physics_properties", GetPhysicsProperties)().time_step
        if abs(step - physics_step) > 1e-9:
            raise RosSimError("the simulator's physics step is %g s, the environment's "
                              "physics_step %g s; pass physics_step=%g" % (step, physics_step, step))
        models = call("get_world_properties", GetWorldProperties)().model_names
        self._spawn = None if ROBOT in models else \
            rospy.ServiceProxy("/gazebo/spawn_urdf_model", SpawnModel)
        self._laser_noise = laser_noise
        if self._spawn is None and laser_noise is not None:
            rospy.logwarn("m2wr_gym: m2wr is already in the simulator; laser_noise=%s is not "
                          "applied (its URDF's noise is)", laser_noise)
        self._lock = threading.Lock()
        self._odom = None
        self._contacts = []                     # (stamp, touching names) as published
        self._cmd = rospy.Publisher(COMMAND_TOPIC, Twist, queue_size=10)
        self._contacts_sub = rospy.Subscriber(CONTACTS_TOPIC, ContactsState,
                                              self._on_contacts, queue_size=100)
        self._subs = []                         # scan and odom, subscribed anew at each reset
        self._observations = queue.Queue()      # the scans that end a step (or the reset)
        self._wanted = None                     # [s] the stamp of the scan that ends this step
        self._command = (0.0, 0.0)
        self._time = None

    def _subscribe(self):
        """Scans and odometry on new connections, each into its own queue or slot: after a
        reset, sim time starts again at 0, so a message from before it (still on its way when
        reset_simulation answered) can carry the very stamp that the reset's own observation
        has. On a new connection none can come."""
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import LaserScan
        rospy = self._rospy
        for sub in self._subs:
            sub.unregister()
        with self._lock:
            self._odom = None
        slot = object()                          # this subscription's, not an older one's
        self._slot = slot

        def on_scan(msg):
            if self._slot is slot:
                self._on_scan(msg)

        def on_odom(msg):
            with self._lock:
                if self._slot is slot:
                    self._odom = msg
        self._subs = [rospy.Subscriber(SCAN_TOPIC, LaserScan, on_scan, queue_size=100),
                      rospy.Subscriber(ODOM_TOPIC, Odometry, on_odom, queue_size=100)]

    def _wait_for_connections(self):
        import time
        deadline = time.monotonic() + self.timeout
        while self._cmd.get_num_connections() == 0 or \
                any(s.get_num_connections() == 0 for s in self._subs):
            if time.monotonic() > deadline:
                raise RosSimError("no connection on %s / %s / %s within %g s"
                                  % (COMMAND_TOPIC, SCAN_TOPIC, ODOM_TOPIC, self.timeout))
            time.sleep(0.02)

    def _on_contacts(self, msg):
        names = tuple(sorted({s.collision2_name for s in msg.states}))
        with self._lock:
            self._contacts.append((msg.header.stamp.to_sec(), names))

    def _publish(self, command):
        msg = self._Twist()
        msg.linear.x, msg.angular.z = command
        self._cmd.publish(msg)

    def _on_scan(self, msg):
        """A scan, in its callback: an intermediate one of this step is answered with the
        step's command (lockstep needs an answer to each); the one stamped `_wanted` pauses
        physics and goes to the main thread."""
        wanted = self._wanted
        if wanted is None:
            return                               # not stepping
        stamp = msg.header.stamp.to_sec()
        if abs(stamp - wanted) <= _SLACK:
            self._wanted = None
            self._pause()
            self._observations.put(msg)
        elif stamp < wanted and self._time is not None and stamp > self._time + _SLACK:
            self._publish(self._command)

    def _step_until(self, stamp_wanted):
        """Unpauses and waits for the scan stamped `stamp_wanted` [s] (physics is paused at
        it by then)."""
        self._wanted = stamp_wanted
        self._unpause()
        try:
            return self._observations.get(timeout=self.timeout)
        except queue.Empty:
            self._wanted = None
            raise RosSimError("no scan stamped %.3f s on %s within %g s of wall time"
                              % (stamp_wanted, SCAN_TOPIC, self.timeout)) from None

    def _spawn_at(self, x, y, yaw):
        """m2wr into the simulator at the first start pose (its reset pose from then on)."""
        from geometry_msgs.msg import Pose as PoseMsg
        pose = PoseMsg()
        pose.position.x, pose.position.y, pose.position.z = x, y, REST_Z
        pose.orientation.z, pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        answer = self._spawn(ROBOT, robot_urdf(self._laser_noise), "", pose, "world")
        if not answer.success:
            raise ValueError("start pose (x=%.3f, y=%.3f, yaw=%.3f): the simulator could not "
                             "spawn m2wr: %s" % (x, y, yaw, answer.status_message))
        self._spawn = None

    def reset(self, x, y, yaw, seed=None):
        from gazebo_msgs.msg import ModelState
        if self._spawn is not None:
            self._spawn_at(x, y, yaw)
        self._pause()
        self._subscribe()
        self._wait_for_connections()
        self._reset_sim()
        state = ModelState()
        state.model_name = ROBOT
        state.pose.position.x, state.pose.position.y, state.pose.position.z = x, y, REST_Z
        state.pose.orientation.z, state.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        state.reference_frame = "world"
        answer = self._set_state(state)
        if not answer.success:
            raise RosSimError("set_model_state failed: %s" % answer.status_message)
        with self._lock:
            self._contacts = [(0.0, ())]
        self._command = (0.0, 0.0)
        self._time = None
        msg = self._step_until(self.physics_step)
        self._time = msg.header.stamp.to_sec()
        return self._snapshot(msg, (), start=(x, y, yaw))

    def run(self, linear_x, angular_z, steps):
        start = self._time
        self._command = (float(linear_x), float(angular_z))
        self._publish(self._command)            # the answer to the last observation's scan
        msg = self._step_until(start + steps * self.physics_step)
        self._time = msg.header.stamp.to_sec()
        with self._lock:
            touched = set()
            current = ()
            for stamp, names in self._contacts:
                if stamp <= start + _SLACK:
                    current = names
                elif stamp <= self._time + _SLACK:
                    touched.update(names)
            touched.update(current)
            self._contacts = [(start, ())] + [c for c in self._contacts if c[0] > self._time]
            self._contacts[0] = (self._time, self._contacts_now(self._time))
        return self._snapshot(msg, tuple(sorted(touched)))

    def _contacts_now(self, stamp):
        names = ()
        for t, n in self._contacts:
            if t <= stamp + _SLACK:
                names = n
        return names

    def _snapshot(self, msg, touched, start=None):
        import time
        if start is not None:
            x, y, yaw = start
        else:
            deadline = time.monotonic() + self.timeout
            while True:
                with self._lock:
                    odom = self._odom
                if odom is not None and odom.header.stamp.to_sec() >= \
                        msg.header.stamp.to_sec() - _SLACK:
                    break
                if time.monotonic() > deadline:
                    raise RosSimError("no /odom for sim time %.3f s" % msg.header.stamp.to_sec())
                time.sleep(0.001)
            p, q = odom.pose.pose.position, odom.pose.pose.orientation
            x, y = p.x, p.y
            yaw = yaw_from_quaternion((q.x, q.y, q.z, q.w))
        ranges = np.array(msg.ranges, dtype=np.float32)
        return Snapshot(ranges, float(msg.range_max), float(x), float(y), float(yaw),
                        msg.header.stamp.to_sec(), touched)

    def close(self):
        for sub in getattr(self, "_subs", []) + [getattr(self, "_contacts_sub", None)]:
            if sub is not None:
                sub.unregister()
        if getattr(self, "_cmd", None) is not None:
            try:
                self._publish((0.0, 0.0))
            except Exception:
                pass
            self._cmd.unregister()
            self._cmd = None
