"""Gazebo's physics dynamic_reconfigure server, same parameters as gazebo_ros's Physics.cfg:
  ~set_parameters (dynamic_reconfigure/Reconfigure)
  ~parameter_descriptions (dynamic_reconfigure/ConfigDescription), latched
  ~parameter_updates (dynamic_reconfigure/Config), latched

Parameters: ~time_step [s], ~max_update_rate [Hz], ~gravity_x/y/z [m/s^2] plus ODE's
solver settings. As in Gazebo, the server starts from what get_physics_properties reports and
hands changes to set_physics_properties' logic (`physics.set`). time_step, max_update_rate and
gravity take effect; ODE's settings have no meaning for Bullet: a change to one is reported
and the value stays what get_physics_properties reports. A request the physics refuses
(time_step 0, say) changes nothing and is reported naming the value; a NaN or inf in a
request is dropped, with a warning naming the parameter, before dynamic_reconfigure's clamp to
the range would turn it into a bound (gravity_z inf would become +100 m/s^2).
"""
import math
import types

import rospy
from dynamic_reconfigure.encoding import extract_params
from dynamic_reconfigure.server import Server

# name, type, default, min, max, what it is. Defaults, ranges and types are gazebo_ros's.
PARAMETERS = (
    ("time_step", "double", 0.001, 0.0, 10.0, "physics step [s]"),
    ("max_update_rate", "double", 60.0, 0.0, 1000.0,
     "physics steps per wall second [Hz]; 0 = as fast as possible"),
    ("gravity_x", "double", 0.0, -100.0, 100.0, "gravity along x [m/s^2]"),
    ("gravity_y", "double", 0.0, -100.0, 100.0, "gravity along y [m/s^2]"),
    ("gravity_z", "double", -9.8, -100.0, 100.0, "gravity along z [m/s^2]"),
    ("auto_disable_bodies", "bool", False, False, True, "ODE: let resting bodies sleep"),
    ("sor_pgs_precon_iters", "int", 0, 0, 10000, "ODE: preconditioning iterations"),
    ("sor_pgs_iters", "int", 20, 0, 10000, "ODE: solver iterations"),
    ("sor_pgs_w", "double", 1.3, 0.0, 5.0, "ODE: SOR relaxation"),
    ("sor_pgs_rms_error_tol", "double", -1.0, -1.0, 10000.0, "ODE: RMS error tolerance"),
    ("cfm", "double", 0.0, 0.0, 10.0, "ODE: constraint force mixing"),
    ("erp", "double", 0.2, 0.0, 10.0, "ODE: error reduction parameter"),
    ("contact_surface_layer", "double", 0.001, 0.0, 10.0, "ODE: contact dead band [m]"),
    ("contact_max_correcting_vel", "double", 100.0, 0.0, 10000000.0,
     "ODE: maximum contact correction velocity [m/s]"),
    ("max_contacts", "int", 100, 0, 10000000, "ODE: contacts between two bodies"),
)
ODE_FIELDS = ("auto_disable_bodies", "sor_pgs_precon_iters", "sor_pgs_iters", "sor_pgs_w",
              "sor_pgs_rms_error_tol", "cfm", "erp", "contact_surface_layer",
              "contact_max_correcting_vel", "max_contacts")
_CTYPES = {"double": ("double", "const double"), "int": ("int", "const int"),
           "bool": ("bool", "const bool")}


def physics_config_type():
    """What dynamic_reconfigure's Server takes as `type`: the description of the parameters
    (the layout dynamic_reconfigure's generator writes) and their defaults and bounds."""
    parameters = []
    for name, kind, default, low, high, what in PARAMETERS:
        ctype, cconst = _CTYPES[kind]
        parameters.append({"name": name, "type": kind, "default": default, "level": 1,
                           "description": what, "min": low, "max": high, "edit_method": "",
                           "srcline": 0, "srcfile": __file__, "ctype": ctype,
                           "cconsttype": cconst})
    description = {"name": "Default", "type": "", "state": True, "cstate": "true", "id": 0,
                   "parent": 0, "parameters": parameters, "groups": [], "srcline": 0,
                   "srcfile": __file__, "class": "DEFAULT", "parentclass": "",
                   "parentname": "Default", "field": "default", "upper": "DEFAULT",
                   "lower": "groups"}
    params = extract_params(description)
    return types.SimpleNamespace(
        config_description=description,
        defaults={p["name"]: p["default"] for p in params},
        min={p["name"]: p["min"] for p in params},
        max={p["name"]: p["max"] for p in params},
        level={p["name"]: p["level"] for p in params},
        type={p["name"]: p["type"] for p in params},
        all_level=1)


class FiniteValuesServer(Server):
    """dynamic_reconfigure's Server, but a NaN or inf value in a request is dropped (its
    parameter keeps its value) with a warning naming it, instead of being clamped to a bound
    of the parameter's range (or, for NaN, passed on)."""

    def update_configuration(self, changes):
        non_finite = sorted(name for name, value in changes.items()
                            if isinstance(value, float) and not math.isfinite(value))
        if non_finite:
            rospy.logwarn("physics reconfigure: %s must be finite; kept as they were"
                          % ", ".join("%s %s" % (name, changes[name]) for name in non_finite))
            changes = {name: value for name, value in changes.items()
                       if name not in non_finite}
        return super().update_configuration(changes)


class PhysicsReconfigure:
    """`physics` gives properties() -> PhysicsProperties-like dict and set(time_step,
    max_update_rate, gravity) raising ValueError (see physics_services)."""

    def __init__(self, physics):
        self.physics = physics
        self._started = False
        self.server = FiniteValuesServer(physics_config_type(), self._on_config)

    def _current(self):
        now = self.physics.properties()
        config = {"time_step": now["time_step"], "max_update_rate": now["max_update_rate"],
                  "gravity_x": now["gravity"][0], "gravity_y": now["gravity"][1],
                  "gravity_z": now["gravity"][2]}
        config.update(now["ode"])
        return config

    def _on_config(self, config, _level):
        current = self._current()
        if not self._started:            # Gazebo's server starts from the world as it is
            self._started = True
            config.update(current)
            return config
        ignored = [name for name in ODE_FIELDS if config[name] != current[name]]
        if ignored:
            rospy.logwarn("physics reconfigure: %s are ODE solver settings, which have no "
                          "meaning for the stand-in's Bullet physics; kept as they were"
                          % ", ".join(ignored))
        wanted = (config["time_step"], config["max_update_rate"],
                  (config["gravity_x"], config["gravity_y"], config["gravity_z"]))
        if wanted != (current["time_step"], current["max_update_rate"],
                      (current["gravity_x"], current["gravity_y"], current["gravity_z"])):
            try:
                self.physics.set(*wanted)
                rospy.loginfo("physics reconfigure: time_step %g s, max_update_rate %g Hz, "
                              "gravity %s m/s^2" % (wanted[0], wanted[1], wanted[2]))
            except ValueError as err:
                rospy.logwarn("physics reconfigure: %s; nothing changed" % err)
        config.update(self._current())
        return config
