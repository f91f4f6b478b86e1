#!/usr/bin/env python3
"""rostest: with the simulation running at 6x real time (real_time_factor 6), this node
first only watches (/clock and /joint_states): it gets /clock every 1/50 s of sim time
(pub_clock_frequency 50) and at most max(watch_rate 30, 50) = 50 ticks per wall second. Then
it subscribes to /odom, as a controller would, and gets every tick the simulator sends: more
than 50 per sim second (/clock also goes out at each step with a reading) and far more than 50
per wall second."""
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from pybullet_gazebo.ros.testing import wait_for_message

WINDOW = 3.0                # [s] wall
BURST = 0.5                 # [s] wall: WallRateLimit.BURST
CLOCK_PERIOD = 0.02         # [s] sim: pub_clock_frequency 50


class ClockWatchersTest(unittest.TestCase):
    def ticks(self, window):
        """The /clock times [s sim] this node gets in `window` wall seconds."""
        times, counting = [], [False]

        def on_clock(msg):
            if counting[0]:
                times.append(msg.clock.to_sec())
        subscriber = rospy.Subscriber("/clock", Clock, on_clock, queue_size=100000)
        time.sleep(1.5)                                  # connected, the burst spent
        counting[0] = True
        time.sleep(window)
        counting[0] = False
        subscriber.unregister()
        return times

    def test_a_watcher_is_held_to_the_wall_rate_and_a_loop_node_gets_every_tick(self):
        rospy.init_node("test_clock_watchers")
        wait_for_message("/joint_states", JointState, timeout=40)      # m2wr is in

        watched = self.ticks(WINDOW)
        sim_s = watched[-1] - watched[0]
        self.assertGreater(sim_s / WINDOW, 3.0, "the simulation ran only %.1fx real time: too "
                           "slow to tell a wall-time limit from the sim-time rate"
                           % (sim_s / WINDOW))
        self.assertLessEqual(len(watched), 50 * (WINDOW + BURST) + 2)
        gaps = [b - a for a, b in zip(watched, watched[1:])]
        self.assertGreater(min(gaps), 0.99 * CLOCK_PERIOD, "closer than Gazebo's cadence")

        odometry = rospy.Subscriber("/odom", Odometry, lambda msg: None, queue_size=1)
        try:
            looped = self.ticks(WINDOW)
        finally:
            odometry.unregister()
        sim_s = looped[-1] - looped[0]
        self.assertGreater(len(looped), sim_s / CLOCK_PERIOD, "not every tick")
        self.assertGreater(len(looped), 3 * 50 * WINDOW, "still held to the wall rate")


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "clock_watchers", ClockWatchersTest)
