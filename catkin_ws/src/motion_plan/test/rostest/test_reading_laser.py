#!/usr/bin/env python3
"""rostest: the tutorial's reading_laser.py (episode 4), run unchanged, prints the five
regions of m2wr's scan that the geometry of worlds/five_regions.world predicts.

The program logs `[right, fright, front, fleft, left]` once per scan; this node reads those
lines from /rosout (node /reading_laser). The expected values are worked out here from the
robot's actual pose (/gazebo/get_model_state): each beam of the tutorial's slices is cast in
2-D from the laser, 0.15 m ahead of the chassis frame, against the fixture's boxes, and a
region is min(min(slice), 10) as the tutorial computes it. A region that sees nothing prints
the integer 10 (the ranges are +inf there), exactly as the tutorial's output shows.
Parameters: none. Topics in: /rosout, /m2wr/laser/scan (for its angles).
"""
import math
import re
import unittest

import rospy
import rostest
from sensor_msgs.msg import LaserScan

from pybullet_gazebo.ros.testing import NodeLog, model_pose, wait_for_message, wait_until_sim_time

SENSOR_AHEAD = 0.15          # [m] joint of sensor_laser on link_chassis
TOLERANCE = 0.05             # [m] Gaussian noise stddev 0.01; a region is a min of ~140 beams
REGIONS = [("right", 0, 143), ("fright", 144, 287), ("front", 288, 431),
           ("fleft", 432, 575), ("left", 576, 713)]     # the tutorial's slices
# The fixture's boxes as (x_min, x_max, y_min, y_max) [m], from worlds/five_regions.world.
BOXES = {
    "right_wall": (-1.0, 0.5, -1.0, -0.8),
    "front_wall": (2.0, 2.2, -0.4, 0.4),
    "fleft_post": (1.21, 1.51, 0.73, 1.03),
}
OPEN = math.inf
LINES = 10                   # log lines checked
NUMBER = r"(?:10|\d+\.\d+(?:e-?\d+)?)"
LOG_LINE = re.compile(r"^\[%s(?:, %s){4}\]$" % (NUMBER, NUMBER))


def ray_box_distance(ox, oy, heading, box):
    """Distance [m] from (ox, oy) along `heading` [rad] to an axis-aligned box, +inf if the
    ray misses it (slab method)."""
    dx, dy = math.cos(heading), math.sin(heading)
    near, far = 0.0, math.inf
    for origin, direction, low, high in ((ox, dx, box[0], box[1]), (oy, dy, box[2], box[3])):
        if abs(direction) < 1e-12:
            if not low <= origin <= high:
                return math.inf
            continue
        t1, t2 = (low - origin) / direction, (high - origin) / direction
        near, far = max(near, min(t1, t2)), min(far, max(t1, t2))
    return near if near <= far else math.inf


class ReadingLaserTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_reading_laser")
        cls.log = NodeLog("/reading_laser")
        scan = wait_for_message("/m2wr/laser/scan", LaserScan, timeout=60)
        cls.angle_min, cls.angle_increment = scan.angle_min, scan.angle_increment
        cls.range_max = scan.range_max
        settled = wait_until_sim_time(scan.header.stamp.to_sec() + 2.0, timeout=30)  # dropped from z 0.5
        cls.pose = model_pose("m2wr")
        cls.lines = [text for _, text in cls.log.wait_for(LINES, since=settled, timeout=30)][:LINES]
        cls.pose_after = model_pose("m2wr")
        cls.expected = cls.expected_regions(*cls.pose)
        rospy.loginfo("robot at %s; expected %s; first line %s", cls.pose, cls.expected, cls.lines[0])

    @classmethod
    def expected_regions(cls, x, y, yaw):
        sx, sy = x + SENSOR_AHEAD * math.cos(yaw), y + SENSOR_AHEAD * math.sin(yaw)
        regions = []
        for _, first, end in REGIONS:
            nearest = OPEN
            for index in range(first, end):
                heading = yaw + cls.angle_min + index * cls.angle_increment
                hit = min(ray_box_distance(sx, sy, heading, box) for box in BOXES.values())
                if hit <= cls.range_max:
                    nearest = min(nearest, hit)
            regions.append(nearest)
        return regions

    def tokens(self, line):
        self.assertRegex(line, LOG_LINE, "reading_laser.py's line is not a list of 5 numbers")
        return line[1:-1].split(", ")

    def test_robot_stands_still_facing_plus_x(self):
        x, y, yaw = self.pose
        self.assertAlmostEqual(x, 0.0, delta=0.05)
        self.assertAlmostEqual(y, 0.0, delta=0.05)
        self.assertAlmostEqual(yaw, 0.0, delta=0.03)
        self.assertLess(math.hypot(self.pose_after[0] - x, self.pose_after[1] - y), 0.01)

    def test_fixture_gives_open_and_walled_regions(self):
        # the design of five_regions.world: fright and left open, the others walled
        self.assertEqual([e == OPEN for e in self.expected], [False, True, False, False, True])
        self.assertAlmostEqual(self.expected[0], 0.80, delta=0.01)
        self.assertAlmostEqual(self.expected[2], 1.85, delta=0.01)
        self.assertAlmostEqual(self.expected[3], 1.29, delta=0.02)

    def test_open_regions_print_the_integer_10(self):
        for line in self.lines:
            for (name, _, _), token, expected in zip(REGIONS, self.tokens(line), self.expected):
                if expected == OPEN:
                    self.assertEqual(token, "10", "region %s in %r" % (name, line))

    def test_walled_regions_print_the_distance_to_the_wall(self):
        for line in self.lines:
            for (name, _, _), token, expected in zip(REGIONS, self.tokens(line), self.expected):
                if expected != OPEN:
                    self.assertNotEqual(token, "10", "region %s in %r" % (name, line))
                    self.assertAlmostEqual(float(token), expected, delta=TOLERANCE,
                                           msg="region %s in %r: expected %.3f m"
                                           % (name, line, expected))

    def test_prints_one_line_per_scan(self):
        start = self.log.since(0.0)[-1][0]
        wait_until_sim_time(start + 1.5, timeout=30)      # the last lines of the second arrived
        lines = [t for t, _ in self.log.since(start + 1e-6) if t <= start + 1.0 + 1e-6]
        self.assertAlmostEqual(len(lines), 20, delta=1, msg="lines in 1 s of sim time (20 Hz scan)")


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "reading_laser", ReadingLaserTest)
