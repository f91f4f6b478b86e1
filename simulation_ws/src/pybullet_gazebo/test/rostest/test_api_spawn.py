#!/usr/bin/env python3
"""rostest, Gazebo's spawn and delete services as a Gazebo user sees them (empty world):
spawn_urdf_model (m2wr), spawn_sdf_model (an SDF crate, also a URDF as Gazebo takes; through
spawn_model -sdf from a file and from -database), a
reference frame, a model spawned inside another (spawned, with a warning), delete_model; a
duplicate name, XML that does not parse, a NaN pose, an unknown frame, an SDF sent to
spawn_urdf_model and an empty name answered success false, the world unchanged."""
import os
import subprocess
import sys
import tempfile
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gazebo_api_client import CRATE_SDF, Gazebo, m2wr_urdf, pose   # noqa: E402
from pybullet_gazebo.ros.testing import NodeLog, wait_until   # noqa: E402


class SpawnDelete(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_api_spawn")
        cls.gazebo = Gazebo()
        cls.simulator_log = NodeLog("/gazebo")
        answer = cls.gazebo.spawn_urdf_model("m2wr", m2wr_urdf(), "", pose(0, 0, 0.1), "")
        assert answer.success, answer.status_message
        cls.first = answer

    def names(self):
        return sorted(self.gazebo.get_world_properties().model_names)

    def test_urdf_spawn_answers_as_gazebo(self):
        self.assertEqual(self.first.status_message, "SpawnModel: Successfully spawned entity")
        self.assertIn("m2wr", self.names())

    def test_sdf_spawn_in_a_reference_frame_and_delete(self):
        self.gazebo.pause_physics()               # m2wr may still roll after another test
        self.addCleanup(self.gazebo.unpause_physics)
        answer = self.gazebo.spawn_sdf_model("crate_rel", CRATE_SDF, "", pose(2.0, 1.0, 0.05),
                                             "m2wr")
        self.assertTrue(answer.success, answer.status_message)
        state = self.gazebo.get_model_state("crate_rel", "m2wr")
        self.assertAlmostEqual(state.pose.position.x, 2.0, places=1)
        self.assertAlmostEqual(state.pose.position.y, 1.0, places=1)
        deleted = self.gazebo.delete_model("crate_rel")
        self.assertTrue(deleted.success)
        self.assertEqual(deleted.status_message, "DeleteModel: successfully deleted model")
        self.assertNotIn("crate_rel", self.names())

    def test_spawn_sdf_model_takes_a_urdf_as_gazebo_does(self):
        answer = self.gazebo.spawn_sdf_model("m2wr_b", m2wr_urdf(), "", pose(0, 5, 0.1), "")
        self.assertTrue(answer.success, answer.status_message)
        self.assertIn("m2wr_b", self.names())
        self.gazebo.delete_model("m2wr_b")

    def test_spawn_model_client_spawns_sdf_from_a_file_and_from_the_database(self):
        with tempfile.NamedTemporaryFile("w", suffix=".sdf", delete=False) as sdf:
            sdf.write(CRATE_SDF)
        self.addCleanup(os.unlink, sdf.name)
        for args, name in ((["-file", sdf.name], "crate_file"), (["-database", "coke_can"], "can")):
            result = subprocess.run(["rosrun", "pybullet_gazebo", "spawn_model", "-sdf", "-model",
                                     name, "-x", "4", "-y", "-4"] + args,
                                    capture_output=True, text=True, timeout=60)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn(name, self.names())
            self.assertTrue(self.gazebo.delete_model(name).success)

    def test_a_model_inside_another_is_spawned(self):
        answer = self.gazebo.spawn_sdf_model("crate_in", CRATE_SDF, "", pose(0.0, 0.0, 0.1), "")
        self.assertTrue(answer.success, answer.status_message)
        self.assertIn("crate_in", self.names())
        self.assertIn("m2wr", self.names())
        warning = "puts 'crate_in' inside 'm2wr'; spawned anyway, as Gazebo does"
        wait_until(lambda: any(warning in text for _, text in self.simulator_log.since(0)),
                   10, "the simulator's warning '%s'" % warning)
        self.gazebo.wait_sim(0.3)                 # physics pushes them apart; both stay sane
        self.assertTrue(self.gazebo.get_model_state("m2wr", "").success)
        self.gazebo.delete_model("crate_in")

    def test_bad_requests_are_refused_and_the_world_unchanged(self):
        self.gazebo.pause_physics()
        self.addCleanup(self.gazebo.unpause_physics)
        before = self.gazebo.snapshot()
        nan = float("nan")
        urdf = m2wr_urdf()
        cases = [
            (self.gazebo.spawn_urdf_model, ("m2wr", urdf, "", pose(5, 5, 0.1), ""),
             "entity already exists"),
            (self.gazebo.spawn_sdf_model, ("m2wr", CRATE_SDF, "", pose(5, 5, 0.1), ""),
             "entity already exists"),
            (self.gazebo.spawn_urdf_model, ("bad", "<robot name='x'><link", "", pose(5, 5, 1), ""),
             "does not parse"),
            (self.gazebo.spawn_sdf_model, ("bad", "<sdf><model name='x'>", "", pose(5, 5, 1), ""),
             "does not parse"),
            (self.gazebo.spawn_sdf_model, ("bad", "<box/>", "", pose(5, 5, 1), ""),
             "not SDF or URDF"),
            (self.gazebo.spawn_urdf_model, ("bad", CRATE_SDF, "", pose(5, 5, 1), ""),
             "entity format is invalid"),
            (self.gazebo.spawn_sdf_model, ("bad", CRATE_SDF, "", pose(nan, 5, 1), ""),
             "not finite"),
            (self.gazebo.spawn_urdf_model, ("bad", urdf, "", pose(5, float("inf"), 1), ""),
             "not finite"),
            (self.gazebo.spawn_sdf_model, ("bad", CRATE_SDF, "", pose(5, 5, 1), "nowhere"),
             "reference_frame not found"),
            (self.gazebo.spawn_sdf_model, ("", CRATE_SDF, "", pose(5, 5, 1), ""),
             "model name is empty"),
            (self.gazebo.spawn_sdf_model, ("bad", "", "", pose(5, 5, 1), ""),
             "model_xml is empty"),
            (self.gazebo.spawn_sdf_model, ("bad", CRATE_SDF, "", pose(5, 5, 1, (nan, 0, 0, 1)),
                                           ""), "not finite"),
            (self.gazebo.delete_model, ("ghost",), "model 'ghost' does not exist"),
            (self.gazebo.delete_model, ("",), "model '' does not exist"),
        ]
        for call, args, message in cases:
            answer = call(*args)
            self.assertFalse(answer.success, (args[0], answer.status_message))
            self.assertIn(message, answer.status_message, args[0])
        self.assertEqual(self.gazebo.snapshot(), before)


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "api_spawn", SpawnDelete)
