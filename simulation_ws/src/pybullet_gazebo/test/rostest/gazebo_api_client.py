"""Shared by the gazebo_api_*.test nodes (imported from beside them): Gazebo's services as a
user's program calls them, m2wr and a small SDF crate to spawn, and a snapshot of the world
(model names and poses) to show that a refused request changed nothing."""
import os

import rospkg
import rospy
import xacro
from gazebo_msgs import srv
from geometry_msgs.msg import Point, Pose, Quaternion
from std_srvs.srv import Empty

from pybullet_gazebo.ros.testing import service, wait_until

CRATE_SDF = """<?xml version="1.0"?>
<sdf version="1.6"><model name="crate"><link name="body">
  <inertial><mass>2.0</mass><inertia><ixx>0.05</ixx><iyy>0.05</iyy><izz>0.05</izz></inertia></inertial>
  <collision name="shell"><geometry><box><size>0.3 0.3 0.3</size></box></geometry></collision>
</link></model></sdf>"""

TYPES = {
    "spawn_urdf_model": srv.SpawnModel, "spawn_sdf_model": srv.SpawnModel,
    "delete_model": srv.DeleteModel, "get_model_state": srv.GetModelState,
    "set_model_state": srv.SetModelState, "get_link_state": srv.GetLinkState,
    "set_link_state": srv.SetLinkState, "get_world_properties": srv.GetWorldProperties,
    "get_model_properties": srv.GetModelProperties, "get_link_properties": srv.GetLinkProperties,
    "set_link_properties": srv.SetLinkProperties,
    "get_joint_properties": srv.GetJointProperties,
    "set_joint_properties": srv.SetJointProperties,
    "set_model_configuration": srv.SetModelConfiguration,
    "apply_body_wrench": srv.ApplyBodyWrench, "clear_body_wrenches": srv.BodyRequest,
    "apply_joint_effort": srv.ApplyJointEffort, "clear_joint_forces": srv.JointRequest,
    "get_physics_properties": srv.GetPhysicsProperties,
    "set_physics_properties": srv.SetPhysicsProperties,
    "get_light_properties": srv.GetLightProperties,
    "set_light_properties": srv.SetLightProperties, "delete_light": srv.DeleteLight,
    "pause_physics": Empty, "unpause_physics": Empty, "reset_simulation": Empty,
    "reset_world": Empty,
}


class Gazebo:
    """gazebo.get_model_state(...) calls /gazebo/get_model_state, and so on."""

    def __init__(self):
        self._proxies = {}

    def __getattr__(self, name):
        if name not in TYPES:
            raise AttributeError(name)
        if name not in self._proxies:
            self._proxies[name] = service("/gazebo/" + name, TYPES[name])
        return self._proxies[name]

    def sim_time(self):
        return self.get_world_properties().sim_time

    def wait_sim(self, seconds, timeout=30.0):
        """Returns once sim time advanced by `seconds`; AssertionError after `timeout` wall s."""
        target = self.sim_time() + seconds
        wait_until(lambda: self.sim_time() >= target, timeout,
                   "sim time %.3f s (from %.3f s)" % (target, target - seconds), interval=0.01)

    def snapshot(self):
        """(model names, their poses rounded to 1 mm): what a refused request must not change."""
        names = sorted(self.get_world_properties().model_names)
        poses = []
        for name in names:
            p = self.get_model_state(name, "").pose.position
            poses.append((round(p.x, 3), round(p.y, 3), round(p.z, 3)))
        return names, poses


def pose(x=0.0, y=0.0, z=0.0, q=(0.0, 0.0, 0.0, 1.0)):
    return Pose(Point(x, y, z), Quaternion(*q))


def m2wr_urdf():
    path = os.path.join(rospkg.RosPack().get_path("m2wr_description"), "urdf", "m2wr.xacro")
    return xacro.process_file(path).toxml()


def spawn_m2wr(gazebo, name="m2wr", x=0.0, y=0.0, namespace=""):
    answer = gazebo.spawn_urdf_model(name, m2wr_urdf(), namespace, pose(x, y, 0.1), "")
    assert answer.success, answer.status_message
    return answer


def spawn_crate(gazebo, name="crate", x=0.0, y=0.0, z=0.15):
    answer = gazebo.spawn_sdf_model(name, CRATE_SDF, "", pose(x, y, z), "")
    assert answer.success, answer.status_message
    return answer
