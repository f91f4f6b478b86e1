"""Helpers for the rostest suites: waiting for messages and services with explicit time-outs,
reading sim time and model poses. Used by test nodes only."""
import math
import time

import rospy
from gazebo_msgs.srv import GetModelState


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
    q = state.pose.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return state.pose.position.x, state.pose.position.y, yaw


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
    return math.atan2(math.sin(angle), math.cos(angle))
