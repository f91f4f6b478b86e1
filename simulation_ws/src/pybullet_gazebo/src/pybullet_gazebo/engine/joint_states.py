"""gazebo_ros_joint_state_publisher (Noetic's gazebo_plugins) as a robot part: the angle and
speed of named joints, at a rate of sim time, for robot_state_publisher and rviz.

Plugin parameters (default in brackets): jointName (comma-separated joint names; required),
updateRate [100 Hz of sim time; <= 0: every step]. The ROS binding publishes
sensor_msgs/JointState on `joint_states` in the robot's namespace.

The same part stands in for a diff drive's publishWheelJointState (its two wheel joints at
its updateRate): robot_loader adds one to every robot with a diff drive and no joint-state
plugin of its own, whatever publishWheelJointState says, so that rviz can place the
wheels (Gazebo publishes them only when the description asks; the tutorial's does not).
"""
from dataclasses import dataclass
import math
from typing import List, Tuple

from .parameters import ParameterReader
from .part import Part, PartContext, next_period_time

_TOLERANCE = 1e-9            # [s] slack for sim times accumulated in floating point


@dataclass
class JointStates:
    """What a sensor_msgs/JointState carries, without ROS."""
    names: Tuple[str, ...]
    positions: List[float]       # [rad] (or [m] for a prismatic joint)
    velocities: List[float]      # [rad/s] (or [m/s])


class JointStatePublisher(Part):
    KEY = "libgazebo_ros_joint_state_publisher.so"

    @classmethod
    def build(cls, context: PartContext, plugin):
        where = "joint state publisher plugin '%s' (%s)" % (plugin.name, plugin.filename)
        read = ParameterReader(dict(plugin.params), where, label="<%s>")
        names = [n.strip() for n in read.text("jointName", "").split(",") if n.strip()]
        if not names:
            raise ValueError("%s: <jointName> is missing or empty; list the joints, comma "
                             "separated" % where)
        return cls(context, names, read.number("updateRate", 100.0), where)

    @classmethod
    def for_wheels(cls, context: PartContext, drive):
        """The wheel joint states of a diff drive, at its update rate."""
        return cls(context, [drive.left_joint, drive.right_joint], drive.update_rate,
                   "diff drive '%s' wheel joint states" % drive.name)

    def __init__(self, context: PartContext, names, update_rate, where):
        unknown = [n for n in names if n not in context.joints]
        if unknown:
            raise ValueError("%s: joint(s) %s are not in the model; its joints are: %s"
                             % (where, ", ".join(unknown), ", ".join(sorted(context.joints))))
        self._client = context.client
        self._body = context.body_id
        self.names = tuple(names)
        self._indices = [context.joints[n] for n in names]
        self.period = 1.0 / update_rate if update_rate > 0 else 0.0      # [s] sim
        self._last = None

    def due(self, now):
        if self._last is None or now < self._last or now - self._last >= self.period - _TOLERANCE:
            self._last = now
            return True
        return False

    def measure(self, now):
        states = self._client.getJointStates(self._body, self._indices)
        return JointStates(self.names, [s[0] for s in states], [s[1] for s in states])

    def skip(self, now):
        pass                    # due() already advanced the schedule; no noise

    def next_hook_time(self, now):
        return math.inf                 # no hooks

    def next_reading_time(self, now):
        return next_period_time(self._last, self.period, now)

    def reset(self):
        self._last = None
