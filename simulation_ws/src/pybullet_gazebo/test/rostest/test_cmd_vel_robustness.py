#!/usr/bin/env python3
"""rostest: bad /cmd_vel values in world02 with m2wr at (0, 8).

- NaN or inf in any field: the command is ignored (the previous one stays, as the diff drive
  documents), a warning says so at most once per 5 s of sim time, /odom and the model state
  stay finite, and a robot at rest does not move.
- Huge values: each wheel's speed is clamped to its URDF velocity limit (1000 rad/s; Bullet
  caps joints at 100 rad/s besides), with one warning per wheel. m2wr may rear up and turn
  over (physics); /odom, the pose and /clock stay finite and sane, and the robot stays inside
  the perimeter.
- Without cmd_vel_timeout (the default, as in Gazebo) the last command is held.
"""
import itertools
import math
import os
import sys
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from std_srvs.srv import Empty

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reliability import ClockWatch, OdomWatch, all_finite, state   # noqa: E402
from pybullet_gazebo.ros.testing import (NodeLog, service, wait_for_message, wait_until,  # noqa: E402
                                         wait_until_sim_time)

FIELDS = ("linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z")
BAD_VALUES = (math.nan, math.inf, -math.inf)
PERIMETER = 9.5          # [m] every perimeter barrier's centre line lies beyond +-9.29


def twist(linear_x=0.0, angular_z=0.0, **fields):
    msg = Twist()
    msg.linear.x, msg.angular.z = linear_x, angular_z
    for path, value in fields.items():
        part, axis = path.split("_")
        setattr(getattr(msg, part), axis, value)
    return msg


def bad_twists():
    """One Twist per (field, non-finite value), the other fields 0."""
    for field, value in itertools.product(FIELDS, BAD_VALUES):
        yield twist(**{field.replace(".", "_"): value})


class CmdVelRobustnessTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_cmd_vel_robustness")
        cls.log = NodeLog("/gazebo")
        cls.clock = ClockWatch()
        cls.odom = OdomWatch()
        cls.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=10)
        cls.reset_world = service("/gazebo/reset_world", Empty, timeout=30)
        wait_for_message("/odom", Odometry, timeout=30)
        wait_until(cls.cmd.get_num_connections, 10, "the simulator's subscription to /cmd_vel")
        wait_until_sim_time(rospy.get_time() + 1.0)          # dropped from z 0.5, settled

    def publish_for(self, messages, wall_seconds, rate=20.0):
        """Publishes the messages in turn at `rate` [Hz wall]; returns how many went out."""
        sent = 0
        end = time.monotonic() + wall_seconds
        for msg in itertools.cycle(messages):
            if time.monotonic() >= end:
                return sent
            self.cmd.publish(msg)
            sent += 1
            time.sleep(1.0 / rate)

    def stop_and_reset(self):
        self.publish_for([Twist()], 0.3)
        self.reset_world()
        wait_until_sim_time(rospy.get_time() + 1.0)

    def assert_odometry_finite_since(self, start, at_least):
        rows = self.odom.since(start)
        self.assertGreaterEqual(len(rows), at_least)
        for row in rows:
            self.assertTrue(all_finite(row), row)

    def logged_since(self, count):
        """What /gazebo logged after its first `count` lines (the node's own log stamps lag
        the world's step stamps by up to a /clock period, so lines are counted, not timed)."""
        return [text for _, text in self.log.since(-1.0)[count:]]

    def test_1_nan_and_inf_are_ignored_and_the_robot_at_rest_stays(self):
        lines_before = len(self.log.since(-1.0))
        t0, x0, y0, z0, yaw0 = state()
        sent = self.publish_for(list(bad_twists()), 2.0)
        wait_until_sim_time(rospy.get_time() + 0.5)
        t1, x1, y1, z1, yaw1 = state()
        self.assertTrue(all_finite((x1, y1, z1, yaw1)))
        self.assertLess(math.hypot(x1 - x0, y1 - y0), 0.002)
        self.assertLess(abs(math.remainder(yaw1 - yaw0, math.tau)), 0.002)
        self.assert_odometry_finite_since(t0, at_least=int((t1 - t0) * 20 * 0.8))
        warnings = [text for text in self.logged_since(lines_before) if "NaN or inf" in text]
        self.assertGreaterEqual(sent, 30)
        self.assertGreaterEqual(len(warnings), 1)
        self.assertLessEqual(len(warnings), 1 + int((t1 - t0) / 5.0) + 1)   # throttled: 5 s
        self.assertIn("'m2wr'", warnings[0])

    def test_2_nan_keeps_the_previous_command(self):
        self.publish_for([twist(0.3)], 0.3)
        wait_until_sim_time(rospy.get_time() + 1.0)                 # up to speed
        t0, x0, _, _, _ = state()
        self.publish_for([twist(linear_x=math.nan), twist(angular_z=math.inf)], 1.5)
        t1, x1, _, _, _ = state()
        self.assertGreater(t1 - t0, 0.5)
        self.assertAlmostEqual((x1 - x0) / (t1 - t0), 0.3, delta=0.05)   # still 0.3 m/s
        self.assert_odometry_finite_since(t0, at_least=int((t1 - t0) * 20 * 0.8))
        self.stop_and_reset()

    def test_3_huge_values_are_clamped_and_the_state_stays_finite(self):
        t0 = state()[0]
        clock_before = self.clock.count()
        for command in ((1e9, 0.0), (0.0, 1e9), (-1e300, 1e300)):
            self.publish_for([twist(*command)], 1.5, rate=10.0)
            _, x, y, z, yaw = state()
            self.assertTrue(all_finite((x, y, z, yaw)))
            self.assertLess(max(abs(x), abs(y)), PERIMETER)
            self.assertTrue(-0.05 < z < 1.5, z)
        t1 = state()[0]
        self.assertGreater(t1 - t0, 2.0)                               # the clock went on
        self.assertGreater(self.clock.count() - clock_before, 100)
        self.assert_odometry_finite_since(t0, at_least=int((t1 - t0) * 20 * 0.8))
        clamped = [text for text in self.logged_since(0) if "URDF velocity limit" in text]
        self.assertEqual(len(clamped), 2, clamped)                     # once per wheel
        self.assertTrue(any("joint_left_wheel" in text for text in clamped))
        self.assertTrue(any("joint_right_wheel" in text for text in clamped))
        self.stop_and_reset()

    def test_4_the_last_command_is_held_without_cmd_vel_timeout(self):
        self.publish_for([twist(0.3)], 0.3)
        t0, x0, _, _, _ = state()
        wait_until_sim_time(t0 + 3.0)                                  # no command meanwhile
        t1, x1, _, _, _ = state()
        self.assertAlmostEqual((x1 - x0) / (t1 - t0), 0.3, delta=0.05)
        self.stop_and_reset()


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "cmd_vel_robustness", CmdVelRobustnessTest)
