"""Shared by the reliability rostest nodes in this folder (imported from beside them): watch
/clock and /odom, read a model's state, find the simulator's process id."""
import math
import threading
import xmlrpc.client

import rosgraph
import rospy
from gazebo_msgs.srv import GetModelState
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

from pybullet_gazebo.ros.testing import service, yaw_of


class ClockWatch:
    """Every /clock stamp [s] received, in order; `backward_jumps()` lists (before, after)
    for each stamp lower than the one before it."""

    def __init__(self):
        self._lock = threading.Lock()
        self.stamps = []
        self._sub = rospy.Subscriber("/clock", Clock, self._on_clock, queue_size=1000)

    def _on_clock(self, msg):
        with self._lock:
            self.stamps.append(msg.clock.to_sec())

    def count(self):
        with self._lock:
            return len(self.stamps)

    def latest(self):
        with self._lock:
            return self.stamps[-1] if self.stamps else None

    def backward_jumps(self):
        with self._lock:
            return [(a, b) for a, b in zip(self.stamps, self.stamps[1:]) if b < a]


class OdomWatch:
    """Every /odom message received, as (stamp [s], x, y, z, qx, qy, qz, qw, vx, wz)."""

    def __init__(self, topic="/odom"):
        self._lock = threading.Lock()
        self.rows = []
        self._sub = rospy.Subscriber(topic, Odometry, self._on_odom, queue_size=1000)

    def _on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        t = msg.twist.twist
        with self._lock:
            self.rows.append((msg.header.stamp.to_sec(), p.x, p.y, p.z, q.x, q.y, q.z, q.w,
                              t.linear.x, t.angular.z))

    def since(self, start):
        with self._lock:
            return [row for row in self.rows if row[0] >= start]


def all_finite(values):
    return all(math.isfinite(v) for v in values)


def state(name="m2wr"):
    """(sim time [s], x, y, z, yaw [rad]) of a model from /gazebo/get_model_state."""
    answer = service("/gazebo/get_model_state", GetModelState)(name, "world")
    assert answer.success, answer.status_message
    p = answer.pose.position
    return answer.header.stamp.to_sec(), p.x, p.y, p.z, yaw_of(answer.pose.orientation)


def node_pid(node="/gazebo", master_uri=None):
    """Process id of a running node, asked from the node itself (ROS slave API)."""
    master = rosgraph.Master("/reliability_test", master_uri=master_uri)
    code, _, pid = xmlrpc.client.ServerProxy(master.lookupNode(node)).getPid("/reliability_test")
    assert code == 1, "node %s did not give its pid" % node
    return pid
