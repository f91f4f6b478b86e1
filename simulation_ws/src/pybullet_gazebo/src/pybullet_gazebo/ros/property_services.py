"""Gazebo's property services:
  ~get_world_properties (gazebo_msgs/GetWorldProperties)
  ~get_model_properties (gazebo_msgs/GetModelProperties)
  ~get_link_properties / ~set_link_properties (gazebo_msgs/GetLinkProperties / SetLinkProperties)
  ~get_joint_properties / ~set_joint_properties (gazebo_msgs/GetJointProperties / SetJointProperties)
  ~set_model_configuration (gazebo_msgs/SetModelConfiguration)
  ~get_light_properties / ~set_light_properties / ~delete_light (gazebo_msgs/...Light...)
Names as Gazebo's (model, `model::link`, joint; see engine/model_access.py). What the stand-in
cannot do answers success false saying why, and changes nothing:
- lights: the stand-in simulates no lights (pybullet renders with its own), so every light
  name is unknown, as it would be in a Gazebo world without it;
- set_joint_properties: ODE's joint settings (erp, cfm, stops' erp/cfm, fudge_factor, fmax,
  vel) have no Bullet counterpart; damping and the joint limits (loStop, hiStop) are applied;
- set_link_properties: a moved centre of mass or products of inertia (Bullet takes principal
  moments about the centre of mass given by the description).
"""
import math

import rospy
from gazebo_msgs.srv import (DeleteLight, DeleteLightResponse, GetJointProperties,
                             GetJointPropertiesResponse, GetLightProperties,
                             GetLightPropertiesResponse, GetLinkProperties,
                             GetLinkPropertiesResponse, GetModelProperties,
                             GetModelPropertiesResponse, GetWorldProperties,
                             GetWorldPropertiesResponse, SetJointProperties,
                             SetJointPropertiesResponse, SetLightProperties,
                             SetLightPropertiesResponse, SetLinkProperties,
                             SetLinkPropertiesResponse, SetModelConfiguration,
                             SetModelConfigurationResponse)

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.ros import conversions
from pybullet_gazebo.ros.gazebo_answers import refuses

JOINT_TYPES = {"revolute": GetJointPropertiesResponse.REVOLUTE,
               "continuous": GetJointPropertiesResponse.CONTINUOUS,
               "prismatic": GetJointPropertiesResponse.PRISMATIC,
               "ball": GetJointPropertiesResponse.BALL,
               "planar": GetJointPropertiesResponse.UNIVERSAL,
               "fixed": GetJointPropertiesResponse.FIXED}
NO_LIGHTS = ("the stand-in simulates no lights (pybullet renders with its own), so light '%s' "
             "is not in the world")
ODE_ONLY_JOINT_FIELDS = ("erp", "cfm", "stop_erp", "stop_cfm", "fudge_factor", "fmax", "vel")


