#!/usr/bin/env python3
"""rostest: with the simulation running free, many times faster than real time, a
/gazebo/model_states subscriber gets at most max(watch_rate 30, model_states_rate 50) = 50
messages per wall second and a /joint_states subscriber (m2wr's wheels, 20 Hz of sim time)
at most 30, each message its own step's state, while /odom keeps every 1/20 s tick of sim
time (the drive's updateRate) with no gap."""
import time
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelStates
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from pybullet_gazebo.ros.testing import wait_for_message

WINDOW = 4.0                # [s] wall
BURST = 0.5                 # [s] wall: WallRateLimit.BURST
ODOM_PERIOD = 0.05          # [s] sim: m2wr's diff drive at 20 Hz


class WatchRateTest(unittest.TestCase):
    def test_watching_topics_held_to_the_wall_rate_and_odom_at_every_tick(self):
        rospy.init_node("test_watch_rate")
        wait_for_message("/odom", Odometry, timeout=40)                 # m2wr is in
        counts = {"model_states": 0, "joint_states": 0}
        joint_stamps, odom_stamps = [], []
        counting = [False]

        def count(name, stamps=None):
            def on_message(msg):
                if counting[0]:
                    counts[name] = counts.get(name, 0) + 1
                    if stamps is not None:
                        stamps.append(msg.header.stamp.to_sec())
            return on_message
        subscribers = [
            rospy.Subscriber("/gazebo/model_states", ModelStates, count("model_states"),
                             queue_size=1000),
            rospy.Subscriber("/joint_states", JointState, count("joint_states", joint_stamps),
                             queue_size=1000),
            rospy.Subscriber("/odom", Odometry, count("odom", odom_stamps), queue_size=10000),
        ]
        time.sleep(2.0)                                  # connected, the burst spent
        sim0 = rospy.get_time()
        counting[0] = True
        time.sleep(WINDOW)
        counting[0] = False
        sim_s = rospy.get_time() - sim0
        time.sleep(0.5)                                  # messages in flight arrive
        for subscriber in subscribers:
            subscriber.unregister()

        speed = sim_s / WINDOW
        self.assertGreater(speed, 3.0, "the simulation ran only %.1fx real time: too slow to "
                                       "tell a wall-time limit from the sim-time rate" % speed)
        # a token bucket: never more than the limit per wall second plus one burst
        self.assertLessEqual(counts["model_states"], 50 * (WINDOW + BURST) + 2, counts)
        self.assertGreater(counts["model_states"], 0, counts)
        self.assertLessEqual(counts["joint_states"], 30 * (WINDOW + BURST) + 2, counts)
        self.assertLess(counts["joint_states"], 0.5 * 20 * sim_s, "joint_states not limited")
        self.assertTrue(all(b > a for a, b in zip(joint_stamps, joint_stamps[1:])))
        # /odom: every tick of sim time, none skipped
        self.assertGreater(len(odom_stamps), 0.9 * sim_s / ODOM_PERIOD, counts)
        gaps = [b - a for a, b in zip(odom_stamps, odom_stamps[1:])]
        self.assertLess(max(gaps), 1.5 * ODOM_PERIOD, "an /odom tick was skipped")


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "watch_rate", WatchRateTest)
