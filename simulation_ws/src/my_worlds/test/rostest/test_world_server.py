#!/usr/bin/env python3
"""rostest: `roslaunch my_worlds launch_world.launch` (world02, headless) behaves as Gazebo's
world server for the services a tutorial user calls."""
import os
import time
import unittest

import rospkg
import rospy
import rostest
from gazebo_msgs.msg import ModelState, ModelStates
from gazebo_msgs.srv import GetModelState, GetWorldProperties, SetModelState
from std_srvs.srv import Empty

from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.ros.testing import service, sim_time, wait_for_message, wait_until_sim_time

# world02 as the reference lays it out: ground, 16 perimeter barriers, 7 corner barrels,
# 6 interior barriers, 1 barrel and 1 coke can.
WORLD02_MODEL_COUNT = 1 + 16 + 7 + 6 + 1 + 1


class WorldServerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_world_server")
        service("/gazebo/pause_physics", Empty, timeout=30)
        wait_until_sim_time(0.1, timeout=30)

    def test_clock_advances(self):
        first = sim_time()
        time.sleep(0.3)
        second = sim_time()
        self.assertGreater(first, 0.0)
        self.assertGreater(second, first)

    def test_model_states_lists_every_model_of_world02(self):
        rospack = rospkg.RosPack()
        world = load_world(os.path.join(rospack.get_path("my_worlds"), "worlds", "world02.world"),
                           model_path_from_env(os.path.join(rospack.get_path("pybullet_gazebo"),
                                                            "models")))
        states = wait_for_message("/gazebo/model_states", ModelStates)
        self.assertEqual(len(world.models), WORLD02_MODEL_COUNT)
        self.assertEqual(sorted(states.name), sorted(m.name for m in world.models))
        properties = service("/gazebo/get_world_properties", GetWorldProperties)()
        self.assertEqual(sorted(properties.model_names), sorted(states.name))

    def test_pause_stops_sim_time_and_unpause_resumes_it(self):
        pause = service("/gazebo/pause_physics", Empty)
        unpause = service("/gazebo/unpause_physics", Empty)
        try:
            pause()
            time.sleep(0.2)                   # let the last /clock of the running world arrive
            paused_at = sim_time()
            time.sleep(0.5)
            self.assertEqual(sim_time(), paused_at)
        finally:
            unpause()
        wait_until_sim_time(paused_at + 0.2, timeout=10)

    def test_reset_simulation_sets_time_back(self):
        wait_until_sim_time(1.0, timeout=30)
        before = sim_time()
        service("/gazebo/reset_simulation", Empty)()
        time.sleep(0.05)
        self.assertLess(sim_time(), before)

    def test_get_and_set_model_state_round_trip(self):
        pause = service("/gazebo/pause_physics", Empty)
        unpause = service("/gazebo/unpause_physics", Empty)
        set_state = service("/gazebo/set_model_state", SetModelState)
        get_state = service("/gazebo/get_model_state", GetModelState)
        target = ModelState(model_name="coke_can", reference_frame="world")
        target.pose.position.x, target.pose.position.y, target.pose.position.z = 1.5, 2.5, 0.0
        target.pose.orientation.z, target.pose.orientation.w = 0.6, 0.8
        pause()
        try:
            answer = set_state(target)
            self.assertTrue(answer.success, answer.status_message)
            state = get_state("coke_can", "world")
        finally:
            unpause()
        self.assertTrue(state.success, state.status_message)
        for got, want in ((state.pose.position.x, 1.5), (state.pose.position.y, 2.5),
                          (state.pose.position.z, 0.0), (state.pose.orientation.z, 0.6),
                          (state.pose.orientation.w, 0.8)):
            self.assertAlmostEqual(got, want, places=6)
        missing = get_state("no_such_model", "world")
        self.assertFalse(missing.success)
        self.assertIn("no_such_model", missing.status_message)


if __name__ == "__main__":
    rostest.rosrun("my_worlds", "world_server", WorldServerTest)
