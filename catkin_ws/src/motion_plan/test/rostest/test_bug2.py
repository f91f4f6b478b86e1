#!/usr/bin/env python3
"""rostest: the project's bug-2 controller (nodes/standin_bug2.py, with its go-to-point and
wall-following nodes) takes m2wr from (0, 8) to the goal round the walls in the way, as
episodes 8-10 of the series show.

The controller places the robot itself (position-only /gazebo/set_model_state, as the series'
programs do). The test watches /odom from then on until the robot is within 0.3 m of the goal
and the controller has logged `goal reached` (or `duration` s of sim time pass), and
/gazebo/contacts. It prints the nearest distance, the sim time taken, the path length, the
controller's state changes and the touches; no touch is allowed.
Parameters (~): goal_x, goal_y [m], duration [s sim], wall_timeout [s wall].
"""
import math
import threading
import time
import unittest

import rosgraph
import rospy
import rostest
from nav_msgs.msg import Odometry
from std_srvs.srv import Empty

from pybullet_gazebo.ros.testing import (ContactLog, NodeLog, sim_time, wait_for_message,
                                         wait_until)

TOLERANCE = 0.3             # [m]


class Bug2Test(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_bug2")
        cls.goal = (rospy.get_param("~goal_x"), rospy.get_param("~goal_y"))
        cls.duration = rospy.get_param("~duration", 200.0)
        wall_timeout = rospy.get_param("~wall_timeout", 150.0)
        cls.lock = threading.Lock()
        cls.poses = []
        cls.contacts = ContactLog()
        cls.log = NodeLog("/bug2")
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=100)
        # the world starts paused (bug2.xml) until every controller is up, so that every run
        # starts the same way (bug 2 places the robot at its first /odom)
        for name in ("/go_to_point_switch", "/wall_follower_switch", "/gazebo/unpause_physics"):
            rospy.wait_for_service(name, timeout=60)
        master = rosgraph.Master("/test_bug2")
        wait_until(lambda: any(topic == "/odom" and "/bug2" in nodes
                               for topic, nodes in master.getSystemState()[1]),
                   60, "/bug2's subscription to /odom", interval=0.1)
        time.sleep(1.0)                                 # the publishers' connections are made
        rospy.ServiceProxy("/gazebo/unpause_physics", Empty)()
        wait_for_message("/odom", Odometry, timeout=60)
        # bug 2's set_model_state, from its parameters: its log line on /rosout was lost
        # once in CI (a connection to its /rosout made twice as it started)
        wait_until(lambda: (rospy.has_param("/bug2/placed_at")
                            or rospy.has_param("/bug2/not_placed")),
                   60, "/bug2's call to set_model_state (param /bug2/placed_at)", interval=0.05)
        cls.placed = rospy.has_param("/bug2/placed_at")
        cls.start = rospy.get_param("/bug2/placed_at", 0.0)

        def goal_reached_or_time_up():
            done = [t for t, text in cls.log.since(cls.start) if text.startswith("goal reached")]
            return done or sim_time() > cls.start + cls.duration
        outcome = wait_until(goal_reached_or_time_up, wall_timeout,
                             "bug 2's 'goal reached' or the end of its %.0f s of sim time"
                             % cls.duration, interval=0.05)
        cls.reached = outcome[0] if isinstance(outcome, list) else None
        if cls.reached is not None:          # the /odom the controller saw may still be queued
            wait_until(lambda: any(t >= cls.reached for t, _, _ in list(cls.poses)), 5.0,
                       "the /odom of the tick that reached the goal", interval=0.05)
        # the odometry of the tick that reached the goal is stamped with that tick's time, and
        # may be in before this node's /clock has got there: keep it in the run
        cls.end = max(sim_time(), cls.reached or 0.0)

    @classmethod
    def on_odom(cls, msg):
        p = msg.pose.pose.position
        with cls.lock:
            cls.poses.append((msg.header.stamp.to_sec(), p.x, p.y))

    def test_reaches_the_goal_without_touching_anything(self):
        with self.lock:
            poses = [p for p in self.poses if self.start <= p[0] <= self.end]
        nearest = min(math.hypot(x - self.goal[0], y - self.goal[1]) for _, x, y in poses)
        path = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(poses, poses[1:]))
        states = [text for t, text in self.log.since(self.start) if text.startswith("state:")]
        touches = [t for t in self.contacts.touches if self.start <= t[0] <= self.end]
        events = self.contacts.contact_events(self.start, self.end)
        summary = ("goal (%.1f, %.1f): nearest %.3f m, %s, path %.1f m, %d state changes, "
                   "%d contact event(s) %s" % (
                       self.goal[0], self.goal[1], nearest,
                       "reached after %.1f s of sim time" % (self.reached - self.start)
                       if self.reached is not None else "not reached in %.0f s" % self.duration,
                       path, len(states), len(events), events[:3]))
        rospy.loginfo(summary)
        print("FIGURES " + summary)
        self.assertTrue(self.placed, "the controller's set_model_state failed")
        self.assertIsNotNone(self.reached, summary)
        self.assertLess(nearest, TOLERANCE)
        self.assertEqual(touches, [], summary)


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "bug2", Bug2Test)
