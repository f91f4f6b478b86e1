#!/usr/bin/env python3
"""rostest: `rosrun gazebo_ros spawn_model` (the shim, running pybullet_gazebo's client) with
gazebo_ros's flags, as a Gazebo user would call it, in the shim's default empty world.

Each case runs the client as a process and checks its exit code (0: the model is in the world;
1: it is not, with the reason on stderr) and what /gazebo/get_world_properties then lists
(and, for -J, -robot_namespace, -reference_frame and -R, the joint, topics and pose)."""
import math
import os
import signal
import subprocess
import tempfile
import time
import unittest

import rosgraph
import rospy
import rostest
from gazebo_msgs.srv import (GetJointProperties, GetModelState, GetWorldProperties,
                             SpawnModel)
from geometry_msgs.msg import Pose
from std_srvs.srv import Empty

from pybullet_gazebo.ros.testing import (model_pose, service, wait_until, wait_until_sim_time,
                                         yaw_of)

CLIENT = ["rosrun", "gazebo_ros", "spawn_model"]
CRATE = """<sdf version="1.6"><model name="crate"><link name="body">
  <inertial><mass>2.0</mass><inertia><ixx>0.05</ixx><iyy>0.05</iyy><izz>0.05</izz></inertia></inertial>
  <collision name="shell"><geometry><box><size>0.3 0.3 0.3</size></box></geometry></collision>
</link></model></sdf>"""


def models():
    answer = service("/gazebo/get_world_properties", GetWorldProperties)()
    return list(answer.model_names)


def spawn(*args, stdin=None):
    """Runs the client to the end; returns (exit code, stderr)."""
    result = subprocess.run(CLIENT + list(args), input=stdin, capture_output=True, text=True,
                            timeout=60)
    return result.returncode, result.stderr


