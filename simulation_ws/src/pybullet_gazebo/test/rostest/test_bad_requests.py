#!/usr/bin/env python3
"""rostest: malformed requests to the running stand-in (world02, m2wr at (0, 8)) never stop it.

Each bad service request answers success false with a reason naming the problem; each bad
spawn_model / spawn.launch invocation exits non-zero with a message on stderr and runs nothing
it was given as code. Afterwards the world holds the same models, m2wr has not moved, and
/clock still advances.
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import rospkg
import rospy
import rostest
from geometry_msgs.msg import Pose
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import (DeleteModel, GetModelState, GetWorldProperties, SetModelState,
                             SpawnModel)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reliability import ClockWatch, state   # noqa: E402
from pybullet_gazebo.ros.testing import service, wait_until_sim_time   # noqa: E402

SMALL = ("<robot name='s'><link name='base'><inertial><mass value='1'/><inertia ixx='0.01' "
         "iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial><collision><geometry>"
         "<box size='%s'/></geometry></collision></link></robot>")


def pose(x=2.0, y=7.0, z=0.5, q=(0.0, 0.0, 0.0, 1.0)):
    msg = Pose()
    msg.position.x, msg.position.y, msg.position.z = x, y, z
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = q
    return msg


def model_state(name="m2wr", frame="world", linear_x=0.0, angular_z=0.0, **pose_args):
    msg = ModelState(model_name=name, reference_frame=frame)
    msg.pose = pose(**dict(dict(x=0.0, y=8.0, z=0.2), **pose_args))
    msg.twist.linear.x, msg.twist.angular.z = linear_x, angular_z
    return msg


class BadRequestsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_bad_requests")
        cls.clock = ClockWatch()
        cls.spawn = service("/gazebo/spawn_urdf_model", SpawnModel, timeout=30)
        cls.spawn_sdf = service("/gazebo/spawn_sdf_model", SpawnModel)
        cls.delete = service("/gazebo/delete_model", DeleteModel)
        cls.get_state = service("/gazebo/get_model_state", GetModelState)
        cls.set_state = service("/gazebo/set_model_state", SetModelState)
        cls.properties = service("/gazebo/get_world_properties", GetWorldProperties)
        cls.m2wr_urdf = rospy.get_param("/robot_description")
        wait_until_sim_time(1.5, timeout=60)                  # m2wr spawned and settled
        cls.models = sorted(cls.properties().model_names)
        cls.m2wr = state()

    def assert_refused(self, answer, *words):
        self.assertFalse(answer.success, answer.status_message)
        for word in words:
            self.assertIn(word, answer.status_message)

    def assert_world_untouched(self):
        self.assertEqual(sorted(self.properties().model_names), self.models)
        _, x, y, z, yaw = state()
        _, x0, y0, z0, yaw0 = self.m2wr
        self.assertLess(math.hypot(x - x0, y - y0), 0.005)
        self.assertLess(abs(z - z0), 0.005)
        self.assertLess(abs(math.remainder(yaw - yaw0, math.tau)), 0.005)

    def assert_clock_advances(self):
        before, stamp = self.clock.count(), self.clock.latest()
        time.sleep(0.5)
        self.assertGreater(self.clock.count(), before)
        self.assertGreater(self.clock.latest(), stamp)

    def test_set_model_state_garbage(self):
        cases = [
            (model_state(x=math.nan), "non-finite"),
            (model_state(linear_x=math.inf), "non-finite"),
            (model_state(angular_z=1e160), "over 1e+06 m/s or rad/s"),
            (model_state(x=1e300), "over 1e+06 m from the origin"),
            (model_state(name="no_such_model"), "model 'no_such_model' does not exist"),
            (model_state(name=""), "model '' does not exist"),
            (model_state(frame="no_such_frame"), "'no_such_frame' does not exist"),
        ]
        for request, words in cases:
            self.assert_refused(self.set_state(request), "SetModelState: ", words)
        self.assert_world_untouched()
        self.assert_clock_advances()

    def test_get_and_delete_unknown_models(self):
        self.assert_refused(self.get_state("no_such_model", ""), "GetModelState: ",
                            "'no_such_model' does not exist")
        self.assert_refused(self.get_state("m2wr", "no frame at all"),
                            "'no frame at all' does not exist")
        self.assert_refused(self.delete("no_such_model"), "DeleteModel: ",
                            "'no_such_model' does not exist")
        self.assert_refused(self.delete(""), "model '' does not exist")
        self.assert_world_untouched()
        self.assert_clock_advances()

    def test_spawn_garbage(self):
        urdf = self.m2wr_urdf
        cases = [
            (("other", urdf, "", pose(), "no_such_frame"),
             ["reference_frame not found", "'no_such_frame' does not exist"]),
            (("other", urdf, "", pose(x=math.nan), ""), ["not finite"]),
            (("other", urdf, "", pose(q=(0, 0, 0, 1e-200)), ""), ["zero quaternion"]),
            (("other", urdf, "", pose(z=-5.0), ""), ["under ground_plane"]),
            (("other", urdf, "", pose(x=1e300), ""), ["over 1e+06 m"]),
            (("m2wr", urdf, "", pose(), ""), ["already exists"]),
            (("", urdf, "", pose(), ""), ["model name is empty"]),
            (("other", "", "", pose(), ""), ["empty"]),
            (("other", "<robot name='x'/>", "", pose(), ""), ["has no <link>"]),
            (("other", SMALL % "a b c", "", pose(), ""), ["size=\"a b c\"", "expected 3"]),
            (("other", SMALL % "nan 1 1", "", pose(), ""), ["size=\"nan 1 1\""]),
            (("other", "<sdf version='1.6'><model name='a'/></sdf>", "", pose(), ""),
             ["entity format is invalid", "is not a URDF"]),
            (("other", "<" * 1000000, "", pose(), ""), ["does not parse as XML"]),
        ]
        for request, words in cases:
            self.assert_refused(self.spawn(*request), *words)
        self.assert_refused(self.spawn_sdf("other", "<sdf/>", "", pose(), ""), "no <model>")
        self.assert_world_untouched()
        self.assert_clock_advances()

    def test_spawn_inside_an_obstacle_is_spawned_as_gazebo_does(self):
        """Not refused (Gazebo spawns a model that overlaps another; a warning names both)."""
        answer = self.spawn("inside", self.m2wr_urdf, "", pose(x=-0.94, y=4.73, z=0.2), "")
        self.assertTrue(answer.success, answer.status_message)
        self.assertTrue(self.delete("inside").success)
        self.assert_world_untouched()
        self.assert_clock_advances()

    def test_spawn_clients_with_bad_arguments_exit_1_and_run_nothing(self):
        scratch = tempfile.mkdtemp(prefix="bad_requests_")
        self.addCleanup(shutil.rmtree, scratch, ignore_errors=True)
        not_a_robot = os.path.join(scratch, "not_a_robot.urdf")
        with open(not_a_robot, "w") as out:
            out.write("<foo/>")
        rospy.set_param("/a_number", 5)
        client = ["rosrun", "pybullet_gazebo", "spawn_model", "-urdf", "-model", "other"]
        marker = os.path.join(scratch, "ran")
        cases = {
            "missing file": (client + ["-file", os.path.join(scratch, "nope.urdf")],
                             ["cannot read -file"]),
            "not a robot": (client + ["-file", not_a_robot], ["root element is <foo>"]),
            "raw xacro": (client + ["-file", os.path.join(rospkg.RosPack().get_path(
                "m2wr_description"), "urdf", "m2wr.xacro")], ["it is a xacro file"]),
            "number param": (client + ["-param", "/a_number"], ["/a_number is empty"]),
            "zero timeout": (client + ["-param", "robot_description", "-timeout", "0"],
                             ["-timeout 0 must be a positive number"]),
            "infinite x": (client + ["-param", "robot_description", "-x", "1e400"],
                           ["-x '1e400' is not a finite number"]),
            "code as x": (client + ["-param", "robot_description", "-x",
                                    "__import__('os').system('touch %s')" % marker],
                          ["is not a number"]),
            "eval in launch": (["roslaunch", "m2wr_description", "spawn.launch",
                                "x:=$(eval __import__('os').system('touch %s'))" % marker],
                               ["RLException", "substitution args"]),
            "shell in launch": (["roslaunch", "m2wr_description", "spawn.launch",
                                 "y:=0; touch %s" % marker],     # split into words, no shell
                                ["unrecognized arguments: touch", "process has died"]),
        }
        running = {name: subprocess.Popen(command, stdout=subprocess.PIPE,
                                          stderr=subprocess.STDOUT, text=True)
                   for name, (command, _) in cases.items()}
        for name, process in running.items():
            output, _ = process.communicate(timeout=60)
            for words in cases[name][1]:
                self.assertIn(words, output, "%s: %s" % (name, output))
            if name.startswith("eval") or not name.endswith("launch"):
                self.assertNotEqual(process.returncode, 0, name)
        self.assertFalse(os.path.exists(marker))
        self.assert_world_untouched()
        self.assert_clock_advances()


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "bad_requests", BadRequestsTest)
