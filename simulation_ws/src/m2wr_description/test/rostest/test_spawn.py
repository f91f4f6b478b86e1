#!/usr/bin/env python3
"""rostest: spawn.launch y:=8 puts m2wr at (0, 8) in world02; bad spawns fail clearly and
leave the world and the first robot alone; a spawn inside an obstacle succeeds, as in Gazebo."""
import subprocess
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import DeleteModel
from sensor_msgs.msg import LaserScan

from pybullet_gazebo.ros.testing import model_pose, wait_for_message, wait_until_sim_time


def spawn(*args):
    """Runs our spawn_model client; returns (exit code, stderr)."""
    result = subprocess.run(["rosrun", "pybullet_gazebo", "spawn_model", "-urdf", "-param",
                             "robot_description"] + list(args),
                            capture_output=True, text=True, timeout=60)
    return result.returncode, result.stderr


class SpawnTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_spawn")
        wait_for_message("/m2wr/laser/scan", LaserScan, timeout=30)
        wait_until_sim_time(rospy.get_time() + 2.0)

    def test_1_spawned_at_y8_and_settled(self):
        x, y, yaw = model_pose("m2wr")
        self.assertAlmostEqual(x, 0.0, delta=0.05)
        self.assertAlmostEqual(y, 8.0, delta=0.05)
        self.assertAlmostEqual(yaw, 0.0, delta=0.05)

    def test_2_second_m2wr_fails_with_already_exists(self):
        before = model_pose("m2wr")
        code, stderr = spawn("-model", "m2wr", "-x", "3", "-y", "7")
        self.assertEqual(code, 1)
        self.assertIn("already exists", stderr)
        after = model_pose("m2wr")
        for a, b in zip(before, after):
            self.assertAlmostEqual(a, b, delta=0.01)

    def test_3_non_numeric_pose_is_refused_before_anything_happens(self):
        code, stderr = spawn("-model", "other", "-x", "__import__('os')")
        self.assertEqual(code, 1)
        self.assertIn("-x", stderr)
        self.assertIn("not a number", stderr)
        code, stderr = spawn("-model", "other", "-y", "nan")
        self.assertEqual(code, 1)
        self.assertIn("not a finite number", stderr)

    def test_4_pose_inside_an_obstacle_is_spawned_as_gazebo_does(self):
        # the middle barrier of interior row A stands at (-0.94, 4.73); Gazebo spawns a model
        # there (the simulator logs a warning naming both) and so does the stand-in
        before = model_pose("m2wr")
        code, stderr = spawn("-model", "stuck", "-x", "-0.94", "-y", "4.73", "-z", "0.2")
        self.assertEqual(code, 0, stderr)
        names = wait_for_message("/gazebo/model_states", ModelStates).name
        self.assertIn("stuck", names)
        self.assertIn("m2wr", names)
        deleted = rospy.ServiceProxy("/gazebo/delete_model", DeleteModel)("stuck")
        self.assertTrue(deleted.success, deleted.status_message)
        for a, b in zip(before, model_pose("m2wr")):
            self.assertAlmostEqual(a, b, delta=0.01)


if __name__ == "__main__":
    rostest.rosrun("m2wr_description", "spawn", SpawnTest)
