#!/usr/bin/env python3
"""rostest, Gazebo's property services as a Gazebo user sees them (empty world, m2wr and an SDF
crate spawned): world, model, link and joint properties; set_link_properties (mass, gravity
mode), set_joint_properties (damping), set_model_configuration; the light services, which
answer that the stand-in has no lights; bad input answered success false, naming the input,
nothing changed."""
import os
import sys
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelState, ODEJointProperties
from gazebo_msgs.srv import GetJointPropertiesResponse
from geometry_msgs.msg import Twist, Vector3
from std_msgs.msg import ColorRGBA

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gazebo_api_client import Gazebo, pose, spawn_crate, spawn_m2wr   # noqa: E402


class Properties(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_api_properties")
        cls.gazebo = Gazebo()
        spawn_m2wr(cls.gazebo)
        spawn_crate(cls.gazebo, x=3.0)
        cls.gazebo.wait_sim(0.2)

    def test_world_properties(self):
        world = self.gazebo.get_world_properties()
        self.assertTrue(world.success)
        self.assertEqual(world.status_message, "GetWorldProperties: got properties")
        self.assertEqual(sorted(world.model_names), ["crate", "ground_plane", "m2wr"])
        self.assertGreater(world.sim_time, 0.2)

    def test_model_properties_as_gazebo_lists_m2wr_and_the_crate(self):
        m2wr = self.gazebo.get_model_properties("m2wr")
        self.assertTrue(m2wr.success, m2wr.status_message)
        self.assertEqual(sorted(m2wr.body_names),
                         ["link_chassis", "link_left_wheel", "link_right_wheel"])
        self.assertEqual(sorted(m2wr.joint_names), ["joint_left_wheel", "joint_right_wheel"])
        self.assertIn("link_chassis_collision", m2wr.geom_names)
        self.assertFalse(m2wr.is_static)
        ground = self.gazebo.get_model_properties("ground_plane")
        self.assertTrue(ground.is_static)
        crate = self.gazebo.get_model_properties("crate")
        self.assertEqual((crate.body_names, crate.geom_names), (["body"], ["shell"]))

    def test_link_properties_are_the_descriptions(self):
        crate = self.gazebo.get_link_properties("crate::body")
        self.assertTrue(crate.success, crate.status_message)
        self.assertEqual((crate.mass, crate.ixx, crate.gravity_mode), (2.0, 0.05, True))
        wheel = self.gazebo.get_link_properties("m2wr::link_left_wheel")
        self.assertAlmostEqual(wheel.mass, 0.2, places=6)       # m2wr.xacro's wheel mass

    def test_joint_properties_and_set_model_configuration(self):
        answer = self.gazebo.set_model_configuration("m2wr", "", ["joint_left_wheel"], [1.0])
        self.assertTrue(answer.success, answer.status_message)
        joint = self.gazebo.get_joint_properties("joint_left_wheel")
        self.assertTrue(joint.success, joint.status_message)
        self.assertEqual(joint.type, GetJointPropertiesResponse.CONTINUOUS)
        self.assertEqual((len(joint.position), len(joint.rate)), (1, 1))
        scoped = self.gazebo.get_joint_properties("m2wr::joint_left_wheel")
        self.assertTrue(scoped.success)

    def test_gravity_mode_off_lets_the_crate_float(self):
        props = self.gazebo.get_link_properties("crate::body")
        answer = self.gazebo.set_link_properties("crate::body", props.com, False, props.mass,
                                                 props.ixx, 0, 0, props.iyy, 0, props.izz)
        self.assertTrue(answer.success, answer.status_message)
        self.assertFalse(self.gazebo.get_link_properties("crate::body").gravity_mode)
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, 0.0, 2.0), Twist(), ""))
        self.gazebo.wait_sim(0.5)
        self.assertAlmostEqual(self.gazebo.get_model_state("crate", "").pose.position.z, 2.0,
                               places=2)
        self.gazebo.set_link_properties("crate::body", props.com, True, props.mass,
                                        props.ixx, 0, 0, props.iyy, 0, props.izz)
        self.gazebo.wait_sim(1.0)
        self.assertLess(self.gazebo.get_model_state("crate", "").pose.position.z, 0.5)

    def test_joint_damping_is_applied_and_ode_settings_refused(self):
        answer = self.gazebo.set_joint_properties("joint_right_wheel",
                                                  ODEJointProperties(damping=[0.01]))
        self.assertTrue(answer.success, answer.status_message)
        refused = self.gazebo.set_joint_properties("joint_right_wheel",
                                                   ODEJointProperties(erp=[0.5]))
        self.assertFalse(refused.success)
        self.assertIn("erp", refused.status_message)
        self.assertIn("no Bullet counterpart", refused.status_message)

    def test_lights_are_not_simulated(self):
        for answer in (self.gazebo.get_light_properties("sun"),
                       self.gazebo.set_light_properties("sun", True, ColorRGBA(), ColorRGBA(),
                                                        0, 0, 0, Vector3(), pose()),
                       self.gazebo.delete_light("sun")):
            self.assertFalse(answer.success)
            self.assertIn("light sun not found", answer.status_message)
            self.assertIn("simulates no lights", answer.status_message)

    def test_bad_input_is_answered_and_changes_nothing(self):
        self.gazebo.pause_physics()
        self.addCleanup(self.gazebo.unpause_physics)
        before = self.gazebo.snapshot()
        nan = float("nan")
        props = self.gazebo.get_link_properties("crate::body")
        cases = [
            (self.gazebo.get_model_properties, ("ghost",), "model 'ghost' does not exist"),
            (self.gazebo.get_model_properties, ("",), "model '' does not exist"),
            (self.gazebo.get_link_properties, ("crate::lid",), "link 'crate::lid' does not exist"),
            (self.gazebo.get_joint_properties, ("elbow",), "joint 'elbow' does not exist"),
            (self.gazebo.set_joint_properties, ("elbow", ODEJointProperties()),
             "joint 'elbow' does not exist"),
            (self.gazebo.set_joint_properties, ("joint_left_wheel", ODEJointProperties(damping=[nan])),
             "finite"),
            (self.gazebo.set_link_properties, ("crate::body", props.com, True, nan, 1, 0, 0, 1, 0, 1),
             "NaN"),
            (self.gazebo.set_link_properties, ("crate::body", props.com, True, -1, 1, 0, 0, 1, 0, 1),
             "must be > 0"),
            (self.gazebo.set_link_properties, ("crate::body", props.com, True, 1, 1, 0.5, 0, 1, 0, 1),
             "products of inertia"),
            (self.gazebo.set_link_properties, ("ground_plane::link", props.com, True, 1, 1, 0, 0,
                                               1, 0, 1), "static"),
            (self.gazebo.set_model_configuration, ("m2wr", "", ["joint_left_wheel", "elbow"],
                                                   [0.0, 1.0]), "no joint 'elbow'"),
            (self.gazebo.set_model_configuration, ("m2wr", "", ["joint_left_wheel"], [nan]),
             "NaN"),
            (self.gazebo.set_model_configuration, ("m2wr", "", ["joint_left_wheel"], []),
             "1 joint names but 0 positions"),
            (self.gazebo.set_model_configuration, ("ghost", "", [], []),
             "model 'ghost' does not exist"),
            (self.gazebo.set_model_configuration, ("", "", [], []), "model '' does not exist"),
            (self.gazebo.set_model_configuration, ("m2wr", "", ["joint_left_wheel"],
                                                   [float("inf")]), "inf"),
            (self.gazebo.get_link_properties, ("",), "link '' does not exist"),
            (self.gazebo.get_joint_properties, ("",), "joint '' does not exist"),
            (self.gazebo.set_joint_properties, ("", ODEJointProperties()),
             "joint '' does not exist"),
            (self.gazebo.set_joint_properties, ("joint_left_wheel",
                                                ODEJointProperties(damping=[-1.0])),
             "damping [-1.0] must be >= 0"),
            (self.gazebo.set_link_properties, ("crate::lid", props.com, True, 1, 1, 0, 0, 1, 0, 1),
             "link 'crate::lid' does not exist"),
            (self.gazebo.set_link_properties, ("crate::body", props.com, True, 1,
                                               float("inf"), 0, 0, 1, 0, 1), "inf"),
        ]
        for call, args, message in cases:
            answer = call(*args)
            self.assertFalse(answer.success, (args, answer.status_message))
            self.assertIn(message, answer.status_message, args)
        self.assertEqual(self.gazebo.get_link_properties("crate::body").mass, 2.0)
        self.assertEqual(self.gazebo.snapshot(), before)


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "api_properties", Properties)
