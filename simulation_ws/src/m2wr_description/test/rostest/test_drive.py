#!/usr/bin/env python3
"""rostest: m2wr obeys /cmd_vel as gazebo_ros_diff_drive (Noetic) drives it, and /odom tells
the truth.

Expected motion, from the plugin's formula and the robot's real geometry:
- (v, w) = (0.6, 0): both wheels at 0.6 / 0.1 = 6 rad/s -> 0.6 m/s along the heading.
- (v, w) = (0, 0.3): the joint *named* joint_left_wheel (at -y, the robot's right) gets
  -0.3 * 0.4 / 2 / 0.1 = -0.6 rad/s, joint_right_wheel (at +y, its left) +0.6 rad/s. The
  left side rolls forward at 0.06 m/s, the right side back: clockwise at 0.12 / 0.3 = 0.4 rad/s.
  A little less in the stand-in: the caster (Gazebo's mu 1) drags sideways, and under that
  load Bullet's solver leaves the wheel motors short: 0.363 to 0.381 rad/s over 3 s from
  rest, depending on the heading, and a little less here, where the command waits for the
  drive's next 20 Hz update.
"""
import math
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from std_srvs.srv import Empty
from gazebo_msgs.srv import GetModelState
from tf2_msgs.msg import TFMessage

from pybullet_gazebo.ros.testing import (service, unwrap_angle, wait_for_message, wait_until,
                                         wait_until_sim_time, yaw_of)

WHEEL_RADIUS = 0.1          # [m]
FORMULA_SEPARATION = 0.4    # [m] wheelSeparation in the plugin block
REAL_SEPARATION = 0.3       # [m] joints at y = +-0.15
DRIVE_PERIOD = 1 / 20.0     # [s] the drive's updateRate: /odom's period


class DriveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_drive")
        cls.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        cls.get_state = service("/gazebo/get_model_state", GetModelState, timeout=30)
        cls.pause = service("/gazebo/pause_physics", Empty)
        cls.unpause = service("/gazebo/unpause_physics", Empty)
        cls.last_odom = None
        rospy.Subscriber("/odom", Odometry, cls.on_odom)
        wait_for_message("/odom", Odometry, timeout=30)
        wait_until(cls.cmd.get_num_connections, 10, "the simulator's subscription to /cmd_vel")
        wait_until_sim_time(rospy.get_time() + 1.0)          # dropped from z 0.5, settled

    @classmethod
    def on_odom(cls, msg):
        cls.last_odom = msg

    def state(self):
        answer = self.get_state("m2wr", "world")
        self.assertTrue(answer.success, answer.status_message)
        yaw = yaw_of(answer.pose.orientation)
        return answer.header.stamp.to_sec(), answer.pose.position.x, answer.pose.position.y, yaw

    def drive(self, linear, angular, duration):
        """Commands (linear, angular) for `duration` s of sim time, measured exactly by
        pausing physics around it; returns the states before and after."""
        self.pause()
        self.cmd.publish(Twist())
        command = Twist()
        command.linear.x, command.angular.z = linear, angular
        self.cmd.publish(command)
        time.sleep(0.2)                                      # delivered while paused
        start = self.state()
        self.unpause()
        wait_until_sim_time(start[0] + duration)
        self.pause()
        end = self.state()
        self.cmd.publish(Twist())
        time.sleep(0.2)
        self.unpause()
        return start, end

    def test_1_straight_run_moves_three_metres_along_the_heading(self):
        start, end = self.drive(0.6, 0.0, 5.0)
        elapsed = end[0] - start[0]
        dx, dy = end[1] - start[1], end[2] - start[2]
        along = dx * math.cos(start[3]) + dy * math.sin(start[3])
        across = -dx * math.sin(start[3]) + dy * math.cos(start[3])
        self.assertGreaterEqual(elapsed, 5.0)
        self.assertAlmostEqual(along, 0.6 * elapsed, delta=0.05 * 0.6 * elapsed)
        self.assertLess(abs(across), 0.1)

    def test_2_positive_angular_z_turns_m2wr_clockwise(self):
        start, end = self.drive(0.0, 0.3, 3.0)
        rate = unwrap_angle(end[3] - start[3]) / (end[0] - start[0])
        wheel_rim_speed = 0.3 * FORMULA_SEPARATION / 2          # [m/s] each side
        expected = -2 * wheel_rim_speed / REAL_SEPARATION       # [rad/s] clockwise: -0.4
        self.assertLess(rate, 0.0, "a positive angular.z must turn m2wr clockwise")
        # 15 %: the caster's drag (see the module docstring); a drive that put the real
        # 0.3 m track in its formula (0.3 rad/s) still fails
        self.assertAlmostEqual(rate, expected, delta=0.15 * abs(expected))
        # it turns on the spot: the chassis frame moves little
        self.assertLess(math.hypot(end[1] - start[1], end[2] - start[2]), 0.15)

    def test_3_odometry_agrees_with_the_true_pose(self):
        self.cmd.publish(Twist())
        wait_until_sim_time(rospy.get_time() + 1.0)
        # compared at one instant: free-running, the newest /odom this node has read can be
        # seconds of sim older than the state it asks for, and a stopped m2wr still creeps
        # after a turn (up to 0.001 rad/s measured, the caster settling), so paused, with the
        # last odometry published before the pause (one drive update, 1/20 s, at most before)
        self.pause()
        try:
            stamp, x, y, yaw = self.state()
            odom = wait_until(
                lambda: (self.last_odom.header.stamp.to_sec() >= stamp - DRIVE_PERIOD - 0.001
                         and self.last_odom), 5,
                "the /odom of the last drive update before the pause", interval=0.01)
        finally:
            self.unpause()
        self.assertLessEqual(stamp - odom.header.stamp.to_sec(), DRIVE_PERIOD + 0.001,
                             "no /odom from the last drive update before the pause")
        self.assertEqual(odom.header.frame_id, "odom")
        self.assertEqual(odom.child_frame_id, "link_chassis")
        self.assertAlmostEqual(odom.pose.pose.position.x, x, delta=0.01)
        self.assertAlmostEqual(odom.pose.pose.position.y, y, delta=0.01)
        odom_yaw = yaw_of(odom.pose.pose.orientation)
        self.assertAlmostEqual(unwrap_angle(odom_yaw - yaw), 0.0, delta=0.01)

    def test_4_odometry_twist_is_in_the_robot_frame(self):
        command = Twist()
        command.linear.x = 0.6
        self.cmd.publish(command)
        # the chassis pitches as it starts (the twist peaks near 0.7 m/s about 0.4 s after
        # the command reaches the wheels), so the second is counted from the moment it does:
        # free-running, the message may arrive a second of sim time after it was sent
        wait_until(lambda: self.last_odom.twist.twist.linear.x >= 0.1, 10,
                   "/odom's linear.x to pass 0.1 m/s after a 0.6 m/s command", interval=0.01)
        wait_until_sim_time(rospy.get_time() + 1.0)
        odom = self.last_odom
        self.cmd.publish(Twist())
        self.assertAlmostEqual(odom.twist.twist.linear.x, 0.6, delta=0.05)
        self.assertLess(abs(odom.twist.twist.linear.y), 0.05)

    def test_5_tf_odom_to_chassis_is_the_odometry_pose_at_20_hz(self):
        odometry, transforms = {}, []
        odom_sub = rospy.Subscriber("/odom", Odometry,
                                    lambda m: odometry.__setitem__(m.header.stamp, m))
        tf_sub = rospy.Subscriber("/tf", TFMessage, lambda m: transforms.extend(m.transforms))
        # Under load a new subscriber may connect a second after another: count from the
        # moment both topics have delivered, so a late connection is not read as a lost message.
        wait_until(lambda: odometry and transforms, 10, "a first /odom and /tf message",
                   interval=0.01)
        command = Twist()
        command.linear.x, command.angular.z = 0.3, 0.2
        self.cmd.publish(command)
        try:
            wait_until_sim_time(rospy.get_time() + 2.0)
        finally:
            self.cmd.publish(Twist())
            odom_sub.unregister()
            tf_sub.unregister()
        chassis = [t for t in transforms if t.child_frame_id == "link_chassis"]
        self.assertGreater(len(chassis), 20, "odom -> link_chassis on /tf")
        stamps = [t.header.stamp.to_sec() for t in chassis]
        for earlier, later in zip(stamps, stamps[1:]):
            self.assertAlmostEqual(later - earlier, 0.05, delta=1e-6)      # updateRate 20
        matched = 0
        for transform in chassis:
            self.assertEqual(transform.header.frame_id, "odom")
            odom = odometry.get(transform.header.stamp)
            if odom is None:
                continue
            matched += 1
            pose, moved = odom.pose.pose, transform.transform
            self.assertEqual((moved.translation.x, moved.translation.y, moved.translation.z),
                             (pose.position.x, pose.position.y, pose.position.z))
            self.assertEqual(moved.rotation, pose.orientation)
        self.assertGreater(matched, 20)


if __name__ == "__main__":
    rostest.rosrun("m2wr_description", "drive", DriveTest)
