"""Gazebo's services, same names and types, answered from the World.

A request the world cannot honour answers `success: false` with a reason; no request, however
malformed, stops the simulator (every handler catches and reports).

The services see the simulator only through the narrow `Simulation` interface below (the
simulator node implements it): the world to query under its lock, and the few operations
that change more than the world (spawning and deleting bind or unbind a robot's topics;
pausing and resetting restart the pacing).
"""
import threading
from typing import Protocol

import rospy
from std_srvs.srv import Empty, EmptyResponse
from gazebo_msgs.msg import ODEPhysics
from gazebo_msgs.srv import (DeleteModel, DeleteModelResponse, GetModelState,
                             GetModelStateResponse, GetPhysicsProperties,
                             GetPhysicsPropertiesResponse, GetWorldProperties,
                             GetWorldPropertiesResponse, SetModelState, SetModelStateResponse,
                             SpawnModel, SpawnModelResponse)
from geometry_msgs.msg import Vector3

from pybullet_gazebo.ros import conversions

from pybullet_gazebo.engine.world import Robot, World

WORLD_FRAMES = ("", "world", "map")


class Simulation(Protocol):
    world: World                # query it (and set states) under `lock`
    lock: threading.RLock
    paused: bool
    gui: bool                   # a window is open
    real_time_factor: float     # sim seconds per wall second; 0 = unlimited

    def spawn_urdf(self, name, urdf_xml, pose, namespace="") -> Robot: ...
    def delete_model(self, name) -> None: ...
    def set_paused(self, paused) -> None: ...
    def reset(self, simulation: bool) -> None: ...


class GazeboServices:
    def __init__(self, sim: Simulation):
        self.sim = sim
        self.world = sim.world
        self._services = [
            rospy.Service("~reset_simulation", Empty, self.reset_simulation),
            rospy.Service("~reset_world", Empty, self.reset_world),
            rospy.Service("~pause_physics", Empty, self.pause_physics),
            rospy.Service("~unpause_physics", Empty, self.unpause_physics),
            rospy.Service("~spawn_urdf_model", SpawnModel, self.spawn_urdf_model),
            rospy.Service("~spawn_sdf_model", SpawnModel, self.spawn_sdf_model),
            rospy.Service("~delete_model", DeleteModel, self.delete_model),
            rospy.Service("~get_model_state", GetModelState, self.get_model_state),
            rospy.Service("~set_model_state", SetModelState, self.set_model_state),
            rospy.Service("~get_world_properties", GetWorldProperties, self.get_world_properties),
            rospy.Service("~get_physics_properties", GetPhysicsProperties,
                          self.get_physics_properties),
        ]

    # --- std_srvs/Empty -----------------------------------------------------------------------
    def reset_simulation(self, _req):
        self.sim.reset(simulation=True)
        rospy.loginfo("reset_simulation: models back at their initial poses, sim time 0")
        return EmptyResponse()

    def reset_world(self, _req):
        self.sim.reset(simulation=False)
        rospy.loginfo("reset_world: models back at their initial poses")
        return EmptyResponse()

    def pause_physics(self, _req):
        self.sim.set_paused(True)
        return EmptyResponse()

    def unpause_physics(self, _req):
        self.sim.set_paused(False)
        return EmptyResponse()

    # --- models -------------------------------------------------------------------------------
    def spawn_urdf_model(self, req):
        if req.reference_frame not in WORLD_FRAMES:
            return SpawnModelResponse(False, "SpawnModel: reference_frame '%s' is not supported; "
                                      "leave it empty (world)" % req.reference_frame)
        pose = conversions.pose_from_msg(req.initial_pose, zero_quaternion_is_identity=True)
        try:
            robot = self.sim.spawn_urdf(req.model_name, req.model_xml, pose,
                                        namespace=req.robot_namespace)
            with self.sim.lock:
                turning = self.world.positive_turn_direction(robot)
        except Exception as err:                 # any bad input: report, keep running
            rospy.logerr("spawn_urdf_model '%s' failed: %s", req.model_name, err)
            return SpawnModelResponse(False, str(err))
        x, y, z = pose.position
        rospy.loginfo("spawned '%s' at (%.3f, %.3f, %.3f)%s", req.model_name, x, y, z,
                      "; a positive angular.z turns it %s" % turning if turning else "")
        return SpawnModelResponse(True, "SpawnModel: Successfully spawned entity")

    def spawn_sdf_model(self, req):
        return SpawnModelResponse(False, "SpawnModel: the stand-in spawns URDF models only; call "
                                  "/gazebo/spawn_urdf_model (spawn_model -urdf)")

    def delete_model(self, req):
        try:
            self.sim.delete_model(req.model_name)
        except Exception as err:
            return DeleteModelResponse(False, "DeleteModel: %s" % err)
        return DeleteModelResponse(True, "DeleteModel: successfully deleted model")

    def get_model_state(self, req):
        response = GetModelStateResponse()
        try:
            with self.sim.lock:
                pose = self.world.model_pose(req.model_name)
                linear, angular = self.world.model_twist(req.model_name)
                if req.relative_entity_name not in WORLD_FRAMES:
                    reference = self.world.model_pose(req.relative_entity_name)
                    ref_linear, ref_angular = self.world.model_twist(req.relative_entity_name)
                    pose = reference.inverse().compose(pose)
                    rotation = reference.matrix.T
                    linear = rotation @ (linear - ref_linear)
                    angular = rotation @ (angular - ref_angular)
                stamp = conversions.stamp_of(self.world.step_count, self.world.step_size)
        except Exception as err:
            response.success = False
            response.status_message = "GetModelState: %s" % err
            return response
        response.header.stamp = stamp
        response.pose = conversions.pose_to_msg(pose)
        response.twist = conversions.twist_to_msg(linear, angular)
        response.success = True
        response.status_message = "GetModelState: got properties"
        return response

    def set_model_state(self, req):
        state = req.model_state
        try:
            # Gazebo normalizes the quaternion (an all-zero one becomes identity), and the series'
            # bug programs send only a position
            pose = conversions.pose_from_msg(state.pose, zero_quaternion_is_identity=True)
            linear = (state.twist.linear.x, state.twist.linear.y, state.twist.linear.z)
            angular = (state.twist.angular.x, state.twist.angular.y, state.twist.angular.z)
            with self.sim.lock:
                if state.reference_frame not in WORLD_FRAMES:
                    reference = self.world.model_pose(state.reference_frame)
                    pose = reference.compose(pose)
                    rotation = reference.matrix
                    linear = tuple(rotation @ linear)
                    angular = tuple(rotation @ angular)
                self.world.set_model_state(state.model_name, pose, linear, angular)
        except Exception as err:
            return SetModelStateResponse(False, "SetModelState: %s" % err)
        return SetModelStateResponse(True, "SetModelState: set model state done")

    # --- properties -----------------------------------------------------------------------------
    def get_world_properties(self, _req):
        with self.sim.lock:
            return GetWorldPropertiesResponse(self.world.sim_time, self.world.model_names(),
                                              self.sim.gui, True,
                                              "GetWorldProperties: got properties")

    def get_physics_properties(self, _req):
        gravity = self.world.spec.physics.gravity
        rtf = self.sim.real_time_factor
        return GetPhysicsPropertiesResponse(
            self.world.step_size, self.sim.paused,
            rtf / self.world.step_size if rtf > 0 else 0.0, Vector3(*gravity), ODEPhysics(),
            True, "GetPhysicsProperties: got properties")
