#!/usr/bin/env python3
"""rostest, Gazebo's physics properties as a Gazebo user sees them (empty world, real time, an
SDF crate): get/set_physics_properties with time_step, max_update_rate (0 = as fast as
possible) and gravity; ODE settings refused (Bullet physics); the physics dynamic_reconfigure
server; bad input answered success false, naming the input, nothing changed (through
dynamic_reconfigure, which has no status: the values kept and a warning naming them)."""
import os
import sys
import time
import unittest

import rospy
import rostest
from dynamic_reconfigure.client import Client
from gazebo_msgs.msg import ModelState, ODEPhysics
from geometry_msgs.msg import Twist, Vector3

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gazebo_api_client import Gazebo, pose, spawn_crate   # noqa: E402
from pybullet_gazebo.ros.testing import NodeLog, wait_until   # noqa: E402

EARTH = Vector3(0.0, 0.0, -9.8)


class Physics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_api_physics")
        cls.gazebo = Gazebo()
        cls.simulator_log = NodeLog("/gazebo")
        spawn_crate(cls.gazebo, x=3.0)
        cls.initial = cls.gazebo.get_physics_properties()

    def tearDown(self):
        self.gazebo.set_physics_properties(self.initial.time_step, self.initial.max_update_rate,
                                           EARTH, self.initial.ode_config)

    def sim_per_wall(self, wall=1.0):
        start_sim, start_wall = self.gazebo.sim_time(), time.monotonic()
        time.sleep(wall)
        return (self.gazebo.sim_time() - start_sim) / (time.monotonic() - start_wall)

    def test_initial_properties(self):
        now = self.initial
        self.assertTrue(now.success, now.status_message)
        self.assertAlmostEqual(now.time_step, 0.005)            # launch's max_step_size
        self.assertAlmostEqual(now.max_update_rate, 200.0)      # real time: 1 / 0.005 s
        self.assertEqual((now.gravity.x, now.gravity.y, now.gravity.z), (0.0, 0.0, -9.8))
        self.assertFalse(now.pause)
        self.assertEqual(now.ode_config.sor_pgs_iters, 50)      # Gazebo's default, no effect

    def test_gravity_and_time_step_change_as_in_gazebo(self):
        answer = self.gazebo.set_physics_properties(0.002, 500.0, Vector3(0, 0, -1.62),
                                                    self.initial.ode_config)
        self.assertTrue(answer.success, answer.status_message)
        self.assertEqual(answer.status_message, "physics engine updated")
        now = self.gazebo.get_physics_properties()
        self.assertAlmostEqual(now.time_step, 0.002)
        self.assertAlmostEqual(now.max_update_rate, 500.0)
        self.assertAlmostEqual(now.gravity.z, -1.62)
        before = self.gazebo.sim_time()
        self.gazebo.set_model_state(ModelState("crate", pose(3.0, 0.0, 2.0), Twist(), ""))
        self.gazebo.wait_sim(0.5)
        fallen = 2.0 - self.gazebo.get_model_state("crate", "").pose.position.z
        self.assertGreater(fallen, 0.15)                # moon: 0.2 m in 0.5 s (earth: 1.2 m)
        self.assertLess(fallen, 0.45)
        self.assertGreater(self.gazebo.sim_time(), before)      # time ran on, no jump back

    def test_max_update_rate_paces_the_simulation(self):
        self.gazebo.set_physics_properties(0.005, 100.0, EARTH, ODEPhysics())   # half speed
        self.assertLess(self.sim_per_wall(), 0.65)
        self.gazebo.set_physics_properties(0.005, 0.0, EARTH, ODEPhysics())     # unlimited
        self.assertAlmostEqual(self.gazebo.get_physics_properties().max_update_rate, 0.0)
        self.assertGreater(self.sim_per_wall(), 1.5)

    def test_ode_settings_are_refused_and_nothing_changes(self):
        ode = self.initial.ode_config
        ode.sor_pgs_iters = 100
        answer = self.gazebo.set_physics_properties(0.001, 1000.0, EARTH, ode)
        self.assertFalse(answer.success)
        self.assertIn("sor_pgs_iters 100", answer.status_message)
        self.assertIn("no meaning", answer.status_message)
        self.assertAlmostEqual(self.gazebo.get_physics_properties().time_step, 0.005)

    def test_dynamic_reconfigure_changes_gravity_and_keeps_ode_values(self):
        client = Client("/gazebo", timeout=10)
        config = client.update_configuration({"gravity_z": -3.0, "sor_pgs_iters": 7})
        self.assertAlmostEqual(config["gravity_z"], -3.0)
        self.assertEqual(config["sor_pgs_iters"], 50)
        self.assertAlmostEqual(self.gazebo.get_physics_properties().gravity.z, -3.0)
        self.assertAlmostEqual(rospy.get_param("/gazebo/gravity_z"), -3.0)
        client.close()

    def test_bad_input_is_answered_and_changes_nothing(self):
        nan = float("nan")
        cases = [((0.0, 200.0, EARTH), "time_step 0.0"), ((-0.001, 200.0, EARTH), "time_step"),
                 ((nan, 200.0, EARTH), "time_step nan"), ((0.005, -5.0, EARTH), "max_update_rate"),
                 ((0.005, nan, EARTH), "max_update_rate"),
                 ((0.005, 200.0, Vector3(0, nan, 0)), "gravity"),
                 ((float("inf"), 200.0, EARTH), "time_step inf"),
                 ((2.0, 200.0, EARTH), "time_step 2.0 must be in (0, 1] s"),
                 ((0.005, float("inf"), EARTH), "max_update_rate inf"),
                 ((0.005, 200.0, Vector3(0, 0, -float("inf"))), "gravity")]
        for args, message in cases:
            answer = self.gazebo.set_physics_properties(*args, self.initial.ode_config)
            self.assertFalse(answer.success, args)
            self.assertIn(message, answer.status_message)
            now = self.gazebo.get_physics_properties()
            self.assertEqual((now.time_step, now.max_update_rate, now.gravity.z),
                             (0.005, 200.0, -9.8))
        self.gazebo.wait_sim(0.05)

    def test_dynamic_reconfigure_bad_values_change_nothing_and_are_named(self):
        client = Client("/gazebo", timeout=10)
        self.addCleanup(client.close)
        nan, inf = float("nan"), float("inf")
        cases = [({"time_step": 0.0}, "time_step 0.0 must be in (0, 1] s"),
                 ({"time_step": 5.0}, "time_step 5.0 must be in (0, 1] s"),
                 ({"time_step": nan}, "time_step nan must be finite"),
                 ({"max_update_rate": nan}, "max_update_rate nan must be finite"),
                 ({"gravity_z": inf}, "gravity_z inf must be finite")]   # not clamped to +100
        for change, warning in cases:
            config = client.update_configuration(change)
            self.assertEqual((config["time_step"], config["max_update_rate"],
                              config["gravity_z"]), (0.005, 200.0, -9.8), change)
            now = self.gazebo.get_physics_properties()
            self.assertEqual((now.time_step, now.max_update_rate, now.gravity.z),
                             (0.005, 200.0, -9.8), change)
            wait_until(lambda: any(warning in text for _, text in self.simulator_log.since(0)),
                       10, "%s: the simulator's warning '%s'" % (change, warning))
        self.gazebo.wait_sim(0.05)                       # the simulation goes on


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "api_physics", Physics)
