"""Gazebo's physics and simulation-control services:
  ~get_physics_properties (gazebo_msgs/GetPhysicsProperties)
  ~set_physics_properties (gazebo_msgs/SetPhysicsProperties)
  ~pause_physics, ~unpause_physics, ~reset_simulation, ~reset_world (std_srvs/Empty)
and the physics dynamic_reconfigure server (physics_reconfigure.py).

time_step [s] is the fixed physics step; max_update_rate [Hz] is how many steps run per wall
second (0 = as fast as possible), i.e. the stand-in's real_time_factor = max_update_rate *
time_step; gravity [m/s^2]. The physics is Bullet, not ODE: get_physics_properties reports
Gazebo's default ODE settings (they have no effect), and set_physics_properties refuses a
request that changes one (an all-zero ode_config, a request's default, counts as unchanged),
changing nothing. `sim` is the simulator's narrow face to the services (see gazebo_services).
"""
import math

import rospy
from std_srvs.srv import Empty, EmptyResponse
from gazebo_msgs.msg import ODEPhysics
from gazebo_msgs.srv import (GetPhysicsProperties, GetPhysicsPropertiesResponse,
                             SetPhysicsProperties, SetPhysicsPropertiesResponse)
from geometry_msgs.msg import Vector3

from pybullet_gazebo.ros.gazebo_answers import refuses
from pybullet_gazebo.ros.physics_reconfigure import ODE_FIELDS, PhysicsReconfigure

# What a default Gazebo 11 world reports (its <physics type="ode"> defaults).
ODE_DEFAULTS = {"auto_disable_bodies": False, "sor_pgs_precon_iters": 0, "sor_pgs_iters": 50,
                "sor_pgs_w": 1.3, "sor_pgs_rms_error_tol": 0.0, "contact_surface_layer": 0.001,
                "contact_max_correcting_vel": 100.0, "cfm": 0.0, "erp": 0.2,
                "max_contacts": 20}
MAX_TIME_STEP = 1.0        # [s]


class Physics:
    """time_step, max_update_rate and gravity, read and set through the simulator."""

    def __init__(self, sim):
        self.sim = sim

    def properties(self):
        world = self.sim.world
        rtf = self.sim.real_time_factor
        return {"time_step": world.step_size, "paused": self.sim.paused,
                "max_update_rate": rtf / world.step_size if rtf > 0 else 0.0,
                "gravity": tuple(world.gravity), "ode": dict(ODE_DEFAULTS)}

    def set(self, time_step, max_update_rate, gravity):
        """ValueError, naming the value, and nothing changed when one is unusable."""
        if not (math.isfinite(time_step) and 0.0 < time_step <= MAX_TIME_STEP):
            raise ValueError("time_step %r must be in (0, %g] s" % (time_step, MAX_TIME_STEP))
        if not (math.isfinite(max_update_rate) and max_update_rate >= 0.0):
            raise ValueError("max_update_rate %r must be >= 0 Hz (0 = as fast as possible)"
                             % max_update_rate)
        if not all(math.isfinite(g) for g in gravity):
            raise ValueError("gravity %s must be finite [m/s^2]" % (tuple(gravity),))
        with self.sim.lock:
            world = self.sim.world
            world.set_gravity(gravity)
            if time_step != world.step_size:
                world.set_step_size(time_step)
                self.sim.step_size_changed()
            self.sim.set_real_time_factor(max_update_rate * time_step)


class PhysicsServices:
    def __init__(self, sim):
        self.sim = sim
        self.physics = Physics(sim)
        self.services = [          # rospy.Service objects (gazebo_services logs their callers)
            rospy.Service("~get_physics_properties", GetPhysicsProperties, self.get_physics),
            rospy.Service("~set_physics_properties", SetPhysicsProperties, self.set_physics),
            rospy.Service("~pause_physics", Empty, self.pause_physics),
            rospy.Service("~unpause_physics", Empty, self.unpause_physics),
            rospy.Service("~reset_simulation", Empty, self.reset_simulation),
            rospy.Service("~reset_world", Empty, self.reset_world),
        ]
        self.reconfigure = PhysicsReconfigure(self.physics)

    # --- physics properties -------------------------------------------------------------------
    def get_physics(self, _req):
        now = self.physics.properties()
        return GetPhysicsPropertiesResponse(
            now["time_step"], now["paused"], now["max_update_rate"], Vector3(*now["gravity"]),
            ODEPhysics(**now["ode"]), True,
            "GetPhysicsProperties: got properties (Bullet physics: ode_config shows Gazebo's "
            "defaults and has no effect)")

    @refuses("SetPhysicsProperties", SetPhysicsPropertiesResponse, then="; nothing changed",
             errors=(ValueError,))
    def set_physics(self, req):
        gravity = (req.gravity.x, req.gravity.y, req.gravity.z)
        asked = {name: getattr(req.ode_config, name) for name in ODE_FIELDS}
        if asked != ODE_DEFAULTS and any(asked.values()):
            changed = ["%s %s (is %s)" % (name, asked[name], ODE_DEFAULTS[name])
                       for name in ODE_FIELDS if asked[name] != ODE_DEFAULTS[name]]
            raise ValueError(
                "ode_config %s: ODE solver settings have no meaning for the stand-in's Bullet "
                "physics; send the ode_config get_physics_properties returns (or an empty "
                "one) to change time_step, max_update_rate or gravity" % ", ".join(changed))
        self.physics.set(req.time_step, req.max_update_rate, gravity)
        rospy.loginfo("set_physics_properties: time_step %g s, max_update_rate %g Hz "
                      "(real_time_factor %g), gravity %s m/s^2", req.time_step,
                      req.max_update_rate, req.time_step * req.max_update_rate, gravity)
        return SetPhysicsPropertiesResponse(True, "physics engine updated")

    # --- std_srvs/Empty -----------------------------------------------------------------------
    def pause_physics(self, _req):
        self.sim.set_paused(True)
        return EmptyResponse()

    def unpause_physics(self, _req):
        self.sim.set_paused(False)
        return EmptyResponse()

    def reset_simulation(self, _req):
        self.sim.reset(simulation=True)
        rospy.loginfo("reset_simulation: models back at their initial poses, sim time 0")
        return EmptyResponse()

    def reset_world(self, _req):
        self.sim.reset(simulation=False)
        rospy.loginfo("reset_world: models back at their initial poses")
        return EmptyResponse()
