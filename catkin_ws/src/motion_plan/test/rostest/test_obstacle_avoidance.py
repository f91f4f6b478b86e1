#!/usr/bin/env python3
"""rostest: the tutorial's obstacle_avoidance.py (episode 5), run unchanged as node
/reading_laser, drives m2wr around a world for a while without touching anything.

Watches, from the moment the robot's first /odom arrives:
  /odom (nav_msgs/Odometry)            path length, the pose at every touch
  /rosout (rosgraph_msgs/Log)          the program's "case N - ..." lines
  /gazebo/contacts (ContactsState)     latched; any message with states = a touch
Parameters (~):
  duration      [s sim]   how long to watch (120)
  min_distance  [m]       path length the robot must cover (10.0)
  min_cases     [-]       distinct cases of the eight it must pass through (3)
  start_x, start_y, start_yaw  [m, m, rad]  where the launch spawned it (checked, 0.1 m / 0.05 rad)
  wall_timeout  [s wall]  give up waiting for `duration` of sim time after this (100)
"""
import math
import re
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry

from pybullet_gazebo.ros.testing import (ContactLog, NodeLog, unwrap_angle, wait_for_message,
                                         wait_until_sim_time, yaw_of)

CASE_LINE = re.compile(r"case (\d) - ")


def path_length(poses):
    """[m] the polyline through the (t, x, y, yaw) poses."""
    return sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(poses, poses[1:]))


class ObstacleAvoidanceTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_obstacle_avoidance")
        cls.duration = rospy.get_param("~duration", 120.0)
        cls.min_distance = rospy.get_param("~min_distance", 10.0)
        cls.min_cases = rospy.get_param("~min_cases", 3)
        cls.start_pose = (rospy.get_param("~start_x", 0.0), rospy.get_param("~start_y", 0.0),
                          rospy.get_param("~start_yaw", 0.0))
        wall_timeout = rospy.get_param("~wall_timeout", 100.0)

        cls.lock = threading.Lock()
        cls.poses = []                                   # (sim time [s], x [m], y [m], yaw [rad])
        cls.program_log = NodeLog("/reading_laser")
        cls.contacts = ContactLog()
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=100)
        first = wait_for_message("/odom", Odometry, timeout=60)
        cls.start = first.header.stamp.to_sec()
        cls.end = wait_until_sim_time(cls.start + cls.duration, timeout=wall_timeout)
        rospy.loginfo("watched %.1f s of sim time: %s", cls.end - cls.start, cls.summary())

    @classmethod
    def summary(cls):
        with cls.lock:
            poses = [pose for pose in cls.poses if cls.start <= pose[0] <= cls.end]
        path = path_length(poses)
        counts = {}
        for t, text in cls.program_log.since(cls.start):
            m = CASE_LINE.match(text) if t <= cls.end else None
            if m:
                counts[int(m.group(1))] = counts.get(int(m.group(1)), 0) + 1
        return ("path %.2f m, from (%.2f, %.2f) to (%.2f, %.2f); case lines %s; touches %s"
                % (path, poses[0][1], poses[0][2], poses[-1][1], poses[-1][2],
                   dict(sorted(counts.items())), cls.contacts.touches[:3]))

    @classmethod
    def on_odom(cls, msg):
        p = msg.pose.pose.position
        with cls.lock:
            cls.poses.append((msg.header.stamp.to_sec(), p.x, p.y, yaw_of(msg.pose.pose.orientation)))

    def pose_at(self, t):
        """The last /odom pose stamped at or before sim time t."""
        with self.lock:
            before = [pose for pose in self.poses if pose[0] <= t] or self.poses[:1]
        return before[-1]

    def watched_poses(self):
        with self.lock:
            return [pose for pose in self.poses if self.start <= pose[0] <= self.end]

    def test_starts_where_spawned(self):
        _, x, y, yaw = self.watched_poses()[0]
        self.assertAlmostEqual(x, self.start_pose[0], delta=0.1)
        self.assertAlmostEqual(y, self.start_pose[1], delta=0.1)
        self.assertAlmostEqual(unwrap_angle(yaw - self.start_pose[2]), 0.0, delta=0.05)

    def test_travels_far_enough(self):
        poses = self.watched_poses()
        path = path_length(poses)
        self.assertGreaterEqual(
            path, self.min_distance,
            "m2wr drove %.2f m in %.0f s of sim time (from (%.2f, %.2f) to (%.2f, %.2f)); "
            "wanted at least %.1f m" % (path, self.end - self.start, poses[0][1], poses[0][2],
                                        poses[-1][1], poses[-1][2], self.min_distance))

    def test_passes_through_several_cases(self):
        lines = [(t, text) for t, text in self.program_log.since(self.start) if t <= self.end]
        cases = sorted({int(m.group(1)) for m in (CASE_LINE.match(text) for _, text in lines) if m})
        self.assertGreater(len(lines), 0, "obstacle_avoidance.py (node /reading_laser) logged nothing")
        self.assertGreaterEqual(
            len(cases), self.min_cases,
            "obstacle_avoidance.py went through cases %s only (%d lines); wanted %d distinct"
            % (cases, len(lines), self.min_cases))

    def test_never_touches_an_obstacle(self):
        published = dict(rospy.get_published_topics())
        self.assertEqual(published.get("/gazebo/contacts"), "gazebo_msgs/ContactsState",
                         "the simulator does not publish /gazebo/contacts: cannot see touches")
        touches = [(t, what) for t, what in self.contacts.touches if t <= self.end]
        if touches:
            t, what = touches[0]
            _, x, y, yaw = self.pose_at(t)
            self.fail("%d touch(es); the first at sim time %.2f s (%.2f s after the start): %s, "
                      "robot at x %.2f m, y %.2f m, yaw %.2f rad"
                      % (len(touches), t, t - self.start, ", ".join(what), x, y, yaw))


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "obstacle_avoidance", ObstacleAvoidanceTest)
