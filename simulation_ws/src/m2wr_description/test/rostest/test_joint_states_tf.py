#!/usr/bin/env python3
"""rostest: /joint_states carries m2wr's two wheel joints, turning as the wheels turn when the
robot drives, and every link of robot_description resolves in TF from odom (the drive's
odom -> link_chassis, robot_state_publisher's wheels from /joint_states and its fixed
sensor_laser): what rviz's RobotModel needs to show no error."""
import math
import unittest
import xml.etree.ElementTree as ET

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist
from sensor_msgs.msg import JointState

from pybullet_gazebo.ros.testing import wait_for_message

WHEELS = ("joint_left_wheel", "joint_right_wheel")
WHEEL_RADIUS = 0.1          # [m]


class JointStatesAndTfTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_joint_states_tf")
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)

    def test_wheel_joint_states_and_every_link_in_tf_from_odom(self):
        first = wait_for_message("/joint_states", JointState, timeout=40)
        self.assertEqual(sorted(first.name), sorted(WHEELS))
        self.assertEqual(len(first.position), 2)

        urdf = ET.fromstring(rospy.get_param("/robot_description"))
        links = [link.get("name") for link in urdf.findall("link")]
        self.assertEqual(sorted(links), ["link_chassis", "link_left_wheel", "link_right_wheel",
                                         "sensor_laser"])
        for link in links:
            transform = self.buffer.lookup_transform("odom", link, rospy.Time(0),
                                                     rospy.Duration(20.0))
            self.assertEqual(transform.header.frame_id, "odom")

        # drive 1 s of sim time at 0.3 m/s: each wheel turns about 3 rad
        start = wait_for_message("/joint_states", JointState, timeout=10)
        twist = Twist()
        twist.linear.x = 0.3
        until = start.header.stamp.to_sec() + 1.5
        while rospy.get_time() < until and not rospy.is_shutdown():
            self.cmd.publish(twist)
            rospy.sleep(0.05)
        self.cmd.publish(Twist())
        end = wait_for_message("/joint_states", JointState, timeout=10)
        elapsed = (end.header.stamp - start.header.stamp).to_sec()
        self.assertGreater(elapsed, 1.0)
        for name in WHEELS:
            turned = end.position[end.name.index(name)] - start.position[start.name.index(name)]
            self.assertGreater(turned, 0.5 * 0.3 / WHEEL_RADIUS,
                               "%s turned %.2f rad in %.2f s" % (name, turned, elapsed))
            self.assertLess(turned, 0.3 / WHEEL_RADIUS * elapsed * 1.2)

        # the wheels' TF follows the joint states: a wheel frame stays on its axle
        wheel = self.buffer.lookup_transform("link_chassis", "link_left_wheel", rospy.Time(0),
                                             rospy.Duration(5.0))
        self.assertAlmostEqual(wheel.transform.translation.y, -0.15, places=3)
        q = wheel.transform.rotation
        self.assertAlmostEqual(math.sqrt(q.x ** 2 + q.y ** 2 + q.z ** 2 + q.w ** 2), 1.0, places=6)


if __name__ == "__main__":
    rostest.rosrun("m2wr_description", "joint_states_tf", JointStatesAndTfTest)
