#!/usr/bin/env python3
"""rostest, Gazebo's pause and reset services as a Gazebo user sees them (empty world, real
time, an SDF crate): pause_physics stops sim time and the world, unpause_physics starts them,
reset_world puts models back (time runs on), reset_simulation puts models and time back."""
import os
import sys
import time
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelState
from geometry_msgs.msg import Twist

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gazebo_api_client import Gazebo, pose, spawn_crate   # noqa: E402


class PauseReset(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_api_pause_reset")
        cls.gazebo = Gazebo()
        spawn_crate(cls.gazebo, x=3.0, y=1.0)
        cls.gazebo.wait_sim(0.5)

    def crate(self):
        return self.gazebo.get_model_state("crate", "").pose.position

    def test_pause_stops_time_and_the_world_and_unpause_starts_them(self):
        self.gazebo.pause_physics()
        self.assertTrue(self.gazebo.get_physics_properties().pause)
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, 1.0, 2.0), Twist(), ""))
        stopped = self.gazebo.sim_time()
        time.sleep(0.3)
        self.assertEqual(self.gazebo.sim_time(), stopped)
        self.assertAlmostEqual(self.crate().z, 2.0, places=6)   # hangs in the air
        self.gazebo.unpause_physics()
        self.assertFalse(self.gazebo.get_physics_properties().pause)
        self.gazebo.wait_sim(1.0)
        self.assertLess(self.crate().z, 0.3)

    def test_reset_world_puts_models_back_and_time_runs_on(self):
        self.gazebo.set_model_state(ModelState("crate", pose(-4.0, -4.0, 0.15), Twist(), ""))
        before = self.gazebo.sim_time()
        self.gazebo.reset_world()
        self.assertGreaterEqual(self.gazebo.sim_time(), before)
        spot = self.crate()
        self.assertAlmostEqual(spot.x, 3.0, places=2)
        self.assertAlmostEqual(spot.y, 1.0, places=2)

    def test_reset_simulation_puts_models_and_time_back(self):
        self.gazebo.wait_sim(0.5)
        self.gazebo.set_model_state(ModelState("crate", pose(-4.0, 4.0, 0.15), Twist(), ""))
        self.gazebo.reset_simulation()
        self.assertLess(self.gazebo.sim_time(), 0.3)
        self.assertAlmostEqual(self.crate().x, 3.0, places=2)
        self.gazebo.wait_sim(0.2)                              # and goes on from there


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "api_pause_reset", PauseReset)