class PropertyServices:
    def __init__(self, sim):
        self.sim = sim
        self.services = [          # rospy.Service objects (gazebo_services logs their callers)
            rospy.Service("~get_world_properties", GetWorldProperties, self.get_world_properties),
            rospy.Service("~get_model_properties", GetModelProperties, self.get_model_properties),
            rospy.Service("~get_link_properties", GetLinkProperties, self.get_link_properties),
            rospy.Service("~set_link_properties", SetLinkProperties, self.set_link_properties),
            rospy.Service("~get_joint_properties", GetJointProperties, self.get_joint_properties),
            rospy.Service("~set_joint_properties", SetJointProperties, self.set_joint_properties),
            rospy.Service("~set_model_configuration", SetModelConfiguration,
                          self.set_model_configuration),
            rospy.Service("~get_light_properties", GetLightProperties, self.get_light),
            rospy.Service("~set_light_properties", SetLightProperties, self.set_light),
            rospy.Service("~delete_light", DeleteLight, self.delete_light),
        ]

    # --- world and models ----------------------------------------------------------------------
    def get_world_properties(self, _req):
        with self.sim.lock:
            return GetWorldPropertiesResponse(self.sim.world.sim_time, self.sim.world.model_names(),
                                              self.sim.gui, True,
                                              "GetWorldProperties: got properties")

    @refuses("GetModelProperties", GetModelPropertiesResponse)
    def get_model_properties(self, req):
        with self.sim.lock:
            props = model_access.model_properties(self.sim.world, req.model_name)
        return GetModelPropertiesResponse(
            parent_model_name="", canonical_body_name="", body_names=props.body_names,
            geom_names=props.geom_names, joint_names=props.joint_names, child_model_names=[],
            is_static=props.is_static, success=True,
            status_message="GetModelProperties: got properties")

    # --- links ----------------------------------------------------------------------------------
    @refuses("GetLinkProperties", GetLinkPropertiesResponse)
    def get_link_properties(self, req):
        with self.sim.lock:
            ref = model_access.find_link(self.sim.world, req.link_name)
            props = model_access.link_properties(self.sim.world, ref)
        ixx, iyy, izz = props.inertia
        return GetLinkPropertiesResponse(
            com=conversions.pose_to_msg(props.com), gravity_mode=props.gravity_mode,
            mass=props.mass, ixx=ixx, ixy=0.0, ixz=0.0, iyy=iyy, iyz=0.0, izz=izz,
            success=True, status_message="GetLinkProperties: got properties")

    @refuses("SetLinkProperties", SetLinkPropertiesResponse, then="; nothing changed")
    def set_link_properties(self, req):
        com = conversions.pose_from_msg(req.com, zero_quaternion_is_identity=True)
        with self.sim.lock:
            ref = model_access.find_link(self.sim.world, req.link_name)
            model_access.set_link_properties(
                self.sim.world, ref, req.mass, com, (req.ixx, req.iyy, req.izz),
                (req.ixy, req.ixz, req.iyz), req.gravity_mode)
        return SetLinkPropertiesResponse(True, "SetLinkProperties: properties set")

    # --- joints ---------------------------------------------------------------------------------
    @refuses("GetJointProperties", GetJointPropertiesResponse)
    def get_joint_properties(self, req):
        with self.sim.lock:
            ref = model_access.find_joint(self.sim.world, req.joint_name)
            props = model_access.joint_properties(self.sim.world, ref)
        return GetJointPropertiesResponse(
            type=JOINT_TYPES[props.kind], damping=[props.damping], position=[props.position],
            rate=[props.rate], success=True, status_message="GetJointProperties: got properties")

    @refuses("SetJointProperties", SetJointPropertiesResponse, then="; nothing changed")
    def set_joint_properties(self, req):
        config = req.ode_joint_config
        with self.sim.lock:
            ref = model_access.find_joint(self.sim.world, req.joint_name)
            unsupported = [name for name in ODE_ONLY_JOINT_FIELDS if getattr(config, name)]
            if unsupported:
                raise ValueError("%s of joint '%s' are ODE settings with no Bullet "
                                 "counterpart (only damping, loStop and hiStop are applied)"
                                 % (", ".join(unsupported), req.joint_name))
            values = list(config.damping) + list(config.loStop) + list(config.hiStop)
            if not all(math.isfinite(v) for v in values) or \
                    any(len(getattr(config, n)) > 1 for n in ("damping", "loStop", "hiStop")):
                raise ValueError("damping/loStop/hiStop %s must be at most one finite "
                                 "number each (the joint has one axis)" % (values,))
            if any(d < 0 for d in config.damping):
                raise ValueError("damping %s must be >= 0" % (list(config.damping),))
            changes = {}
            if config.damping:
                changes["jointDamping"] = float(config.damping[0])
            if config.loStop:
                changes["jointLowerLimit"] = float(config.loStop[0])
            if config.hiStop:
                changes["jointUpperLimit"] = float(config.hiStop[0])
            if changes:
                self.sim.world.client.changeDynamics(ref.body_id, ref.index, **changes)
        return SetJointPropertiesResponse(True, "SetJointProperties: properties set")

    @refuses("SetModelConfiguration", SetModelConfigurationResponse, then="; nothing changed")
    def set_model_configuration(self, req):
        with self.sim.lock:
            model_access.set_model_configuration(self.sim.world, req.model_name,
                                                 list(req.joint_names),
                                                 list(req.joint_positions))
        return SetModelConfigurationResponse(True, "SetModelConfiguration: success")

    # --- lights ---------------------------------------------------------------------------------
    def get_light(self, req):
        return GetLightPropertiesResponse(success=False, status_message=(
            "getLightProperties: Requested light %s not found! (" % req.light_name
            + NO_LIGHTS % req.light_name + ")"))

    def set_light(self, req):
        return SetLightPropertiesResponse(False, "setLightProperties: Requested light %s not "
                                          "found! (" % req.light_name
                                          + NO_LIGHTS % req.light_name + ")")

    def delete_light(self, req):
        return DeleteLightResponse(False, "DeleteLight: Requested light %s not found! ("
                                   % req.light_name + NO_LIGHTS % req.light_name + ")")
