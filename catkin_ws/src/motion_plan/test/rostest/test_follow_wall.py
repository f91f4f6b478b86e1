#!/usr/bin/env python3
"""rostest: the project's wall follower (nodes/standin_follow_wall.py) goes round world02's
yard keeping the wall on its right at 0.3-1.05 m, as episode 7 of the series shows.

The test switches the follower on (/wall_follower_switch) and watches, for `duration` s of
sim time: /m2wr/laser/scan (the nearest range from -90 to +15 deg: the distance from the wall
on the right as the robot sees it; and the nearest range of all), /odom (the heading turned in all, and the path) and /gazebo/contacts. Once the
wall is found (that range first under max_wall - FOUND_MARGIN), it must stay in [min_wall, max_wall] and
nothing may come nearer than min_wall, the robot must turn at least `loops` full turns in `direction`
(counter-clockwise: round the inside of a yard with its wall on the right), and touch nothing. It prints those figures.
Parameters (~): duration [s sim], min_wall, max_wall [m], loops, direction
(counter-clockwise | clockwise), wall_timeout [s wall].
"""
import math
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_srvs.srv import SetBool

from pybullet_gazebo.ros.testing import (ContactLog, NodeLog, service, sim_time,
                                         wait_for_message, wait_until_sim_time, yaw_of)


RIGHT_UP_TO = math.radians(15.0)
# m2wr's laser has gaussian noise (stddev 0.01 m): "found" is taken this far inside the band, so
# that a noisy scan just after it cannot fall outside while the robot still closes in
FOUND_MARGIN = 0.1          # [m]
DIRECTIONS = {1: "counter-clockwise", -1: "clockwise"}


class FollowWallTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_follow_wall")
        cls.duration = rospy.get_param("~duration", 150.0)
        cls.min_wall = rospy.get_param("~min_wall", 0.3)
        cls.max_wall = rospy.get_param("~max_wall", 1.0)
        cls.loops = rospy.get_param("~loops", 1.0)
        # inside a walled yard with the wall on the right, the robot turns left at each corner
        cls.direction = {v: k for k, v in DIRECTIONS.items()}[
            rospy.get_param("~direction", "counter-clockwise")]
        wall_timeout = rospy.get_param("~wall_timeout", 120.0)
        cls.lock = threading.Lock()
        cls.nearest = []                     # (sim time, nearest range [m])
        cls.poses = []                       # (sim time, x, y, yaw)
        cls.contacts = ContactLog()
        cls.simulator_log = NodeLog("/gazebo")      # its lockstep warnings explain a failure
        rospy.Subscriber("/m2wr/laser/scan", LaserScan, cls.on_scan, queue_size=100)
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=100)
        wait_for_message("/odom", Odometry, timeout=60)
        service("/wall_follower_switch", SetBool, timeout=30)(True)
        cls.start = sim_time()
        wait_until_sim_time(cls.start + cls.duration, timeout=wall_timeout)
        cls.end = sim_time()

    @classmethod
    def on_scan(cls, msg):
        # the wall on the right: beams from -90 deg to +15 deg (the front's right part too, a
        # wall met at a corner); and the nearest thing anywhere
        right = [r for i, r in enumerate(msg.ranges)
                 if math.isfinite(r) and msg.angle_min + i * msg.angle_increment <= RIGHT_UP_TO]
        every = [r for r in msg.ranges if math.isfinite(r)]
        with cls.lock:
            cls.nearest.append((msg.header.stamp.to_sec(), min(right, default=math.inf),
                                min(every, default=math.inf)))

    @classmethod
    def on_odom(cls, msg):
        p = msg.pose.pose.position
        with cls.lock:
            cls.poses.append((msg.header.stamp.to_sec(), p.x, p.y, yaw_of(msg.pose.pose.orientation)))

    def test_goes_round_the_wall_keeping_its_distance(self):
        with self.lock:
            nearest = [(t, r, a) for t, r, a in self.nearest if self.start <= t <= self.end]
            poses = [p for p in self.poses if self.start <= p[0] <= self.end]
        found = next((i for i, (_, r, _) in enumerate(nearest)
                      if r < self.max_wall - FOUND_MARGIN), None)
        self.assertIsNotNone(found, "the follower never came within %.2f m of a wall"
                             % (self.max_wall - FOUND_MARGIN))
        following = [r for _, r, _ in nearest[found:]]
        closest = min(a for _, _, a in nearest[found:])
        turned = sum(math.remainder(b[3] - a[3], math.tau) for a, b in zip(poses, poses[1:]))
        path = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(poses, poses[1:]))
        touches = [t for t in self.contacts.touches if self.start <= t[0] <= self.end]
        outside = [(round(t - self.start, 2), round(r, 3), round(a, 3))
                   for t, r, a in nearest[found:]
                   if not (self.min_wall <= r <= self.max_wall and a >= self.min_wall)]
        summary = ("wall found at %.1f s; wall on the right at %.3f..%.3f m over %d scans, "
                   "nearest anything %.3f m (%d scans outside %.2f..%.2f m); turned %.2f turns; "
                   "path %.1f m; %d contact event(s)" % (
                       nearest[found][0] - self.start, min(following), max(following),
                       len(following), closest, len(outside),
                                          self.min_wall, self.max_wall, turned / math.tau, path,
                                          len(self.contacts.contact_events(
                                              self.start, self.end))))
        rospy.loginfo(summary)
        print("FIGURES " + summary)
        warnings = [(round(t - self.start, 2), text) for t, text in self.simulator_log.entries
                    if "lockstep" in text]
        self.assertEqual(outside[:10], [], "the simulator's lockstep warnings: %s"
                         % (warnings[:5],))
        self.assertGreaterEqual(turned * self.direction, self.loops * math.tau,
                                "not round the wall %s" % DIRECTIONS[self.direction])
        self.assertEqual(touches, [], "the simulator's lockstep warnings: %s" % (warnings[:5],))


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "follow_wall", FollowWallTest)
