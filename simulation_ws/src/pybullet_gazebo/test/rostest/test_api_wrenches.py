#!/usr/bin/env python3
"""rostest, Gazebo's force services as a Gazebo user sees them (empty world at 4x real time, m2wr and
a 2 kg SDF crate): apply_body_wrench pushes for its duration of sim time (from its start_time;
a negative duration until clear_body_wrenches), apply_joint_effort turns a wheel until
clear_joint_forces; bad input answered success false, naming the input, nothing applied;
clearing an unknown link or joint clears nothing and the simulator's warning names it."""
import os
import sys
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelState
from geometry_msgs.msg import Point, Twist, Vector3, Wrench

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gazebo_api_client import Gazebo, pose, spawn_crate, spawn_m2wr   # noqa: E402
from pybullet_gazebo.ros.testing import NodeLog, wait_until   # noqa: E402

WEIGHT = 2.0 * 9.8            # [N] the crate's
LIFT = Wrench(Vector3(0.0, 0.0, 2.0 * WEIGHT), Vector3())      # net 9.8 m/s^2 up


class Wrenches(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_api_wrenches")
        cls.gazebo = Gazebo()
        cls.simulator_log = NodeLog("/gazebo")
        spawn_m2wr(cls.gazebo)
        spawn_crate(cls.gazebo, x=3.0)
        cls.gazebo.wait_sim(0.3)

    def setUp(self):
        self.gazebo.pause_physics()
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, 0.0, 0.15), Twist(), ""))
        self.now = rospy.Time.from_sec(self.gazebo.sim_time())

    def assert_warned(self, *words, timeout=10.0):
        """The simulator logged a line holding every one of `words` (on /rosout)."""
        def logged():
            return [text for _, text in self.simulator_log.since(0)]
        try:
            wait_until(lambda: any(all(w in text for w in words) for text in logged()), timeout,
                       "a line with %s in the simulator's log" % (words,))
        except AssertionError as error:
            raise AssertionError("%s; it logged %s" % (error, logged()[-5:])) from None

    def crate_z(self):
        return self.gazebo.get_model_state("crate", "").pose.position.z

    def test_a_wrench_lifts_for_its_duration_then_the_crate_falls_back(self):
        answer = self.gazebo.apply_body_wrench("crate::body", "", Point(), LIFT, rospy.Time(0),
                                               rospy.Duration(0.5))
        self.assertTrue(answer.success, answer.status_message)
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(1.0)        # 0.5 s up at 9.8 m/s^2, then 0.5 s coasting to the top
        self.assertGreater(self.crate_z(), 2.0)       # 0.15 + 1.225 + 1.225 m at the top
        self.assertLess(self.crate_z(), 3.0)
        self.gazebo.wait_sim(1.5)
        self.assertLess(self.crate_z(), 0.3)          # back on the ground: the push ended

    def test_a_wrench_waits_for_its_start_time(self):
        start = self.now + rospy.Duration(1.0)
        self.gazebo.apply_body_wrench("crate::body", "world", Point(), LIFT, start,
                                      rospy.Duration(0.3))
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(0.7)
        self.assertAlmostEqual(self.crate_z(), 0.15, places=2)
        self.gazebo.wait_sim(0.6)
        self.assertGreater(self.crate_z(), 0.3)

    def test_a_negative_duration_pushes_until_cleared(self):
        self.gazebo.apply_body_wrench("crate::body", "", Point(), LIFT, rospy.Time(0),
                                      rospy.Duration(-1.0))
        self.gazebo.clear_body_wrenches("crate::lid")         # no such link: clears nothing
        self.assert_warned("clear_body_wrenches: link 'crate::lid' does not exist",
                           "nothing cleared")
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(0.5)
        self.assertGreater(self.crate_z(), 1.0)       # 0.15 + 1.2 m after 0.5 s, rising
        self.gazebo.clear_body_wrenches("crate::body")
        self.gazebo.wait_sim(2.5)                     # up to 2.6 m, down within 1.2 s
        self.assertLess(self.crate_z(), 0.3)

    def test_a_joint_effort_spins_a_wheel_until_cleared(self):
        answer = self.gazebo.apply_joint_effort("joint_left_wheel", 20.0, rospy.Time(0),
                                                rospy.Duration(-1.0))
        self.assertTrue(answer.success, answer.status_message)
        self.assertEqual(answer.status_message, "ApplyJointEffort: effort set")
        self.gazebo.clear_joint_forces("elbow")                # no such joint: clears nothing
        self.assert_warned("clear_joint_forces: joint 'elbow' does not exist", "nothing cleared")
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(0.3)
        spinning = self.gazebo.get_joint_properties("joint_left_wheel").rate[0]
        self.assertGreater(abs(spinning), 2.0)        # over the drive's 5 N m holding it
        self.gazebo.clear_joint_forces("joint_left_wheel")
        # the drive's motor brings it to rest; how fast depends on how the robot rocks as the
        # wheel stops (under load it may still spin 0.5 s after the clear): look for 2 s
        rates = []
        for _ in range(20):
            self.gazebo.wait_sim(0.1)
            rates.append(abs(self.gazebo.get_joint_properties("joint_left_wheel").rate[0]))
            if rates[-1] < 0.5:
                break
        self.assertLess(rates[-1], 0.5, "still spinning 2 s after the clear: %s" % rates)

    def test_bad_input_is_answered_and_nothing_applied(self):
        nan = float("nan")
        cases = [
            (self.gazebo.apply_body_wrench, ("crate::lid", "", Point(), LIFT, rospy.Time(0),
                                             rospy.Duration(1)), "link 'crate::lid' does not exist"),
            (self.gazebo.apply_body_wrench, ("", "", Point(), LIFT, rospy.Time(0),
                                             rospy.Duration(1)), "link '' does not exist"),
            (self.gazebo.apply_body_wrench, ("crate::body", "nowhere", Point(), LIFT,
                                             rospy.Time(0), rospy.Duration(1)), "'nowhere'"),
            (self.gazebo.apply_body_wrench, ("crate::body", "", Point(),
                                             Wrench(Vector3(nan, 0, 0), Vector3()),
                                             rospy.Time(0), rospy.Duration(1)), "wrench.force"),
            (self.gazebo.apply_body_wrench, ("crate::body", "", Point(0, float("inf"), 0), LIFT,
                                             rospy.Time(0), rospy.Duration(1)), "reference_point"),
            (self.gazebo.apply_joint_effort, ("elbow", 1.0, rospy.Time(0), rospy.Duration(1)),
             "joint 'elbow' does not exist"),
            (self.gazebo.apply_joint_effort, ("joint_left_wheel", nan, rospy.Time(0),
                                              rospy.Duration(1)), "effort"),
            (self.gazebo.apply_body_wrench, ("crate::body", "", Point(),
                                             Wrench(Vector3(), Vector3(0, 0, float("inf"))),
                                             rospy.Time(0), rospy.Duration(1)), "wrench.torque"),
            (self.gazebo.apply_body_wrench, ("crate::body", "", Point(),
                                             Wrench(Vector3(0, 0, 1e12), Vector3()),
                                             rospy.Time(0), rospy.Duration(1)), "over 1e+09"),
            (self.gazebo.apply_joint_effort, ("", 1.0, rospy.Time(0), rospy.Duration(1)),
             "joint '' does not exist"),
            (self.gazebo.apply_joint_effort, ("joint_left_wheel", float("inf"), rospy.Time(0),
                                              rospy.Duration(1)), "effort [inf]"),
        ]
        for call, args, message in cases:
            answer = call(*args)
            self.assertFalse(answer.success, (args, answer.status_message))
            self.assertIn(message, answer.status_message, args)
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(0.5)
        self.assertAlmostEqual(self.crate_z(), 0.15, places=2)       # nothing pushed it
        self.assertLess(abs(self.gazebo.get_joint_properties("joint_left_wheel").rate[0]), 0.5)


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "api_wrenches", Wrenches)
