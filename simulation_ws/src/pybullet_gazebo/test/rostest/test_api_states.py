#!/usr/bin/env python3
"""rostest, Gazebo's state services and topics as a Gazebo user sees them (empty world, m2wr
and an SDF crate spawned): get/set_model_state with reference frames, a zero quaternion and a
twist; get/set_link_state; the /gazebo/set_model_state and /gazebo/set_link_state topics;
/gazebo/model_states and /gazebo/link_states; and bad input answered success false, naming the
input, with nothing changed (on the two topics: dropped, with a warning naming it)."""
import math
import os
import sys
import unittest

import rospy
import rostest
from gazebo_msgs.msg import LinkState, LinkStates, ModelState, ModelStates
from geometry_msgs.msg import Twist, Vector3

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gazebo_api_client import Gazebo, pose, spawn_crate, spawn_m2wr   # noqa: E402
from pybullet_gazebo.ros.testing import NodeLog, wait_for_message, wait_until   # noqa: E402


def xyz(p):
    return (p.position.x, p.position.y, p.position.z)


class States(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_api_states")
        cls.gazebo = Gazebo()
        cls.simulator_log = NodeLog("/gazebo")
        spawn_m2wr(cls.gazebo, x=0.0, y=0.0)
        spawn_crate(cls.gazebo, x=3.0, y=0.0)
        cls.gazebo.wait_sim(0.5)

    def test_zero_quaternion_moves_the_model_upright_as_gazebo_normalizes_it(self):
        answer = self.gazebo.set_model_state(ModelState("crate", pose(3.0, 2.0, 0.15, (0, 0, 0, 0)),
                                                        Twist(), ""))
        self.assertTrue(answer.success, answer.status_message)
        self.assertEqual(answer.status_message, "SetModelState: set model state done")
        state = self.gazebo.get_model_state("crate", "")
        self.assertAlmostEqual(state.pose.position.y, 2.0, places=2)
        q = state.pose.orientation
        self.assertAlmostEqual(abs(q.w), 1.0, places=2)

    def test_state_relative_to_another_model_and_a_link(self):
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, 0.0, 0.15), Twist(), ""))
        m2wr = self.gazebo.get_model_state("m2wr", "")
        relative = self.gazebo.get_model_state("crate", "m2wr")
        self.assertTrue(relative.success, relative.status_message)
        self.assertEqual(relative.header.frame_id, "m2wr")
        self.assertAlmostEqual(relative.pose.position.x, 3.0 - m2wr.pose.position.x, places=1)
        by_link = self.gazebo.get_model_state("crate", "m2wr::link_chassis")
        self.assertTrue(by_link.success, by_link.status_message)
        self.assertAlmostEqual(by_link.pose.position.x, relative.pose.position.x, places=2)

    def test_set_model_state_in_a_reference_frame(self):
        m2wr = self.gazebo.get_model_state("m2wr", "")
        answer = self.gazebo.set_model_state(ModelState("crate", pose(2.0, 0.0, 0.05), Twist(),
                                                        "m2wr"))
        self.assertTrue(answer.success, answer.status_message)
        crate = self.gazebo.get_model_state("crate", "m2wr")
        self.assertAlmostEqual(crate.pose.position.x, 2.0, places=1)
        self.assertAlmostEqual(crate.pose.position.y, 0.0, places=1)
        del m2wr

    def test_a_twist_sets_the_velocity(self):
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, -3.0, 1.0), Twist(), ""))
        twist = Twist(Vector3(0.0, 0.0, 2.0), Vector3())
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, -3.0, 1.0), twist, ""))
        state = self.gazebo.get_model_state("crate", "")
        self.assertGreater(state.twist.linear.z, 1.0)     # thrown up (gravity slows it)
        self.gazebo.wait_sim(0.1)
        self.assertGreater(self.gazebo.get_model_state("crate", "").pose.position.z, 1.05)

    def test_link_state_of_a_wheel_and_set_link_state_of_the_crate(self):
        wheel = self.gazebo.get_link_state("m2wr::link_left_wheel", "")
        self.assertTrue(wheel.success, wheel.status_message)
        self.assertEqual(wheel.status_message, "GetLinkState: got state")
        chassis = self.gazebo.get_link_state("m2wr::link_chassis", "")
        relative = self.gazebo.get_link_state("m2wr::link_left_wheel", "m2wr::link_chassis")
        self.assertAlmostEqual(abs(relative.link_state.pose.position.y), 0.15, places=2)
        self.assertAlmostEqual(relative.link_state.pose.position.z, 0.0, places=2)
        del chassis
        answer = self.gazebo.set_link_state(LinkState("crate::body", pose(5.0, 5.0, 0.15),
                                                      Twist(), ""))
        self.assertTrue(answer.success, answer.status_message)
        self.assertAlmostEqual(self.gazebo.get_model_state("crate", "").pose.position.x, 5.0,
                               places=2)

    def test_the_state_topics_move_models_and_links(self):
        publisher = rospy.Publisher("/gazebo/set_model_state", ModelState, queue_size=1)
        wait_until(publisher.get_num_connections, 10, "the simulator's subscription")
        publisher.publish(ModelState("crate", pose(-2.0, 4.0, 0.15), Twist(), "world"))
        wait_until(lambda: abs(self.gazebo.get_model_state("crate", "").pose.position.y - 4.0)
                   < 0.01, 10, "the crate moved by /gazebo/set_model_state")
        links = rospy.Publisher("/gazebo/set_link_state", LinkState, queue_size=1)
        wait_until(links.get_num_connections, 10, "the simulator's subscription")
        links.publish(LinkState("crate::body", pose(-2.0, -4.0, 0.15), Twist(), ""))
        wait_until(lambda: abs(self.gazebo.get_model_state("crate", "").pose.position.y + 4.0)
                   < 0.01, 10, "the crate moved by /gazebo/set_link_state")

    def test_model_states_and_link_states_list_every_model_and_link(self):
        models = wait_for_message("/gazebo/model_states", ModelStates)
        self.assertEqual(sorted(models.name), ["crate", "ground_plane", "m2wr"])
        index = models.name.index("m2wr")
        direct = self.gazebo.get_model_state("m2wr", "").pose
        self.assertAlmostEqual(models.pose[index].position.x, direct.position.x, places=2)
        links = wait_for_message("/gazebo/link_states", LinkStates)
        self.assertEqual(sorted(links.name), ["crate::body", "ground_plane::link",
                                              "m2wr::link_chassis", "m2wr::link_left_wheel",
                                              "m2wr::link_right_wheel"])
        # a teleported model shows up where it was put
        self.gazebo.set_model_state(ModelState("crate", pose(1.0, 7.0, 0.15), Twist(), ""))

        def crate_y():
            states = wait_for_message("/gazebo/model_states", ModelStates)
            return states.pose[states.name.index("crate")].position.y
        wait_until(lambda: abs(crate_y() - 7.0) < 0.01, 10,
                   "/gazebo/model_states showing the crate's new pose")

    def test_bad_input_is_answered_and_changes_nothing(self):
        self.gazebo.pause_physics()               # nothing moves but what a request moves
        self.addCleanup(self.gazebo.unpause_physics)
        before = self.gazebo.snapshot()
        nan = float("nan")
        cases = [
            (self.gazebo.get_model_state, ("ghost", ""), "model 'ghost' does not exist"),
            (self.gazebo.get_model_state, ("m2wr", "nowhere"), "'nowhere'"),
            (self.gazebo.get_model_state, ("", ""), "model '' does not exist"),
            (self.gazebo.set_model_state, (ModelState("ghost", pose(), Twist(), ""),),
             "model 'ghost' does not exist"),
            (self.gazebo.set_model_state, (ModelState("crate", pose(nan, 0, 0), Twist(), ""),),
             "non-finite"),
            (self.gazebo.set_model_state, (ModelState("crate", pose(), Twist(Vector3(math.inf, 0, 0),
                                                                              Vector3()), ""),),
             "non-finite"),
            (self.gazebo.set_model_state, (ModelState("crate", pose(), Twist(), "nowhere"),),
             "reference frame 'nowhere'"),
            (self.gazebo.get_link_state, ("m2wr::ghost", ""), "link 'm2wr::ghost' does not exist"),
            (self.gazebo.get_link_state, ("", ""), "link '' does not exist"),
            (self.gazebo.set_link_state, (LinkState("crate::body", pose(0, nan, 0), Twist(), ""),),
             "non-finite"),
            (self.gazebo.set_link_state, (LinkState("m2wr::link_left_wheel", pose(), Twist(), ""),),
             "root link only"),
            (self.gazebo.set_link_state, (LinkState("crate::lid", pose(), Twist(), ""),),
             "link 'crate::lid' does not exist"),
            (self.gazebo.set_link_state, (LinkState("", pose(), Twist(), ""),),
             "link '' does not exist"),
            (self.gazebo.set_link_state, (LinkState("crate::body", pose(3, 0, 0.15), Twist(),
                                                    "nowhere"),), "reference frame 'nowhere'"),
            (self.gazebo.set_link_state, (LinkState("crate::body", pose(3, 0, 0.15),
                                                    Twist(Vector3(), Vector3(0, 0, math.inf)),
                                                    ""),), "non-finite"),
            (self.gazebo.get_link_state, ("crate::body", "nowhere"), "reference frame 'nowhere'"),
        ]
        for call, args, message in cases:
            answer = call(*args)
            self.assertFalse(answer.success, (args, answer.status_message))
            self.assertIn(message, answer.status_message, args)
        self.assertEqual(self.gazebo.snapshot(), before)
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(0.05)                       # the simulation goes on

    def test_bad_messages_on_the_state_topics_are_dropped_with_a_warning(self):
        models = rospy.Publisher("/gazebo/set_model_state", ModelState, queue_size=10)
        links = rospy.Publisher("/gazebo/set_link_state", LinkState, queue_size=10)
        wait_until(lambda: models.get_num_connections() > 0 and links.get_num_connections() > 0,
                   10, "the simulator's subscriptions to both state topics")
        self.gazebo.pause_physics()
        self.addCleanup(self.gazebo.unpause_physics)
        before = self.gazebo.snapshot()
        nan = float("nan")
        messages = [
            (models, ModelState("ghost", pose(), Twist(), ""),
             "/gazebo/set_model_state message ignored: model 'ghost' does not exist"),
            (models, ModelState("crate", pose(nan, 0.0, 0.15), Twist(), ""),
             "model state of 'crate' is not finite"),
            (links, LinkState("crate::lid", pose(), Twist(), ""),
             "/gazebo/set_link_state message ignored: link 'crate::lid' does not exist"),
            (links, LinkState("crate::body", pose(0.0, 0.0, 0.15), Twist(), "nowhere"),
             "reference frame 'nowhere'"),
        ]
        for publisher, message, warning in messages:     # each reason said, none throttled
            publisher.publish(message)
            wait_until(lambda: any(warning in text for _, text in self.simulator_log.since(0)),
                       10, "the simulator's warning '%s'" % warning)
        self.assertEqual(self.gazebo.snapshot(), before)
        self.gazebo.unpause_physics()
        self.gazebo.wait_sim(0.05)                       # the simulation goes on


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "api_states", States)
