#!/usr/bin/env python3
"""rostest: the tutorial's launch files, verbatim, run on the stand-in (tutorial_launch_files.test).

episode 5's launch_world.launch loads world01 (16 jersey barriers and 7 construction barrels
round a 19 x 19 m yard, per the reference layout); the series' spawn.launch puts m2wr at
(0, 0) facing +x; the tutorial's obstacle_avoidance.py (node /reading_laser) drives it.

Checks what the learner would see:
  /gazebo/get_world_properties   the world's models, and m2wr
  /m2wr/laser/scan               the beams to the right (-90 deg), ahead and to the left
                                 (+90 deg) end on the south, east and north walls where the
                                 layout puts them, seen from the robot's /odom pose, while
                                 it drives east
  /odom, /gazebo/contacts        over ~duration [s sim] (40): the robot drives east, >= 7 m
                                 of path, and touches nothing
Parameters: ~duration [s sim] (40), ~wall_timeout [s wall] (90).
"""
import math
import threading
import unittest

import rospy
import rostest
from gazebo_msgs.srv import GetWorldProperties
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from pybullet_gazebo.ros.testing import (ContactLog, NodeLog, service, wait_for_message,
                                         wait_until_sim_time, yaw_of)

# The perimeter of world01 (reference: tutorial_worlds.md), barrier centres [m]. A barrier is
# 4.06542 m long; at the laser's height (~0.15 m) its base is 0.5 .. 0.65 m thick.
BARRIER_LENGTH = 4.06542                              # [m]
HALF_THICKNESS = (0.25, 0.325)                        # [m] at scan height, least and most
ALONG_X = [(-5.66, 9.46), (-1.66, 9.36), (2.40, 9.29), (6.45, 9.34),      # north wall
           (6.71, -9.54), (2.60, -9.51), (-1.33, -9.51), (-5.45, -9.50)]  # south wall
ALONG_Y = [(9.45, 5.36), (9.37, 1.33), (9.43, -2.63), (9.45, -6.53),      # east wall
           (-9.54, -6.33), (-9.62, -2.35), (-9.59, 1.70), (-9.45, 5.84)]  # west wall
SENSOR_AHEAD = 0.15          # [m] laser ahead of link_chassis
NOISE = 0.06                 # [m] 3 sigma of the laser's noise (0.01 m) plus pose error
MIN_PATH = 7.0               # [m] the robot drives east along y = 0 for ~8 m before turning


def boxes(half_thickness):
    """The perimeter barriers as (xmin, xmax, ymin, ymax) rectangles [m]."""
    half = BARRIER_LENGTH / 2
    return ([(x - half, x + half, y - half_thickness, y + half_thickness) for x, y in ALONG_X]
            + [(x - half_thickness, x + half_thickness, y - half, y + half) for x, y in ALONG_Y])


def ray_to_boxes(ox, oy, heading, rects):
    """[m] distance from (ox, oy) along `heading` to the nearest rectangle, or inf (slab test)."""
    dx, dy = math.cos(heading), math.sin(heading)
    nearest = math.inf
    for xmin, xmax, ymin, ymax in rects:
        t_near, t_far = 0.0, math.inf
        for o, d, lo, hi in ((ox, dx, xmin, xmax), (oy, dy, ymin, ymax)):
            if abs(d) < 1e-12:
                if not lo <= o <= hi:
                    break
                continue
            a, b = sorted(((lo - o) / d, (hi - o) / d))
            t_near, t_far = max(t_near, a), min(t_far, b)
        else:
            if t_near <= t_far:
                nearest = min(nearest, t_near)
    return nearest


class TutorialLaunchFilesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_tutorial_launch_files")
        duration = rospy.get_param("~duration", 40.0)
        wall_timeout = rospy.get_param("~wall_timeout", 90.0)
        cls.lock = threading.Lock()
        cls.poses = []                               # (sim time [s], x [m], y [m], yaw [rad])
        cls.scans = []                               # every LaserScan received
        cls.program_log = NodeLog("/reading_laser")
        cls.contacts = ContactLog()
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=200)
        rospy.Subscriber("/m2wr/laser/scan", LaserScan, cls.on_scan, queue_size=200)
        cls.start = wait_for_message("/odom", Odometry, timeout=60).header.stamp.to_sec()
        cls.end = wait_until_sim_time(cls.start + duration, timeout=wall_timeout)

    @classmethod
    def on_odom(cls, msg):
        p = msg.pose.pose.position
        with cls.lock:
            cls.poses.append((msg.header.stamp.to_sec(), p.x, p.y, yaw_of(msg.pose.pose.orientation)))

    @classmethod
    def on_scan(cls, msg):
        with cls.lock:
            cls.scans.append(msg)

    def pose_at(self, t):
        """The /odom pose stamped nearest to sim time t [s]."""
        with self.lock:
            return min(self.poses, key=lambda pose: abs(pose[0] - t))

    def test_world_has_world01_models_and_m2wr(self):
        answer = service("/gazebo/get_world_properties", GetWorldProperties)()
        self.assertTrue(answer.success, answer.status_message)
        names = list(answer.model_names)
        barriers = [n for n in names if n.startswith("jersey_barrier")]
        barrels = [n for n in names if n.startswith("construction_barrel")]
        self.assertEqual((len(barriers), len(barrels)), (16, 7),
                         "world01 has 16 barriers and 7 barrels; got %s" % names)
        self.assertIn("ground_plane", names)
        self.assertIn("m2wr", names)

    def test_scan_ends_on_the_walls(self):
        # scans from the straight run east, from 1 s after m2wr began to move (as it starts,
        # it pitches up to 8 deg, and a beam level with it then passes over a 0.8 m barrier
        # 8 m away, as in Gazebo) until 6 s later, before the first turn. roslaunch starts the
        # program beside the spawn, so when it begins to drive depends on the machine.
        with self.lock:
            moving = [p[0] for p in self.poses if p[0] >= self.start and abs(p[1]) > 0.05]
            self.assertTrue(moving, "m2wr never moved from (0, 0)")
            scans = [s for s in self.scans if moving[0] + 1.0 <= s.header.stamp.to_sec()
                     <= moving[0] + 6.0]
        self.assertTrue(scans, "no /m2wr/laser/scan 1 to 6 s of sim time after m2wr began to "
                        "move (at %.2f s)" % moving[0])
        checked = 0
        for scan in scans[::10]:
            t, x, y, yaw = self.pose_at(scan.header.stamp.to_sec())
            lx, ly = x + SENSOR_AHEAD * math.cos(yaw), y + SENSOR_AHEAD * math.sin(yaw)
            for index in (0, len(scan.ranges) // 2, len(scan.ranges) - 1):
                heading = yaw + scan.angle_min + index * scan.angle_increment
                far = ray_to_boxes(lx, ly, heading, boxes(HALF_THICKNESS[0]))
                near = ray_to_boxes(lx, ly, heading, boxes(HALF_THICKNESS[1]))
                measured = scan.ranges[index]
                self.assertTrue(
                    near - NOISE <= measured <= far + NOISE,
                    "beam %d (%.0f deg) at sim time %.2f s from (%.2f, %.2f, yaw %.2f): %.3f m; "
                    "the layout puts a wall %.3f .. %.3f m away"
                    % (index, math.degrees(heading - yaw), t, x, y, yaw, measured, near, far))
                checked += 1
        self.assertGreaterEqual(checked, 3)

    def test_obstacle_avoidance_drives_without_touching(self):
        with self.lock:
            poses = [p for p in self.poses if self.start <= p[0] <= self.end]
        path = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(poses, poses[1:]))
        lines = self.program_log.since(self.start)
        self.assertTrue(lines, "obstacle_avoidance.py (node /reading_laser) logged nothing")
        self.assertGreaterEqual(
            path, MIN_PATH, "m2wr drove %.2f m in %.0f s of sim time, from (%.2f, %.2f) to "
            "(%.2f, %.2f)" % (path, self.end - self.start, poses[0][1], poses[0][2],
                              poses[-1][1], poses[-1][2]))
        self.assertGreater(max(p[1] for p in poses), 6.0, "m2wr never drove east past x = 6 m")
        touches = [touch for touch in self.contacts.touches if touch[0] <= self.end]
        self.assertEqual(touches, [], "m2wr touched something: %s" % touches[:3])
        rospy.loginfo("path %.2f m in %.0f s of sim time, from (%.2f, %.2f) to (%.2f, %.2f)",
                      path, self.end - self.start, poses[0][1], poses[0][2], poses[-1][1],
                      poses[-1][2])


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "tutorial_launch_files", TutorialLaunchFilesTest)
