#!/usr/bin/env python3
"""rostest: with a master but no simulator, spawn_model fails within 10 s (Gazebo's own client
waits for ever) and tells the user to start the world."""
import subprocess
import time
import unittest

import rospy
import rostest


def spawn(param, *extra):
    """Runs our spawn_model client on a description parameter; returns the finished process."""
    return subprocess.run(["rosrun", "pybullet_gazebo", "spawn_model", "-urdf", "-param", param,
                           "-model", "m2wr"] + list(extra),
                          capture_output=True, text=True, timeout=40)


class SpawnWithoutSimulatorTest(unittest.TestCase):
    def test_gives_up_within_ten_seconds_and_says_what_to_do(self):
        started = time.monotonic()
        result = spawn("robot_description", "-y", "8")
        elapsed = time.monotonic() - started
        self.assertEqual(result.returncode, 1)
        self.assertIn("within 10 s", result.stderr)        # its own wait: the default 10 s
        # it gives up, where Gazebo's client waits for ever; the bound leaves room for a
        # Python start-up on a loaded machine (seen: 4.3 s beside the other test streams)
        self.assertLess(elapsed, 30.0)
        self.assertIn("launch_world.launch", result.stderr)
        self.assertIn("start the world", result.stderr)

    def test_empty_description_is_refused(self):
        rospy.set_param("/empty_description", "")
        result = spawn("empty_description")
        self.assertEqual(result.returncode, 1)
        self.assertIn("empty", result.stderr)

    def test_malformed_description_is_refused_with_its_line(self):
        rospy.set_param("/broken_description", "<robot name='m2wr'>\n<link name='a'>\n</robot>")
        result = spawn("broken_description")
        self.assertEqual(result.returncode, 1)
        self.assertIn("not valid XML (line 3", result.stderr)


if __name__ == "__main__":
    rospy.init_node("test_spawn_without_simulator")
    rostest.rosrun("m2wr_description", "spawn_without_simulator", SpawnWithoutSimulatorTest)
