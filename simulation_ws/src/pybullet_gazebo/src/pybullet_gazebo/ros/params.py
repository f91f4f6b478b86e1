"""The simulator node's parameters, read once at start-up into a dataclass.

The world comes from the command line (checked before any ROS traffic). Private
parameters (~name), with units:
  paused              start with physics paused (Gazebo's `paused`)
  real_time_factor    sim seconds per wall second; 0 = as fast as the machine allows
                      (unset: the world file's <real_time_factor>)
  max_step_size       [s] fixed physics step; 0 = the world file's <max_step_size>
  pub_clock_frequency [Hz] of sim time at which /clock is published
  model_states_rate   [Hz] of sim time at which /gazebo/model_states is published
  watch_rate          [Hz] of wall time: when the simulation runs faster than real time,
                      model_states, link_states and joint_states go out at most max(this,
                      their own rate) times per wall second; 0 = no limit (watch_rate.py)
  seed                seed of the sensors' noise
  lockstep            before the simulation goes on, wait until the controllers are done
                      with what they were sent (lockstep/gate.py, README "Lockstep")
  lockstep_timeout    [s] of wall time: the longest such wait; a controller still at work
                      then is stepped past and named in the run summary
  cmd_vel_timeout     [s] of sim time after which a robot stops without commands; 0 = never
  gui                 open a window showing the world (needs a display; else headless)
  gui_fps             [Hz wall] at most this many frames per second in that window
  gui_rays            laser beams drawn: sdf (as the sensor's <visualize>, Gazebo's rule),
                      true (every ray sensor) or false
  gui_follow          the window's camera comes close to the robot and follows it (key f
                      toggles); false: it frames the whole world
  debug               log at debug level
  legacy_mode         true: diff drives as Kinetic's with <legacyMode>true whatever the URDF
                      says (m2wr turns counter-clockwise for a positive angular.z, as the
                      series' later programs expect); false: Noetic's, Gazebo's (clockwise)
  contacts            also publish ~contacts (the stand-in's own topic, not Gazebo's): off by
                      default, so the world offers exactly Gazebo's API
  web                 serve the world live in a browser page (web_adapter.py)
  web_host            address the page is served on; 127.0.0.1 (this machine only) by default
  web_port            its TCP port (8090)
  web_control         the page's Pause, Play, Step and Reset world buttons; false: view only
Global: /use_sim_time (publish /clock).
Each value is read with engine.parameters.ParameterReader: a bad one stops the node with a
message naming the parameter, the value and the allowed range.
"""
from dataclasses import dataclass
from typing import Optional

from pybullet_gazebo.engine.parameters import ROS_BOOLEANS, ParameterError, ParameterReader
from pybullet_gazebo.ros.watch_rate import DEFAULT_WATCH_RATE

__all__ = ["SimulatorParams", "ParameterError"]


@dataclass(frozen=True)
class SimulatorParams:
    paused: bool = False
    use_sim_time: bool = True
    real_time_factor: Optional[float] = None  # None: the world file's
    max_step_size: float = 0.005            # [s]
    pub_clock_frequency: float = 100.0      # [Hz]
    model_states_rate: float = 50.0         # [Hz]
    watch_rate: float = DEFAULT_WATCH_RATE  # [Hz] wall
    seed: int = 0
    lockstep: bool = False
    lockstep_timeout: float = 1.0           # [s] wall
    cmd_vel_timeout: float = 0.0            # [s] sim
    gui: bool = False
    gui_fps: float = 30.0                   # [Hz] wall
    gui_rays: str = "sdf"                   # sdf | true | false
    gui_follow: bool = True
    debug: bool = False
    legacy_mode: bool = False
    contacts: bool = False
    web: bool = False
    web_host: str = "127.0.0.1"
    web_port: int = 8090
    web_control: bool = True

    @staticmethod
    def from_values(private, use_sim_time=True, where="gazebo"):
        """Reads the node's private parameters from a dict (as rospy.get_param('~') gives
        it); ParameterError names the first bad one."""
        read = ParameterReader(private, where, label="~%s", booleans=ROS_BOOLEANS)
        d = SimulatorParams()
        return SimulatorParams(
            paused=read.boolean("paused", d.paused),
            use_sim_time=bool(use_sim_time),
            real_time_factor=read.number("real_time_factor", d.real_time_factor, minimum=0.0),
            max_step_size=read.number("max_step_size", d.max_step_size, minimum=0.0),
            pub_clock_frequency=read.number("pub_clock_frequency", d.pub_clock_frequency,
                                            above=0.0),
            model_states_rate=read.number("model_states_rate", d.model_states_rate, above=0.0),
            watch_rate=read.number("watch_rate", d.watch_rate, minimum=0.0),
            seed=read.integer("seed", d.seed, minimum=0),
            lockstep=read.boolean("lockstep", d.lockstep),
            lockstep_timeout=read.number("lockstep_timeout", d.lockstep_timeout, above=0.0),
            cmd_vel_timeout=read.number("cmd_vel_timeout", d.cmd_vel_timeout, minimum=0.0),
            gui=read.boolean("gui", d.gui),
            gui_fps=read.number("gui_fps", d.gui_fps, above=0.0),
            gui_rays=read.choice("gui_rays", d.gui_rays, ("sdf", "true", "false")),
            gui_follow=read.boolean("gui_follow", d.gui_follow),
            debug=read.boolean("debug", d.debug),
            legacy_mode=read.boolean("legacy_mode", d.legacy_mode),
            contacts=read.boolean("contacts", d.contacts),
            web=read.boolean("web", d.web),
            web_host=str(read.text("web_host", d.web_host)).strip() or d.web_host,
            web_port=read.integer("web_port", d.web_port, minimum=1),
            web_control=read.boolean("web_control", d.web_control),
        )

    @staticmethod
    def from_ros():
        import rospy
        return SimulatorParams.from_values(rospy.get_param("~", {}),
                                           rospy.get_param("/use_sim_time", True),
                                           where=rospy.get_name())

