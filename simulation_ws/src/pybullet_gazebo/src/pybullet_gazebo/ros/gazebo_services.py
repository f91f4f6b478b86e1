"""Gazebo's whole ROS API (gazebo_ros_api_plugin's), same names, types and md5sums, answered
from the World. Each family lives in its own module:
  state_services     get/set_model_state, get/set_link_state, the set_*_state topics
  property_services  world, model, link, joint properties; set_model_configuration; lights
  wrench_services    apply/clear body wrenches and joint efforts
  physics_services   get/set_physics_properties, pause/unpause, resets, dynamic_reconfigure
  spawn_services     spawn_urdf_model, spawn_sdf_model, delete_model
  call_log           with /gazebo/call_log set, who called which service, at what sim time
A request the world cannot honour answers `success: false` with a reason naming the input
(gazebo_answers.refuses, shared by every family); no request, however malformed, stops the
simulator.

The services see the simulator only through the narrow `Simulation` interface below (the
simulator node implements it): the world to query and change under its lock, and the few
operations that change more than the world (spawning and deleting bind or unbind a robot's
topics; pausing, resetting and pacing changes restart the pacing; a new time step changes
the publication periods).
"""
import threading
from typing import List, Protocol

import rospy

from pybullet_gazebo.engine.world import Robot, World
from pybullet_gazebo.ros.call_log import log_callers
from pybullet_gazebo.ros.physics_services import PhysicsServices
from pybullet_gazebo.ros.property_services import PropertyServices
from pybullet_gazebo.ros.spawn_services import SpawnServices
from pybullet_gazebo.ros.state_services import StateServices
from pybullet_gazebo.ros.wrench_services import WrenchServices


class Simulation(Protocol):
    world: World                # query it (and set states) under `lock`
    lock: threading.RLock
    paused: bool
    gui: bool                   # a window is open
    real_time_factor: float     # sim seconds per wall second; 0 = unlimited
    model_path: List[str]       # directories searched for model://NAME (spawn_sdf_model)

    def spawn_urdf(self, name, urdf_xml, pose, namespace="") -> Robot: ...
    def delete_model(self, name) -> None: ...
    def set_paused(self, paused) -> None: ...
    def reset(self, simulation: bool) -> None: ...
    def set_real_time_factor(self, rtf) -> None: ...
    def step_size_changed(self) -> None: ...       # after world.set_step_size
    def stamp(self) -> rospy.Time: ...             # the world's sim time


class GazeboServices:
    def __init__(self, sim: Simulation):
        self.families = [StateServices(sim), PropertyServices(sim), WrenchServices(sim),
                         SpawnServices(sim), PhysicsServices(sim)]
        self.call_log = log_callers([s for f in self.families for s in f.services], sim.stamp)
