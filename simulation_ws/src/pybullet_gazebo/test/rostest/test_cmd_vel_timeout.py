#!/usr/bin/env python3
"""rostest: with cmd_vel_timeout (~timeout [s] of sim time, 0.5 in the .test) m2wr drives while
commands come at 10 Hz, stops once they stop, and drives again on the next one."""
import os
import sys
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reliability import state   # noqa: E402
from pybullet_gazebo.ros.testing import (wait_for_message, wait_until,   # noqa: E402
                                         wait_until_sim_time)

SPEED = 0.5            # [m/s]


class CmdVelTimeoutTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_cmd_vel_timeout")
        cls.timeout = rospy.get_param("~timeout")
        cls.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        wait_for_message("/odom", Odometry, timeout=30)
        wait_until(cls.cmd.get_num_connections, 10, "the simulator's subscription to /cmd_vel")
        wait_until_sim_time(rospy.get_time() + 1.0)          # dropped from z 0.5, settled

    def drive(self, wall_seconds):
        """Commands SPEED at 10 Hz wall; returns the sim time of the last command."""
        msg = Twist()
        msg.linear.x = SPEED
        end = time.monotonic() + wall_seconds
        while time.monotonic() < end:
            self.cmd.publish(msg)
            time.sleep(0.1)
        return rospy.get_time()

    def test_robot_stops_when_commands_stop_and_goes_on_the_next(self):
        self.drive(0.8)                                              # up to speed
        t0, x0 = state()[:2]
        last = self.drive(1.5)
        t1, x1 = state()[:2]
        self.assertAlmostEqual((x1 - x0) / (t1 - t0), SPEED, delta=0.05)   # commanded
        wait_until_sim_time(last + self.timeout + 0.5)
        t2, x2 = state()[:2]
        wait_until_sim_time(t2 + 1.5)
        t3, x3 = state()[:2]
        self.assertLess(abs(x3 - x2) / (t3 - t2), 0.01)              # stopped
        # it ran on for the time-out at most (plus a short brake), not beyond
        self.assertLess(x2 - x1, SPEED * (t2 - t1 - 0.5) + 0.05)
        self.drive(1.5)
        self.assertGreater(state()[1] - x3, 0.3)                     # the next command drives


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "cmd_vel_timeout", CmdVelTimeoutTest)
