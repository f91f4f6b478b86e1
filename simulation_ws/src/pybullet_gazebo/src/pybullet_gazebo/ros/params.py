"""The simulator node's parameters, read once at start-up into a dataclass.

The world comes from the command line (checked before any ROS traffic). Private
parameters (~name), with units:
  paused              start with physics paused (Gazebo's `paused`)
  real_time_factor    sim seconds per wall second; 0 = as fast as the machine allows
  max_step_size       [s] fixed physics step; 0 = the world file's <max_step_size>
  pub_clock_frequency [Hz] of sim time at which /clock is published
  model_states_rate   [Hz] of sim time at which /gazebo/model_states is published
  seed                seed of the sensors' noise
  lockstep            after each scan, wait for the controller's cmd_vel (see README)
  lockstep_timeout    [s] of wall time to wait for it before stepping on
  cmd_vel_timeout     [s] of sim time after which a robot stops without commands; 0 = never
  gui                 open pybullet's GUI window (needs a display)
  debug               log at debug level
Global: /use_sim_time (publish /clock).
"""
from dataclasses import dataclass
import math

import rospy


class ParameterError(ValueError):
    pass


@dataclass(frozen=True)
class SimulatorParams:
    world_name: str                          # the resolved world file
    paused: bool = False
    use_sim_time: bool = True
    real_time_factor: float = 1.0
    max_step_size: float = 0.005            # [s]
    pub_clock_frequency: float = 100.0      # [Hz]
    model_states_rate: float = 50.0         # [Hz]
    seed: int = 0
    lockstep: bool = False
    lockstep_timeout: float = 1.0           # [s] wall
    cmd_vel_timeout: float = 0.0            # [s] sim
    gui: bool = False
    debug: bool = False

    def __post_init__(self):
        def check(name, value, low, allow_zero=True):
            if not (isinstance(value, (int, float)) and math.isfinite(value)) or value < low \
                    or (not allow_zero and value == 0):
                raise ParameterError("~%s = %r is invalid: expected a number >= %s%s"
                                     % (name, value, low, "" if allow_zero else ", not 0"))
        check("real_time_factor", self.real_time_factor, 0.0)
        check("max_step_size", self.max_step_size, 0.0)
        check("pub_clock_frequency", self.pub_clock_frequency, 0.0, allow_zero=False)
        check("model_states_rate", self.model_states_rate, 0.0, allow_zero=False)
        check("lockstep_timeout", self.lockstep_timeout, 0.0, allow_zero=False)
        check("cmd_vel_timeout", self.cmd_vel_timeout, 0.0)

    @staticmethod
    def from_ros(world_name):
        def get(name, default, kind):
            value = rospy.get_param("~" + name, default)
            if kind is bool and isinstance(value, str):
                if value.lower() in ("true", "1", "yes"):
                    return True
                if value.lower() in ("false", "0", "no"):
                    return False
            try:
                return kind(value)
            except (TypeError, ValueError):
                raise ParameterError("~%s = %r is not a %s" % (name, value, kind.__name__))
        defaults = SimulatorParams(world_name="-")
        return SimulatorParams(
            world_name=world_name,
            paused=get("paused", defaults.paused, bool),
            use_sim_time=bool(rospy.get_param("/use_sim_time", True)),
            real_time_factor=get("real_time_factor", defaults.real_time_factor, float),
            max_step_size=get("max_step_size", defaults.max_step_size, float),
            pub_clock_frequency=get("pub_clock_frequency", defaults.pub_clock_frequency, float),
            model_states_rate=get("model_states_rate", defaults.model_states_rate, float),
            seed=get("seed", defaults.seed, int),
            lockstep=get("lockstep", defaults.lockstep, bool),
            lockstep_timeout=get("lockstep_timeout", defaults.lockstep_timeout, float),
            cmd_vel_timeout=get("cmd_vel_timeout", defaults.cmd_vel_timeout, float),
            gui=get("gui", defaults.gui, bool),
            debug=get("debug", defaults.debug, bool),
        )
