"""Gazebo's spawn and delete services:
  ~spawn_urdf_model (gazebo_msgs/SpawnModel)  a URDF (<robot>), with its <gazebo> plugins
  ~spawn_sdf_model (gazebo_msgs/SpawnModel)   an SDF <model> (or <include>); a URDF too, as Gazebo
  ~delete_model (gazebo_msgs/DeleteModel)
initial_pose is in reference_frame (a model or `model::link`; "", "world", "map" = the world);
an all-zero quaternion is the identity. A model spawned inside another is spawned with a
warning naming both (Gazebo does the same); a duplicate name, XML that does not parse or is
not a model, a NaN or inf pose or an unknown reference frame answer success false, saying
which, and the world is left as it was.
"""
import xml.etree.ElementTree as ET

import rospy
from gazebo_msgs.srv import DeleteModel, DeleteModelResponse, SpawnModel, SpawnModelResponse

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.ros import conversions
from pybullet_gazebo.ros.gazebo_answers import refuses

INVALID_URDF = ("SpawnModel: Failure - entity format is invalid: model_xml of '%s' is not a "
                "URDF: its root element is %s; call /gazebo/spawn_sdf_model for an SDF model")


def _root_tag(text):
    if not text.strip():
        raise ValueError("model_xml is empty; send the model's URDF or SDF text")
    try:
        return ET.fromstring(text).tag
    except ET.ParseError as err:
        raise ValueError("model_xml does not parse as XML (%s); send the model's text" % err)


class SpawnServices:
    def __init__(self, sim):
        self.sim = sim
        self.services = [          # rospy.Service objects (gazebo_services logs their callers)
            rospy.Service("~spawn_urdf_model", SpawnModel, self.spawn_urdf_model),
            rospy.Service("~spawn_sdf_model", SpawnModel, self.spawn_sdf_model),
            rospy.Service("~delete_model", DeleteModel, self.delete_model),
        ]

    def spawn_urdf_model(self, req):
        try:
            root = _root_tag(req.model_xml)
        except ValueError as err:
            return self._refused(req, "SpawnModel: Failure - entity format is invalid: %s" % err)
        if root != "robot":
            return self._refused(req, INVALID_URDF % (req.model_name, "<%s>" % root))
        return self._spawn(req, urdf=True)

    def spawn_sdf_model(self, req):
        try:
            root = _root_tag(req.model_xml)
        except ValueError as err:
            return self._refused(req, "SpawnModel: Failure - %s" % err)
        if root == "robot":                       # Gazebo's spawn_sdf_model takes URDF too
            return self._spawn(req, urdf=True)
        if root not in ("sdf", "gazebo"):
            return self._refused(req, "GazeboRosApiPlugin SpawnModel Failure: input model_xml "
                                 "not SDF or URDF: its root element is <%s>" % root)
        return self._spawn(req, urdf=False)

    def _refused(self, req, message):
        rospy.logerr("spawn of '%s' refused: %s", req.model_name, message)
        return SpawnModelResponse(False, message)

    def _spawn(self, req, urdf):
        world = self.sim.world
        pose = conversions.pose_from_msg(req.initial_pose, zero_quaternion_is_identity=True)
        try:
            with self.sim.lock:
                try:
                    frame = model_access.frame_state(world, req.reference_frame)
                except LookupError as err:
                    raise ValueError("SpawnModel: reference reference_frame not found (%s)" % err)
                if frame is not None:
                    pose = frame[0].compose(pose)
                turning = None
                if urdf:            # the node binds the robot's topics
                    robot = self.sim.spawn_urdf(req.model_name, req.model_xml, pose,
                                                namespace=req.robot_namespace)
                    turning = world.positive_turn_direction(robot)
                else:
                    world.spawn_sdf(req.model_name, req.model_xml, pose,
                                    model_path=self.sim.model_path)
        except Exception as err:                 # any bad input: report, keep running
            return self._refused(req, str(err))
        x, y, z = pose.position
        rospy.loginfo("spawned '%s' at (%.3f, %.3f, %.3f)%s", req.model_name, x, y, z,
                      "; a positive angular.z turns it %s" % turning if turning else "")
        return SpawnModelResponse(True, "SpawnModel: Successfully spawned entity")

    @refuses("DeleteModel", DeleteModelResponse)
    def delete_model(self, req):
        self.sim.delete_model(req.model_name)
        return DeleteModelResponse(True, "DeleteModel: successfully deleted model")