def start(*args):
    """Starts the client in the background (its own process group)."""
    return subprocess.Popen(CLIENT + list(args), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


class SpawnFlagsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_spawn_flags")
        service("/gazebo/spawn_urdf_model", SpawnModel, timeout=30)
        cls.urdf = rospy.get_param("/robot_description")

    def test_default_world_is_gazebo_s_empty_world(self):
        self.assertEqual(models()[0], "ground_plane")

    def test_file_spawns_at_the_pose_and_a_missing_file_exits_1(self):
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as urdf:
            urdf.write(self.urdf)
        try:
            code, err = spawn("-urdf", "-file", urdf.name, "-model", "from_file", "-x", "3", "-y", "-2",
                              "-Y", "1.5")
        finally:
            os.unlink(urdf.name)
        self.assertEqual(code, 0, err)
        wait_until_sim_time(rospy.get_time() + 1.0)
        x, y, yaw = model_pose("from_file")
        self.assertAlmostEqual(x, 3.0, delta=0.05)
        self.assertAlmostEqual(y, -2.0, delta=0.05)
        self.assertAlmostEqual(yaw, 1.5, delta=0.05)
        code, err = spawn("-urdf", "-file", "/nonexistent/m2wr.urdf", "-model", "nothing")
        self.assertEqual(code, 1)
        self.assertIn("/nonexistent/m2wr.urdf", err)
        self.assertNotIn("nothing", models())

    def test_stdin_spawns_and_malformed_stdin_exits_1(self):
        code, err = spawn("-urdf", "-stdin", "-model", "from_stdin", "-x", "-3", stdin=self.urdf)
        self.assertEqual(code, 0, err)
        self.assertIn("from_stdin", models())
        code, err = spawn("-urdf", "-stdin", "-model", "broken", stdin="<robot name='x'><link>")
        self.assertEqual(code, 1)
        self.assertIn("not valid XML", err)
        self.assertNotIn("broken", models())

    def test_wait_holds_the_spawn_until_the_other_model_exists(self):
        waiting = start("-urdf", "-param", "/robot_description", "-model", "second",
                        "-y", "4", "-wait", "first")
        try:
            time.sleep(3.0)
            self.assertIsNone(waiting.poll(), "spawn_model -wait first ended before 'first' existed")
            self.assertNotIn("second", models())
            code, err = spawn("-urdf", "-param", "/robot_description", "-model", "first", "-y", "6")
            self.assertEqual(code, 0, err)
            self.assertEqual(waiting.wait(timeout=30), 0, waiting.stderr.read())
            self.assertIn("second", models())
        finally:
            if waiting.poll() is None:
                os.killpg(waiting.pid, signal.SIGKILL)

    def test_unpause_starts_a_paused_world(self):
        service("/gazebo/pause_physics", Empty)()
        paused_at = rospy.get_time()
        time.sleep(1.0)
        self.assertAlmostEqual(rospy.get_time(), paused_at, delta=0.02)
        code, err = spawn("-urdf", "-param", "/robot_description", "-model", "unpauser",
                          "-y", "-6", "-unpause")
        self.assertEqual(code, 0, err)
        wait_until_sim_time(paused_at + 0.5, timeout=20)

    def test_b_deletes_the_model_when_interrupted(self):
        bonded = start("-urdf", "-param", "/robot_description", "-model", "bonded", "-x", "-6", "-b")
        try:
            wait_until(lambda: "bonded" in models(), 30, "model 'bonded' to be spawned",
                       interval=0.1)
            time.sleep(0.5)
            self.assertIsNone(bonded.poll(), "spawn_model -b ended on its own")
            os.killpg(bonded.pid, signal.SIGINT)
            self.assertEqual(bonded.wait(timeout=20), 0)
            self.assertNotIn("Traceback", bonded.stderr.read())
            self.assertNotIn("bonded", models())
        finally:
            if bonded.poll() is None:
                os.killpg(bonded.pid, signal.SIGKILL)

    def test_sdf_calls_spawn_sdf_model_and_relays_its_answer(self):
        xml = "<not_a_model/>"
        direct = service("/gazebo/spawn_sdf_model", SpawnModel)("sdf_probe", xml, "/", Pose(), "")
        self.assertFalse(direct.success)
        with tempfile.NamedTemporaryFile("w", suffix=".sdf", delete=False) as sdf:
            sdf.write(xml)
        try:
            code, err = spawn("-sdf", "-file", sdf.name, "-model", "sdf_probe")
        finally:
            os.unlink(sdf.name)
        self.assertEqual(code, 1)
        self.assertIn(direct.status_message, err)
        self.assertNotIn("sdf_probe", models())

    def test_bad_joint_position_exits_1_before_spawning(self):
        code, err = spawn("-urdf", "-param", "/robot_description", "-model", "jointed",
                          "-J", "joint_left_wheel", "half")
        self.assertEqual(code, 1)
        self.assertIn("-J joint_left_wheel 'half' is not a number", err)
        self.assertNotIn("jointed", models())

    def test_j_robot_namespace_reference_frame_and_roll_as_gazebo_s(self):
        """-J sets the joint after the spawn; -robot_namespace puts the plugin topics under it;
        -x .. -R .. -Y are taken in -reference_frame (here a crate turned 90 deg)."""
        service("/gazebo/pause_physics", Empty)()         # the poses read as they were set
        self.addCleanup(service("/gazebo/unpause_physics", Empty))
        anchor = Pose()
        anchor.position.x, anchor.position.y, anchor.position.z = -4.0, -4.0, 0.15
        anchor.orientation.z = anchor.orientation.w = math.sqrt(0.5)          # yaw +90 deg
        answer = service("/gazebo/spawn_sdf_model", SpawnModel)("anchor", CRATE, "", anchor, "")
        self.assertTrue(answer.success, answer.status_message)
        code, err = spawn("-urdf", "-param", "/robot_description", "-model", "posed",
                          "-robot_namespace", "/third", "-reference_frame", "anchor",
                          "-x", "1", "-z", "0.1", "-R", "0.2", "-J", "joint_left_wheel", "0.5")
        self.assertEqual(code, 0, err)
        state = service("/gazebo/get_model_state", GetModelState)("posed", "")
        p, q = state.pose.position, state.pose.orientation
        self.assertAlmostEqual(p.x, -4.0, delta=1e-3)         # 1 m along the crate's x = +y
        self.assertAlmostEqual(p.y, -3.0, delta=1e-3)
        self.assertAlmostEqual(p.z, 0.25, delta=1e-3)
        roll = math.atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x ** 2 + q.y ** 2))
        self.assertAlmostEqual(roll, 0.2, delta=1e-3)
        self.assertAlmostEqual(yaw_of(q), math.pi / 2, delta=1e-3)
        joint = service("/gazebo/get_joint_properties", GetJointProperties)(
            "posed::joint_left_wheel")
        self.assertAlmostEqual(joint.position[0], 0.5, delta=1e-6)
        subscribed = dict(rosgraph.Master("/test_spawn_flags").getSystemState()[1])
        self.assertIn("/gazebo", subscribed.get("/third/cmd_vel", []))
        code, err = spawn("-urdf", "-param", "/robot_description", "-model", "unjointed",
                          "-y", "-9", "-J", "elbow", "1")     # Gazebo: spawned, then exit 1
        self.assertEqual(code, 1)
        self.assertIn("elbow", err)
        self.assertIn("unjointed", models())

    def test_refused_spawn_exits_1_with_the_reason(self):
        code, err = spawn("-urdf", "-param", "/robot_description", "-model", "elsewhere",
                          "-reference_frame", "no_such_model")
        self.assertEqual(code, 1)
        self.assertIn("no_such_model", err)
        self.assertNotIn("elsewhere", models())


if __name__ == "__main__":
    rostest.rosrun("m2wr_description", "spawn_flags", SpawnFlagsTest)
