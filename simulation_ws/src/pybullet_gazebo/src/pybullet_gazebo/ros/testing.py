"""Helpers for the rostest suites: waiting for a condition (wait_until, the one way a test
waits), for messages and services with explicit time-outs, reading sim time and model poses, collecting a node's /rosout lines (NodeLog) and the
simulator's touches from /gazebo/contacts (ContactLog), an Xvfb server for tests of windows
(VirtualDisplay). Used by test nodes only."""
import os
import subprocess
import threading
import time

import rospy
from gazebo_msgs.srv import GetModelState

from pybullet_gazebo.engine.transforms import wrap_angle, yaw_from_quaternion


def wait_until(predicate, timeout, what, interval=0.02):
    """Calls `predicate()` every `interval` wall s until it returns something truthy and
    returns that value. After `timeout` wall s, AssertionError naming `what` (a phrase such
    as "a subscriber on /cmd_vel") and the last value the predicate returned. The predicate
    is called at least once, and once more at the deadline; an exception in it propagates."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise AssertionError("timed out waiting for %s within %.1f s (last value: %r)"
                                 % (what, timeout, value))
        time.sleep(max(0.0, min(interval, deadline - time.monotonic())))


def wait_for_message(topic, msg_type, timeout=10.0):
    """The next message on `topic`; AssertionError naming the topic after `timeout` wall s."""
    try:
        return rospy.wait_for_message(topic, msg_type, timeout=timeout)
    except rospy.ROSException:
        raise AssertionError("no %s message on %s within %.0f s" % (msg_type._type, topic, timeout))


def sim_time():
    """Current sim time [s]: the test node runs with /use_sim_time, so rospy follows /clock."""
    return rospy.get_time()


def service(name, srv_type, timeout=15.0):
    try:
        rospy.wait_for_service(name, timeout=timeout)
    except rospy.ROSException:
        raise AssertionError("service %s not offered within %.0f s" % (name, timeout))
    return rospy.ServiceProxy(name, srv_type)


def model_pose(name):
    """(x, y, yaw) of a model from /gazebo/get_model_state."""
    state = service("/gazebo/get_model_state", GetModelState)(name, "")
    assert state.success, state.status_message
    return state.pose.position.x, state.pose.position.y, yaw_of(state.pose.orientation)


def wait_until_sim_time(target, timeout=60.0):
    """Blocks until /clock reaches `target` [s]; AssertionError after `timeout` wall s."""
    deadline = time.monotonic() + timeout
    while sim_time() < target:
        if time.monotonic() > deadline:
            raise AssertionError("sim time stuck at %.2f s, waiting for %.2f s"
                                 % (sim_time(), target))
        time.sleep(0.005)
    return sim_time()


def unwrap_angle(angle):
    """`angle` [rad] wrapped into (-pi, pi]."""
    return wrap_angle(angle)


def yaw_of(orientation):
    """Yaw [rad] of a geometry_msgs/Quaternion."""
    return yaw_from_quaternion((orientation.x, orientation.y, orientation.z, orientation.w))


class NodeLog:
    """Collects what one node logs, from /rosout: `entries` is a list of (sim time [s], text).

    `node` is the full node name, e.g. "/reading_laser". Subscribes at construction, so build
    it before the node starts talking."""

    def __init__(self, node):
        from rosgraph_msgs.msg import Log
        self.node = node
        self.entries = []
        self._lock = threading.Lock()
        self._sub = rospy.Subscriber("/rosout", Log, self._on_log, queue_size=1000)

    def _on_log(self, msg):
        if msg.name == self.node:
            with self._lock:
                self.entries.append((msg.header.stamp.to_sec(), msg.msg))

    def since(self, start):
        """The entries stamped at or after sim time `start` [s]."""
        with self._lock:
            return [(t, text) for t, text in self.entries if t >= start]

    def wait_for(self, count, since=0.0, timeout=30.0):
        """Blocks until `count` entries stamped at or after `since` arrived; returns them.
        AssertionError naming the node after `timeout` wall s."""
        deadline = time.monotonic() + timeout
        while len(self.since(since)) < count:
            if time.monotonic() > deadline:
                raise AssertionError("node %s logged %d messages on /rosout after sim time "
                                     "%.2f s within %.0f s, wanted %d; is it running?"
                                     % (self.node, len(self.since(since)), since, timeout, count))
            time.sleep(0.02)
        return self.since(since)


class ContactLog:
    """Every touch the simulator reports on its latched /gazebo/contacts topic: `touches` is a
    list of (sim time [s], ["robot touches model", ...]), one per non-empty message.
    /gazebo/contacts is opt-in (launch arg contacts:=true): reading `touches` while no
    simulator publishes it raises AssertionError, so a test cannot pass by seeing nothing."""

    def __init__(self, topic="/gazebo/contacts"):
        from gazebo_msgs.msg import ContactsState
        self.topic = topic
        self._touches = []
        self._events = []                   # (sim time, robot, model) of each touch onset
        self._touching = set()
        self.messages = 0
        self._sub = rospy.Subscriber(topic, ContactsState, self._on_contacts, queue_size=1000)

    @property
    def touches(self):
        if self.messages == 0 and self._sub.get_num_connections() == 0:
            raise AssertionError("nothing publishes %s: launch the world with contacts:=true "
                                 "(param /gazebo/contacts) to see touches" % self.topic)
        return self._touches

    def contact_events(self, start=0.0, end=float("inf")):
        """The touch onsets (sim time [s], robot, model) from `start` to `end` [s sim]: a
        pair counts when it starts touching, as the simulator's run summary counts them."""
        self.touches                       # asserts that someone publishes the topic
        return [e for e in self._events if start <= e[0] <= end]

    def _on_contacts(self, msg):
        self.messages += 1
        pairs = {(s.collision1_name, s.collision2_name) for s in msg.states}
        for robot, model in sorted(pairs - self._touching):
            self._events.append((msg.header.stamp.to_sec(), robot, model))
        self._touching = pairs
        if msg.states:
            self._touches.append((msg.header.stamp.to_sec(),
                                  ["%s touches %s" % (s.collision1_name, s.collision2_name)
                                   for s in msg.states]))


class VirtualDisplay:
    """An Xvfb server on a free display number (Xvfb picks it: -displayfd), stopped by PID."""

    def __init__(self):
        read_end, write_end = os.pipe()
        self.process = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1024x768x24",
             "-nolisten", "tcp"], pass_fds=(write_end,), stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True)
        os.close(write_end)
        with os.fdopen(read_end) as pipe:
            number = pipe.readline().strip()       # written once the server accepts clients
        if not number:
            self.stop()
            raise AssertionError("Xvfb did not start")
        self.display = ":" + number

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
