#!/usr/bin/env python3
"""rostest: learned_avoidance.py with the shipped policy drives m2wr in world02 without
touching anything.

Watches, from the robot's first /odom:
  /odom (nav_msgs/Odometry)            path length
  /gazebo/contacts (ContactsState)     latched; any message with states = a touch
Parameters (~): duration [s sim] (60), min_distance [m] (10.0), wall_timeout [s wall] (100)
"""
import math
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry

from pybullet_gazebo.ros.testing import ContactLog, wait_for_message, wait_until_sim_time


class LearnedAvoidanceTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_learned_avoidance")
        cls.duration = rospy.get_param("~duration", 60.0)
        cls.min_distance = rospy.get_param("~min_distance", 10.0)
        cls.lock = threading.Lock()
        cls.poses = []
        cls.contacts = ContactLog()
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=100)
        first = wait_for_message("/odom", Odometry, timeout=60)
        cls.start = first.header.stamp.to_sec()
        cls.end = wait_until_sim_time(cls.start + cls.duration,
                                      timeout=rospy.get_param("~wall_timeout", 100.0))

    @classmethod
    def on_odom(cls, msg):
        p = msg.pose.pose.position
        with cls.lock:
            cls.poses.append((msg.header.stamp.to_sec(), p.x, p.y))

    def test_drives_far_enough(self):
        with self.lock:
            poses = [p for p in self.poses if self.start <= p[0] <= self.end]
        path = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(poses, poses[1:]))
        self.assertGreaterEqual(path, self.min_distance,
                                "m2wr drove %.2f m in %.0f s from (%.2f, %.2f) to (%.2f, %.2f)"
                                % (path, self.end - self.start, poses[0][1], poses[0][2],
                                   poses[-1][1], poses[-1][2]))

    def test_never_touches_an_obstacle(self):
        touches = [(t, what) for t, what in self.contacts.touches if t <= self.end]
        self.assertEqual(touches, [], "touches (sim time, models): %s" % touches[:3])


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "learned_avoidance", LearnedAvoidanceTest)
