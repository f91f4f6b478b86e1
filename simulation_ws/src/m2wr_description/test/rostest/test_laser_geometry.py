#!/usr/bin/env python3
"""rostest: m2wr's laser in wall_ahead.world reports the wall where geometry puts it.

The robot is spawned at the origin facing +x; its laser sits 0.15 m ahead of the chassis
frame, and the wall's face is the plane x = 2.15 m for |y| <= 3 m. A beam at world heading phi
from the sensor at (sx, sy) meets that plane at (2.15 - sx) / cos(phi) when the hit point lies
on the wall, and sees nothing (+inf, REP 117) otherwise."""
import collections
import math
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from pybullet_gazebo.ros.testing import model_pose, wait_for_message, wait_until_sim_time

WALL_X = 2.15            # [m] the wall's face
WALL_HALF_WIDTH = 3.0    # [m]
SENSOR_AHEAD = 0.15      # [m] joint of sensor_laser on link_chassis
TOLERANCE = 0.04         # [m] the sensor's Gaussian noise has stddev 0.01


class LaserGeometryTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_laser_geometry")
        wait_for_message("/m2wr/laser/scan", LaserScan, timeout=30)
        wait_until_sim_time(rospy.get_time() + 2.0)          # dropped from z 0.5, settled
        cls.scan = wait_for_message("/m2wr/laser/scan", LaserScan)
        cls.x, cls.y, cls.yaw = model_pose("m2wr")

    def expected_range(self, index):
        sx = self.x + SENSOR_AHEAD * math.cos(self.yaw)
        sy = self.y + SENSOR_AHEAD * math.sin(self.yaw)
        phi = self.yaw + self.scan.angle_min + index * self.scan.angle_increment
        if math.cos(phi) <= 1e-9:
            return math.inf
        distance = (WALL_X - sx) / math.cos(phi)
        hit_y = sy + distance * math.sin(phi)
        if abs(hit_y) > WALL_HALF_WIDTH or distance > self.scan.range_max:
            return math.inf
        return distance

    def test_metadata(self):
        scan = self.scan
        self.assertEqual(len(scan.ranges), 720)
        self.assertEqual(scan.header.frame_id, "sensor_laser")
        self.assertAlmostEqual(scan.angle_min, -1.570796, places=5)
        self.assertAlmostEqual(scan.angle_max, 1.570796, places=5)
        self.assertAlmostEqual(scan.angle_increment, 2 * 1.570796 / 719, places=7)
        self.assertAlmostEqual(scan.range_min, 0.10, places=5)
        self.assertAlmostEqual(scan.range_max, 10.0, places=5)
        self.assertAlmostEqual(scan.scan_time, 0.05, places=6)
        self.assertGreater(scan.header.stamp.to_sec(), 0.0)

    def test_robot_stands_where_spawned(self):
        self.assertAlmostEqual(self.x, 0.0, delta=0.05)
        self.assertAlmostEqual(self.y, 0.0, delta=0.05)
        self.assertAlmostEqual(self.yaw, 0.0, delta=0.02)

    def test_clock_ticks_every_10_ms_of_sim_time(self):
        """/clock at pub_clock_frequency 100 Hz, in sim time, as Gazebo sends it. Not rostest's
        hztest: in a node with /use_sim_time, rospy's own /clock subscriber has queue_size 1
        and any other /clock subscriber of the node shares its connection, so ticks that
        arrive together (a busy machine) are dropped but the last, and a count of them
        measures the machine. The spacing of the ticks that do arrive measures the simulator:
        each a whole number of 10 ms after the last, and 10 ms the usual one."""
        stamps = []
        subscriber = rospy.Subscriber("/clock", Clock, lambda m: stamps.append(m.clock.to_sec()))
        try:
            wait_until_sim_time(rospy.get_time() + 5.0)
        finally:
            subscriber.unregister()
        gaps = [b - a for a, b in zip(stamps, stamps[1:])]
        self.assertGreater(len(gaps), 100, "too few /clock ticks in 5 s of sim time")
        in_periods = [gap / 0.01 for gap in gaps]
        odd = [g for g in in_periods if g < 0.95 or abs(g - round(g)) > 0.05]
        self.assertFalse(odd, "/clock gaps that are not whole 10-ms periods: %s" % odd[:10])
        usual, _ = collections.Counter(round(g) for g in in_periods).most_common(1)[0]
        self.assertEqual(usual, 1, "the usual /clock gap is %d0 ms, not 10 ms" % usual)

    def test_every_beam_matches_the_wall_geometry(self):
        hits = open_beams = 0
        for index, measured in enumerate(self.scan.ranges):
            expected = self.expected_range(index)
            if math.isinf(expected):
                # skip the two beams that graze the wall's edge within a noise width
                self.assertTrue(math.isinf(measured) or abs(measured - 3.6) < 0.2,
                                "beam %d: expected +inf, got %r" % (index, measured))
                open_beams += measured == math.inf
            else:
                self.assertAlmostEqual(measured, expected, delta=TOLERANCE,
                                       msg="beam %d: %r vs %r m" % (index, measured, expected))
                hits += 1
        # atan(3 / 2) = 56.3 deg either side of straight ahead hits the wall: ~450 beams
        self.assertGreater(hits, 430)
        self.assertGreater(open_beams, 250)
        self.assertAlmostEqual(min(self.scan.ranges), 2.0, delta=TOLERANCE + 0.02)


if __name__ == "__main__":
    rostest.rosrun("m2wr_description", "laser_geometry", LaserGeometryTest)
