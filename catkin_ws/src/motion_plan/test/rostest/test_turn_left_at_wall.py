#!/usr/bin/env python3
"""rostest: facing a wall, the tutorial's obstacle_avoidance.py turns m2wr LEFT, and the robot
clears the wall. Fixture worlds/wall_ahead_2p5.world: the wall's face is x = 2.5 m for
y -4 .. 4; m2wr starts at the origin heading ~start_yaw (0.1 rad in turn_left_at_wall.test)
left of +x, the wall's normal.

Head-on (yaw 0) the test would judge the laser noise, not the program: the robot runs on a few
cm past the 1 m mark, the fleft and fright regions (nearest points 18 deg either side of the
heading) both fall under 1 m, and the noise picks which falls first (some runs turned
right). At 0.1 rad, fright's nearest point is 1.024 d away and fleft's 1.092 d (d the
laser's distance to the wall), so the geometry picks fright, and the program must turn left.

The tutorial's program answers "case 2 - front" (and cases 3, 5, 7, 8) with angular.z = -0.3
and says the robot turns left: on m2wr, whose joint named "right" is on its left, a negative
angular.z turns it counter-clockwise under gazebo_ros_diff_drive. A stand-in that turned it
the other way would send it into oscillation or into the wall; this test catches that.

Watches /odom (yaw unwrapped, speed), /rosout lines of node /reading_laser ("case N - ...")
and the latched /gazebo/contacts, for ~duration [s sim] (25) from the first /odom;
~wall_timeout [s wall] (60); ~start_yaw [rad] is the heading the launch spawned m2wr at.
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

WALL_X = 2.5                 # [m] the wall's face
SENSOR_AHEAD = 0.15          # [m] laser ahead of the chassis frame
THRESHOLD = 1.0              # [m] the program's "something there" distance
CASE_LINE = re.compile(r"case (\d) - ")


class TurnLeftAtWallTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_turn_left_at_wall")
        duration = rospy.get_param("~duration", 25.0)
        wall_timeout = rospy.get_param("~wall_timeout", 60.0)
        cls.start_yaw = rospy.get_param("~start_yaw")
        cls.lock = threading.Lock()
        cls.received = []              # (sim time [s], x [m], y [m], unwrapped yaw [rad], v [m/s])
        cls.program_log = NodeLog("/reading_laser")
        cls.contacts = ContactLog()
        rospy.Subscriber("/odom", Odometry, cls.on_odom, queue_size=100)
        cls.start = wait_for_message("/odom", Odometry, timeout=60).header.stamp.to_sec()
        cls.end = wait_until_sim_time(cls.start + duration, timeout=wall_timeout)
        with cls.lock:                 # what the tests judge: the watched interval only
            cls.odom = [o for o in cls.received if cls.start <= o[0] <= cls.end]
        cls.cases = [(t, int(m.group(1))) for t, m in
                     ((t, CASE_LINE.match(text)) for t, text in cls.program_log.since(cls.start))
                     if m and t <= cls.end]
        rospy.loginfo("cases (start s, case): %s; odom every 1 s: %s", cls.case_runs(40),
                      [tuple(round(v, 2) for v in o) for o in cls.odom[::20]])

    @classmethod
    def on_odom(cls, msg):
        p = msg.pose.pose.position
        yaw = yaw_of(msg.pose.pose.orientation)
        with cls.lock:
            if cls.received:                               # unwrap against the previous yaw
                yaw = cls.received[-1][3] + unwrap_angle(yaw - cls.received[-1][3])
            cls.received.append((msg.header.stamp.to_sec(), p.x, p.y, yaw, msg.twist.twist.linear.x))

    @classmethod
    def case_runs(cls, limit=12):
        """"(sim time [s], case) ..." for the first `limit` runs of equal cases, for messages."""
        runs = []
        for t, case in cls.cases:
            if not runs or runs[-1][1] != case:
                runs.append((round(t, 2), case))
        more = " and %d more runs" % (len(runs) - limit) if len(runs) > limit else ""
        return "%s%s" % (runs[:limit], more)

    def odom_at(self, t):
        before = [o for o in self.odom if o[0] <= t]
        return before[-1] if before else self.odom[0]

    def wall_seen(self):
        """Sim time [s] and case of the first line that is not case 1."""
        seen = next(((t, case) for t, case in self.cases if case != 1), None)
        self.assertIsNotNone(seen, "the robot never left case 1: did it not reach the wall? "
                                   "runs %s" % self.case_runs())
        return seen

    def back_in_case_1(self, after):
        """Sim time [s] of the first case 1 line after `after`, or None."""
        return next((t for t, case in self.cases if t > after and case == 1), None)

    def test_1_drives_up_to_the_wall_and_sees_it_in_front(self):
        t0, first = self.wall_seen()
        # front alone, or front and fright (nearer than fleft at ~start_yaw): both turn left
        self.assertIn(first, (2, 5), "first case off the straight run: %s" % self.case_runs())
        _, x, y, yaw, _ = self.odom_at(t0)
        laser_to_wall = WALL_X - (x + SENSOR_AHEAD * math.cos(yaw))
        self.assertAlmostEqual(laser_to_wall, THRESHOLD, delta=0.1,
                               msg="the program should see the wall at 1 m (robot at %.2f, %.2f)"
                               % (x, y))
        self.assertAlmostEqual(yaw, self.start_yaw, delta=0.03,
                               msg="it drove straight up to the wall")

    def test_2_turns_left_at_the_wall(self):
        t0, _ = self.wall_seen()
        t1 = self.back_in_case_1(t0)
        yaws = [o[3] for o in self.odom if t0 <= o[0] <= (t1 or self.end)]
        print("FIGURES turned left by %.1f deg to a heading of %.1f deg from %.2f s to %s s" % (
            math.degrees(yaws[-1] - yaws[0]), math.degrees(yaws[-1]), t0 - self.start,
            "%.2f" % (t1 - self.start) if t1 else "the end"))
        self.assertGreaterEqual(min(yaws), yaws[0] - 0.02,
                                "turned right (clockwise) at the wall: yaw fell from %.3f to "
                                "%.3f rad" % (yaws[0], min(yaws)))
        # the program turns until front and fright are clear, so the heading it leaves the turn
        # on is the geometry's, some 10 deg either side of 45 deg (the controller starts while
        # the world runs, so where its ticks fall differs from run to run): 30 deg is a turn
        self.assertGreater(yaws[-1], math.radians(30),
                           "turned left to a heading of %.1f deg only (by %.1f deg)%s"
                           % (math.degrees(yaws[-1]), math.degrees(yaws[-1] - yaws[0]),
                              "" if t1 else ", and stayed"))
        self.assertIsNotNone(t1, "never back in case 1 after the wall: runs %s" % self.case_runs())
        self.assertGreaterEqual(min(o[3] for o in self.odom), self.start_yaw - 0.05,
                                "the robot turned right (clockwise) at some point")

    def test_3_clears_the_wall_without_touching_it(self):
        published = dict(rospy.get_published_topics())
        self.assertEqual(published.get("/gazebo/contacts"), "gazebo_msgs/ContactsState",
                         "the simulator does not publish /gazebo/contacts (contacts:=true?): "
                         "cannot see touches")
        touches = [touch for touch in self.contacts.touches if touch[0] <= self.end]
        self.assertEqual(touches, [], "the robot touched something")
        t, x, y, yaw, speed = self.odom[-1]
        self.assertEqual(self.cases[-1][1], 1, "not going on in case 1 at the end: runs %s"
                         % self.case_runs())
        self.assertGreater(speed, 0.5, "not moving at the end")
        self.assertLess(math.cos(yaw), 0.1, "still heading into the wall (+x) at the end: "
                        "yaw %.2f rad" % yaw)
        self.assertGreater(y, 4.0, "not past the wall's end (y 4 m) at the end: (%.2f, %.2f)"
                           % (x, y))


if __name__ == "__main__":
    rostest.rosrun("motion_plan", "turn_left_at_wall", TurnLeftAtWallTest)
