#!/usr/bin/env python3
"""rostest: the ROS-connected environment and the in-process one agree.

Both start m2wr at (0, 8, yaw 0) in world02 with a noiseless laser and take the same 60
actions (6 s of sim time: straight, turning while driving, turning in place, straight).
Tolerances, per step: position 1 mm, heading 1 mrad, regions 1 mm; sim times equal. Then
both drive north into a barrier: the touch (/gazebo/contacts over ROS) ends the episode at
the same step, with the same penalty.
Both run the same engine with the same 5 ms step, the commands reach the drive at the same
sim time (lockstep) and the ROS pose is /odom's stamped with the same sim time as the scan,
so the only possible difference is how m2wr got to its start (the ROS one is reset and
teleported by set_model_state, which zeroes its velocities and joints; the in-process one is
spawned there in a fresh world): Bullet's contact cache. Measured: 0 to 1e-4 m. A step
taken at a different sim time would show at once: 1 mm is 2 ms of driving at 0.5 m/s.
"""
import math
import time
import unittest

import numpy as np
import rospy
import rostest
from std_srvs.srv import Empty

from m2wr_gym.env import M2wrEnv
from m2wr_gym.sim_ros import RosSimError

KWARGS = dict(world="world02", start=[(0.0, 8.0, 0.0)], action="continuous", laser_noise=0.0)
ACTIONS = ([(0.5, 0.0)] * 15 + [(0.3, 0.6)] * 15 + [(0.0, -0.8)] * 15 + [(0.5, 0.0)] * 15)
# facing north from (0, 8), straight on into world02's jersey_barrier_0 (in process: the
# touch ends the episode at the 12th step, y = 8.56)
INTO_A_WALL = dict(KWARGS, start=[(0.0, 8.0, math.pi / 2)])


def until_the_end(env, steps=40):
    """(touched, terminated, reward) of each step, driving straight on, until the end."""
    env.reset(seed=0)
    trace = []
    for _ in range(steps):
        _, reward, terminated, truncated, info = env.step(np.array((0.5, 0.0), np.float32))
        trace.append((info["touched"], terminated, round(float(reward), 4)))
        if terminated or truncated:
            break
    env.close()
    return trace


def rollout(env):
    obs, info = env.reset(seed=0)
    trace = [(obs, info)]
    for action in ACTIONS:
        obs, _, terminated, truncated, info = env.step(np.array(action, np.float32))
        trace.append((obs, info))
        if terminated or truncated:
            break
    env.close()
    return trace


class RosMatchesInProcess(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_ros_matches_inprocess")
        cls.ros = rollout(M2wrEnv(backend="ros", **KWARGS))
        # the second run's environment is made while the world runs on unpaused from sim
        # time 0 (another program reset and unpaused it): the scans it sends meanwhile carry
        # the stamps of the run's own after its reset, and must not be taken for them
        again = M2wrEnv(backend="ros", **KWARGS)
        rospy.ServiceProxy("/gazebo/reset_simulation", Empty)()
        rospy.ServiceProxy("/gazebo/unpause_physics", Empty)()
        time.sleep(0.5)
        cls.ros_again = rollout(again)
        cls.local = rollout(M2wrEnv(**KWARGS))
        cls.ros_touch = until_the_end(M2wrEnv(backend="ros", **INTO_A_WALL))
        cls.local_touch = until_the_end(M2wrEnv(**INTO_A_WALL))

    def test_same_number_of_steps_of_exactly_dt(self):
        self.assertEqual(len(self.ros), len(ACTIONS) + 1)
        self.assertEqual(len(self.local), len(ACTIONS) + 1)
        times = [info["sim_time"] for _, info in self.ros]
        self.assertTrue(np.allclose(np.diff(times), 0.1, atol=1e-9), times[:5])
        self.assertTrue(np.allclose(times, [info["sim_time"] for _, info in self.local], atol=1e-9))

    def check_close(self, a, b, label):
        worst = (0.0, 0.0, 0.0, None)
        for k, ((obs_a, info_a), (obs_b, info_b)) in enumerate(zip(a, b)):
            dp = math.hypot(info_a["x"] - info_b["x"], info_a["y"] - info_b["y"])
            dyaw = abs(math.atan2(math.sin(info_a["yaw"] - info_b["yaw"]),
                                  math.cos(info_a["yaw"] - info_b["yaw"])))
            dobs = float(np.max(np.abs(obs_a - obs_b)))
            if dp > worst[0] or dyaw > worst[1] or dobs > worst[2]:
                worst = (max(dp, worst[0]), max(dyaw, worst[1]), max(dobs, worst[2]), k)
        rospy.loginfo("%s: worst position %.4f m, heading %.4f rad, regions %.4f m", label,
                      *worst[:3])
        self.assertLess(worst[0], 0.001, "%s: positions differ by %.4f m" % (label, worst[0]))
        self.assertLess(worst[1], 0.001, "%s: headings differ by %.4f rad" % (label, worst[1]))
        self.assertLess(worst[2], 0.001, "%s: regions differ by %.4f m" % (label, worst[2]))

    def test_trajectories_agree(self):
        self.check_close(self.ros, self.local, "ROS vs in process")
        end = self.local[-1][1]
        self.assertGreater(end["distance"], 1.8)                 # it really moved (1.95 m asked)
        self.assertLess(min(info["yaw"] for _, info in self.local), -0.6)   # and turned

    def test_ros_runs_repeat(self):
        self.check_close(self.ros, self.ros_again, "ROS run 1 vs 2")

    def test_a_touch_ends_the_episode_at_the_same_step_with_the_same_penalty(self):
        touched, terminated, _ = self.local_touch[-1]
        self.assertEqual((touched, terminated), (("jersey_barrier_0",), True), self.local_touch)
        self.assertLess(len(self.local_touch), 20, self.local_touch)
        self.assertEqual(self.ros_touch, self.local_touch)

    def test_a_turning_the_simulator_does_not_run_is_refused(self):
        """The simulator runs Noetic's drive (legacy_mode:=false): an environment that means
        Kinetic's turning would steer the wrong way, so it is refused, saying what to do."""
        with self.assertRaises(RosSimError) as caught:
            M2wrEnv(backend="ros", turning="legacy", **KWARGS)
        self.assertIn("legacy_mode:=false", str(caught.exception))
        self.assertIn("turning='gazebo'", str(caught.exception))


if __name__ == "__main__":
    rostest.rosrun("m2wr_gym", "ros_matches_inprocess", RosMatchesInProcess)
