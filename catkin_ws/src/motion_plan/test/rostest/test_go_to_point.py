#!/usr/bin/env python3
"""rostest: the project's go-to-point node (nodes/standin_go_to_point.py) takes m2wr from
(0, 8), facing +x, to each goal within 0.3 m, as episode 6 of the series shows.

For each goal: m2wr is put back at (0, 8) yaw 0 with /gazebo/set_model_state, the goal is set
in des_pos_x/des_pos_y and /go_to_point_switch is called with data true; the test watches
/odom until the node says `goal reached` (or `goal_timeout` s of sim time pass), then for 2 s
of sim time more: the robot must have come within 0.3 m and be at rest (< 0.05 m/s) within
0.35 m of the goal (it stops where it declared done), then the node is switched off. It prints, per goal, the nearest distance, the sim time
taken and the touches /gazebo/contacts reported.
Parameters (~): goals "x,y;x,y;..." [m], goal_timeout [s sim] (60), wall_timeout [s wall].
"""
import math
import threading
import time
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import GetModelState, SetModelState
from nav_msgs.msg import Odometry
from std_srvs.srv import SetBool

from pybullet_gazebo.ros.testing import ContactLog, NodeLog, service, sim_time, wait_for_message

START = (0.0, 8.0)
TOLERANCE = 0.3             # [m] the series' "done" distance


def parse_goals(text):
    return [tuple(float(v) for v in pair.split(",")) for pair in text.split(";") if pair.strip()]


class GoToPointTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_go_to_point")
        cls.goals = parse_goals(rospy.get_param("~goals"))
        cls.goal_timeout = rospy.get_param("~goal_timeout", 60.0)
        cls.wall_timeout = rospy.get_param("~wall_timeout", 100.0)
        cls.lock = threading.Lock()
        cls.odom = None
        cls.contacts = ContactLog()
        cls.node_log = NodeLog("/go_to_point")
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=1)
        wait_for_message("/odom", Odometry, timeout=60)
        cls.switch = service("/go_to_point_switch", SetBool, timeout=30)
        cls.set_state = service("/gazebo/set_model_state", SetModelState)
        cls.get_state = service("/gazebo/get_model_state", GetModelState)

    @classmethod
    def on_odom(cls, msg):
        with cls.lock:
            p = msg.pose.pose.position
            cls.odom = (msg.header.stamp.to_sec(), p.x, p.y, msg.twist.twist.linear.x,
                        msg.twist.twist.angular.z)

    def place_at_start(self):
        state = ModelState(model_name="m2wr")
        state.pose.position.x, state.pose.position.y = START
        state.pose.position.z = self.get_state("m2wr", "").pose.position.z
        state.pose.orientation.w = 1.0
        self.assertTrue(self.set_state(state).success)
        settle = sim_time() + 0.5
        while sim_time() < settle and not rospy.is_shutdown():
            rospy.sleep(0.05)

    def run_to(self, goal):
        """(nearest distance [m], sim time [s] to get within TOLERANCE and stop, touches)."""
        self.place_at_start()
        rospy.set_param("des_pos_x", goal[0])
        rospy.set_param("des_pos_y", goal[1])
        touches_before = len(self.contacts.touches)
        start = sim_time()
        self.switch(True)
        nearest, reached_at, said_done, distance, v = math.inf, None, None, math.inf, 0.0
        wall_end = time.monotonic() + self.wall_timeout
        try:
            while not rospy.is_shutdown() and time.monotonic() < wall_end:
                with self.lock:
                    t, x, y, v, w = self.odom
                distance = math.hypot(goal[0] - x, goal[1] - y)
                nearest = min(nearest, distance)
                if said_done is None and any(text.startswith("goal reached") for _, text
                                             in self.node_log.since(start)):
                    said_done = t
                if said_done is not None and t > said_done + 2.0:
                    if nearest < TOLERANCE and distance < TOLERANCE + 0.05 and abs(v) < 0.05:
                        reached_at = said_done - start
                    break
                if t - start > self.goal_timeout:
                    break
                time.sleep(0.01)
        finally:
            self.switch(False)
        touches = self.contacts.touches[touches_before:]
        events = self.contacts.contact_events(start)
        rospy.loginfo("goal (%.1f, %.1f): nearest %.3f m, at rest %.3f m from it (%.3f m/s), "
                      "reached after %s s of sim time, %d contact event(s) %s", goal[0], goal[1],
                      nearest, distance, v,
                      "%.2f" % reached_at if reached_at is not None else "(never)",
                      len(events), events[:3])
        print("FIGURES goal=(%.1f,%.1f) nearest=%.3f final=%.3f time=%s contact_events=%d"
              % (goal[0], goal[1], nearest, distance, reached_at, len(events)))
        return nearest, reached_at, touches

    def test_reaches_each_goal_from_0_8(self):
        failures = []
        for goal in self.goals:
            nearest, reached_at, touches = self.run_to(goal)
            if reached_at is None or touches:
                failures.append("goal %s: nearest %.2f m, reached after %s s, touches %s"
                                % (goal, nearest, reached_at, touches[:3]))
        self.assertEqual(failures, [])


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "go_to_point", GoToPointTest)
