#!/usr/bin/env python3
"""rostest (two_robots.test): two m2wr spawned in namespaces /robot1 and /robot2 (whose
tf_prefix parameter is "second") are driven independently and report on their own.

  /robot1/cmd_vel  linear.x 0.4 m/s    -> robot1 drives straight ahead (+x), ~2 m in 5 s
  /robot2/cmd_vel  angular.z 0.6 rad/s -> robot2 turns on the spot, clockwise (m2wr's wheel
                                          names: see the README), ~0.8 rad/s
Each odometry on /robotN/odom in its own frames (robot1/odom -> robot1/link_chassis,
second/odom -> second/link_chassis), the same pairs on /tf; the laser topic of the URDF is
absolute (/m2wr/laser/scan), so both scans arrive there, told apart by frame_id
(sensor_laser; second/sensor_laser: the laser takes tf_prefix only, as gazebo_ros_laser).
A robot whose diff drive plugin names its own <robotNamespace>/own</robotNamespace> listens on
/own/cmd_vel whatever the spawn's robot_namespace."""
import math
import re
import threading
import time
import unittest

import rosgraph
import rospy
import rostest
from gazebo_msgs.srv import SpawnModel
from geometry_msgs.msg import Pose, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

from pybullet_gazebo.ros.testing import (service, unwrap_angle, wait_for_message,
                                         wait_until_sim_time, yaw_of)

DRIVE_TIME = 5.0                 # [s sim]
LINEAR = 0.4                     # [m/s] robot1's command
ANGULAR = 0.6                    # [rad/s] robot2's command
# m2wr's plugin says wheelSeparation 0.4 m, its wheels sit 0.3 m apart: it turns 4/3 faster
# than commanded, clockwise for a positive angular.z (README, "Which way the robot turns")
EXPECTED_YAW_RATE = -ANGULAR * 0.4 / 0.3     # [rad/s]


class Track:
    """Poses and frames from one robot's odometry: (sim time [s], x, y, unwrapped yaw)."""

    def __init__(self, topic):
        self.lock = threading.Lock()
        self.poses = []
        self.frames = set()
        rospy.Subscriber(topic, Odometry, self.on_odom, queue_size=200)

    def on_odom(self, msg):
        p = msg.pose.pose.position
        yaw = yaw_of(msg.pose.pose.orientation)
        with self.lock:
            if self.poses:
                yaw = self.poses[-1][3] + unwrap_angle(yaw - self.poses[-1][3])
            self.poses.append((msg.header.stamp.to_sec(), p.x, p.y, yaw))
            self.frames.add((msg.header.frame_id, msg.child_frame_id))

    def at(self, t):
        with self.lock:
            return min(self.poses, key=lambda pose: abs(pose[0] - t))


def latched(topic, msg_type):
    return rospy.Publisher(topic, msg_type, queue_size=1, latch=True)


class TwoRobotsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_two_robots")
        cls.tracks = {name: Track("/%s/odom" % name) for name in ("robot1", "robot2")}
        cls.tf_pairs = set()
        cls.scan_frames = set()
        rospy.Subscriber("/tf", TFMessage, cls.on_tf, queue_size=200)
        rospy.Subscriber("/m2wr/laser/scan", LaserScan,
                         lambda msg: cls.scan_frames.add(msg.header.frame_id), queue_size=50)
        for name in cls.tracks:
            wait_for_message("/%s/odom" % name, Odometry, timeout=60)
        wait_until_sim_time(rospy.get_time() + 1.0)          # both settled on their wheels
        cls.start = rospy.get_time()
        commands = []
        for name, (v, w) in (("robot1", (LINEAR, 0.0)), ("robot2", (0.0, ANGULAR))):
            pub = latched("/%s/cmd_vel" % name, Twist)
            command = Twist()
            command.linear.x, command.angular.z = v, w
            pub.publish(command)
            commands.append(pub)
        cls.end = wait_until_sim_time(cls.start + DRIVE_TIME + 0.5, timeout=60)
        for pub in commands:                                  # stop both
            pub.publish(Twist())

    @classmethod
    def on_tf(cls, msg):
        for transform in msg.transforms:
            cls.tf_pairs.add((transform.header.frame_id, transform.child_frame_id))

    def motion(self, name):
        """(distance [m], yaw change [rad]) of a robot over DRIVE_TIME from its command."""
        track = self.tracks[name]
        a, b = track.at(self.start), track.at(self.start + DRIVE_TIME)
        return math.hypot(b[1] - a[1], b[2] - a[2]), b[3] - a[3], a, b

    def test_robot1_drives_straight_on_its_own_command(self):
        distance, turned, a, b = self.motion("robot1")
        self.assertAlmostEqual(distance, LINEAR * DRIVE_TIME, delta=0.25,
                               msg="robot1 from %s to %s" % (a, b))
        self.assertGreater(b[1] - a[1], 0.9 * distance, "robot1 did not drive along +x")
        self.assertAlmostEqual(turned, 0.0, delta=0.1)

    def test_robot2_turns_on_the_spot_on_its_own_command(self):
        distance, turned, a, b = self.motion("robot2")
        self.assertLess(distance, 0.1, "robot2 moved %.2f m; it was only told to turn" % distance)
        self.assertAlmostEqual(turned, EXPECTED_YAW_RATE * DRIVE_TIME,
                               delta=0.15 * abs(EXPECTED_YAW_RATE * DRIVE_TIME),
                               msg="robot2 turned %.2f rad in %.0f s" % (turned, DRIVE_TIME))

    def test_each_odometry_in_its_own_frames(self):
        self.assertEqual(self.tracks["robot1"].frames, {("robot1/odom", "robot1/link_chassis")})
        self.assertEqual(self.tracks["robot2"].frames, {("second/odom", "second/link_chassis")})

    def test_tf_carries_both_robots_apart(self):
        self.assertIn(("robot1/odom", "robot1/link_chassis"), self.tf_pairs)
        self.assertIn(("second/odom", "second/link_chassis"), self.tf_pairs)
        self.assertNotIn(("odom", "link_chassis"), self.tf_pairs)

    def test_both_scans_on_the_urdf_s_absolute_topic_told_apart_by_frame(self):
        self.assertEqual(self.scan_frames, {"sensor_laser", "second/sensor_laser"})

    def test_plugin_robot_namespace_wins_over_the_spawn_s(self):
        urdf = rospy.get_param("/robot_description")
        own = re.sub(r"(<plugin[^>]*libgazebo_ros_diff_drive\.so[^>]*>)",
                     r"\1<robotNamespace>/own</robotNamespace>", urdf)
        self.assertNotEqual(own, urdf, "the description has no diff drive plugin to edit")
        pose = Pose()
        pose.position.y, pose.position.z, pose.orientation.w = -3.0, 0.5, 1.0
        answer = service("/gazebo/spawn_urdf_model", SpawnModel)("robot3", own, "/ignored", pose, "")
        self.assertTrue(answer.success, answer.status_message)
        odom = wait_for_message("/own/odom", Odometry, timeout=20)
        self.assertEqual((odom.header.frame_id, odom.child_frame_id), ("own/odom", "own/link_chassis"))
        _, subscribers, _ = rosgraph.Master("/test_two_robots").getSystemState()
        topics = {topic for topic, _ in subscribers}
        self.assertIn("/own/cmd_vel", topics)
        self.assertNotIn("/ignored/cmd_vel", topics)


if __name__ == "__main__":
    rostest.rosrun("m2wr_description", "two_robots", TwoRobotsTest)
