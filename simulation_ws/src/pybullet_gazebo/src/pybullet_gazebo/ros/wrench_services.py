"""Gazebo's force services, scheduled over sim time by the engine (engine/wrenches.py):
  ~apply_body_wrench (gazebo_msgs/ApplyBodyWrench)   force [N] and torque [N m] on a link
  ~clear_body_wrenches (gazebo_msgs/BodyRequest)     drops a link's wrenches
  ~apply_joint_effort (gazebo_msgs/ApplyJointEffort) effort [N m or N] along a joint's axis
  ~clear_joint_forces (gazebo_msgs/JointRequest)     drops a joint's efforts
start_time [s sim]: a time already past means now. duration [s sim]: < 0 = until cleared.
A wrench is given in reference_frame (a model or `model::link`; "", "world", "map" = the
world), about reference_point in that frame; the stand-in applies the force at the link's
centre of mass and the torque (including reference_point x force), both turned into the
world frame. (Gazebo's own transformation of a wrench with a reference frame is a FIXME in
its source; this is what its documentation says.) Bad input (unknown link, joint or frame,
NaN or inf) answers success false naming it and schedules nothing. The clear services' answers
have no fields (as Gazebo's): clearing an unknown link or joint clears nothing and logs a
warning naming it.
"""
import math

import numpy as np
import rospy
from gazebo_msgs.srv import (ApplyBodyWrench, ApplyBodyWrenchResponse, ApplyJointEffort,
                             ApplyJointEffortResponse, BodyRequest, BodyRequestResponse,
                             JointRequest, JointRequestResponse)

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.ros.gazebo_answers import refuses

MAX_WRENCH = 1.0e9          # [N] and [N m]: Bullet's state turns to NaN far beyond


def _finite(values, what):
    values = [float(v) for v in values]
    if not all(math.isfinite(v) for v in values):
        raise ValueError("%s %s holds NaN or inf" % (what, values))
    if max(abs(v) for v in values) > MAX_WRENCH:
        raise ValueError("%s %s is over %g" % (what, values, MAX_WRENCH))
    return np.asarray(values)


class WrenchServices:
    def __init__(self, sim):
        self.sim = sim
        self.services = [          # rospy.Service objects (gazebo_services logs their callers)
            rospy.Service("~apply_body_wrench", ApplyBodyWrench, self.apply_body_wrench),
            rospy.Service("~clear_body_wrenches", BodyRequest, self.clear_body_wrenches),
            rospy.Service("~apply_joint_effort", ApplyJointEffort, self.apply_joint_effort),
            rospy.Service("~clear_joint_forces", JointRequest, self.clear_joint_forces),
        ]

    @refuses("ApplyBodyWrench", ApplyBodyWrenchResponse, then="; nothing applied")
    def apply_body_wrench(self, req):
        world = self.sim.world
        force = _finite((req.wrench.force.x, req.wrench.force.y, req.wrench.force.z),
                        "wrench.force")
        torque = _finite((req.wrench.torque.x, req.wrench.torque.y, req.wrench.torque.z),
                         "wrench.torque")
        point = _finite((req.reference_point.x, req.reference_point.y,
                         req.reference_point.z), "reference_point")
        with self.sim.lock:
            ref = model_access.find_link(world, req.body_name)
            frame = model_access.frame_state(world, req.reference_frame)
            torque = torque + np.cross(point, force)
            if frame is not None:
                rotation = frame[0].matrix
                force, torque = rotation @ force, rotation @ torque
            world.wrenches.add_body_wrench(ref.scoped, ref.body_id, ref.link_index, force,
                                           torque, req.start_time.to_sec(),
                                           req.duration.to_sec(), world.sim_time)
        return ApplyBodyWrenchResponse(True, "")

    def clear_body_wrenches(self, req):
        with self.sim.lock:
            try:
                name = model_access.find_link(self.sim.world, req.body_name).scoped
            except LookupError as err:
                rospy.logwarn("clear_body_wrenches: %s; nothing cleared", err)
                return BodyRequestResponse()
            self.sim.world.wrenches.clear_body_wrenches(name)
        return BodyRequestResponse()

    @refuses("ApplyJointEffort", ApplyJointEffortResponse, then="; nothing applied")
    def apply_joint_effort(self, req):
        world = self.sim.world
        effort = _finite((req.effort,), "effort")[0]
        with self.sim.lock:
            ref = model_access.find_joint(world, req.joint_name)
            world.wrenches.add_joint_effort(ref.scoped, ref.body_id, ref.index, effort,
                                            req.start_time.to_sec(), req.duration.to_sec(),
                                            world.sim_time)
        return ApplyJointEffortResponse(True, "ApplyJointEffort: effort set")

    def clear_joint_forces(self, req):
        with self.sim.lock:
            try:
                name = model_access.find_joint(self.sim.world, req.joint_name).scoped
            except LookupError as err:
                rospy.logwarn("clear_joint_forces: %s; nothing cleared", err)
                return JointRequestResponse()
            self.sim.world.wrenches.clear_joint_efforts(name)
        return JointRequestResponse()
