"""Gazebo's `<sensor type="ray">` with its gazebo_ros_laser plugin, as an engine component.

One horizontal fan of `samples` beams in the sensor frame's xy plane, from `min_angle`
(index 0, the right-most beam) to `max_angle` [rad], angle_increment =
(max_angle - min_angle) / (samples - 1). The sensor frame is the link's world pose composed
with the sensor's `<pose>`. Each beam tests [range_min, range_max] [m] (like Gazebo's rays,
which start at the minimum range) and never sees the robot's own body. No return is `+inf`
(REP 117); Gaussian noise N(noise_mean, noise_stddev) [m] is added to returns only, drawn
from the generator passed in (seedable), and a noisy return is kept inside
[range_min, range_max] as Gazebo does.

The plugin's parameters (libgazebo_ros_laser.so) are kept as `plugin_params`: the ROS
adapter reads its topic and frame from them (ros/plugin_names.py) and publishes
`measure()`'s LaserScanData there, stamped with the sim time passed in. Measurements are due
at `update_rate` [Hz] of sim time (0 = every step).
"""
from dataclasses import dataclass
import math

import numpy as np

from . import ray_kernel
from .parameters import ParameterReader
from .part import Part, PartContext, next_period_time
from .transforms import Pose

_TOLERANCE = 1e-9            # [s] slack for sim times accumulated in floating point
_NO_NOISE = np.zeros(0)


def _due(last, sim_time, period):
    """A scan is due at sim_time [s] when `period` [s] passed since the last one (sim time
    `last`, None before the first), and when the sim time went backwards."""
    if last is None or sim_time < last:
        return True
    return sim_time - last >= period - _TOLERANCE


@dataclass
class LaserScanData:
    """What a sensor_msgs/LaserScan carries, without ROS."""
    stamp: float                # sim time [s]
    angle_min: float            # [rad]
    angle_max: float            # [rad]
    angle_increment: float      # [rad]
    time_increment: float       # [s], 0: all beams at once
    scan_time: float            # [s] between scans
    range_min: float            # [m]
    range_max: float            # [m]
    ranges: np.ndarray          # float32 (samples,) [m]; +inf where nothing is in range


class RaySensor(Part):
    """A laser scanner on a link of a body."""

    KEY = "ray"

    @classmethod
    def build(cls, context: PartContext, spec):
        return cls(context.client, context.body_id, context.links[spec.link], spec,
                   context.caster, context.rng)

    def __init__(self, client, body_id, link_index, spec, caster, rng):
        self._check(spec)
        self._client = client
        self.body_id = body_id
        self.link_index = link_index
        self.spec = spec
        self._caster = caster
        self.rng = rng                       # numpy Generator; reseed() swaps it on reset
        # its topic and frame names: the ROS side's (ros/plugin_names.py)
        self.plugin_params = dict(spec.plugin.params) if spec.plugin is not None else {}
        self.update_rate = float(spec.update_rate)                   # [Hz]
        self._period = 1.0 / self.update_rate if self.update_rate > 0 else 0.0   # [s]
        samples = int(spec.samples)
        self.angle_increment = ((spec.max_angle - spec.min_angle) / (samples - 1)
                                if samples > 1 else 0.0)              # [rad]
        angles = spec.min_angle + self.angle_increment * np.arange(samples)
        self._cos_sin = np.ascontiguousarray(np.stack([np.cos(angles), np.sin(angles)], axis=1))
        self._offset = (np.array(spec.pose.position, dtype=float),
                        np.array(spec.pose.orientation, dtype=float))
        self._frame = np.empty((4, 3))       # scratch of measure(): ray_kernel.fan_rays'
        self._fan = np.empty(8)
        self._directions = np.empty((samples, 3))
        self._rays_pose = None               # the link pose those three were laid out at
        self._noisy = spec.noise_stddev > 0.0 or spec.noise_mean != 0.0
        self._normals = np.empty(samples) if self._noisy else _NO_NOISE   # measure()'s draws
        # the scan's numbers as measure() passes them on (the spec is frozen)
        self._limits = (float(spec.min_angle), float(spec.max_angle), float(spec.range_min),
                        float(spec.range_max), float(spec.noise_mean), float(spec.noise_stddev))
        # bound once: a BulletClient makes a new partial at every attribute read
        self._link_state = client.getLinkState
        if link_index == -1:
            # pybullet reports the base's centre of mass; the link frame is offset from it
            self._base_inertial = Pose(*client.getDynamicsInfo(body_id, -1)[3:5]).inverse()
        self._last = None                                            # sim time of last scan

    @staticmethod
    def _check(spec):
        """The sensor's values Gazebo could not run are refused (ParameterError, a
        ValueError), naming the tag, its value and the allowed range."""
        read = ParameterReader({"samples": spec.samples, "max_angle": spec.max_angle,
                                "range/min": spec.range_min, "range/max": spec.range_max,
                                "update_rate": spec.update_rate,
                                "noise/stddev": spec.noise_stddev},
                               "ray sensor '%s' on link '%s'" % (spec.name, spec.link),
                               label="<%s>")
        read.integer("samples", 1, minimum=1)
        read.number("max_angle", 0.0, minimum=spec.min_angle)      # [rad]
        read.number("range/min", 0.0, minimum=0.0)                 # [m]
        read.number("range/max", 0.0, above=spec.range_min)        # [m]
        read.number("update_rate", 0.0, minimum=0.0)               # [Hz]; 0 = every step
        read.number("noise/stddev", 0.0, minimum=0.0)              # [m]

    def reset(self):
        """After a simulation reset: the next call to due() is true."""
        self._last = None

    def reseed(self, rng):
        self.rng = rng

    def due(self, sim_time):
        """True when at least 1/update_rate [s] of sim time passed since the last scan (and on
        the first call, and when the sim time went backwards)."""
        return _due(self._last, sim_time, self._period)

    def next_hook_time(self, now):
        return math.inf                 # no hooks: a scan is a reading

    def next_reading_time(self, now):
        """The next scan (see Part)."""
        return next_period_time(self._last, self._period, now)

    def scans_at(self, times):
        """Indices of the coming sim times `times` [s] (ascending) at which the sensor will
        scan, if it is asked at each of them and nothing resets it in between."""
        last, least, indices = self._last, self._period - _TOLERANCE, []
        for index, sim_time in enumerate(times):
            # _due, inline (the environment asks this every step)
            if last is None or sim_time < last or sim_time - last >= least:
                last = sim_time
                indices.append(index)
        return indices

    def skip(self, sim_time):
        """A scan due at `sim_time` [s] that nobody reads: nothing is cast, but the schedule
        and the noise stream advance exactly as measure() would advance them."""
        if self._noisy:
            # measure() takes one standard normal draw per beam, as this does
            self.rng.standard_normal(out=self._normals)
        self._last = sim_time

    def _link_frame(self):
        """(position, quaternion) of the sensor's link frame in the world."""
        client = self._client
        if self.link_index == -1:
            link = Pose(*client.getBasePositionAndOrientation(self.body_id)).compose(
                self._base_inertial)
            return link.position, link.orientation
        state = self._link_state(self.body_id, self.link_index, computeForwardKinematics=True)
        return state[4], state[5]

    def sensor_pose(self):
        """World pose of the sensor frame: the link frame composed with the sensor's pose."""
        return Pose(*self._link_frame()).compose(self.spec.pose)

    def measure(self, sim_time):
        """Scan now; returns a LaserScanData stamped `sim_time` [s]."""
        angle_min, angle_max, range_min, range_max, noise_mean, noise_stddev = self._limits
        position, orientation = self._link_frame()
        frame, fan, directions = self._frame, self._fan, self._directions
        pose = (tuple(position), tuple(orientation))
        same_rays = pose == self._rays_pose   # a link at rest keeps its rays, to the bit
        if not same_rays:
            self._rays_pose = None
            if not ray_kernel.fan_rays(np.asarray(position, dtype=float),
                                       np.asarray(orientation, dtype=float), self._offset[0],
                                       self._offset[1], self._cos_sin, angle_min,
                                       self.angle_increment, frame, fan, directions):
                raise ValueError("ray sensor '%s': its link's pose is not finite"
                                 % self.spec.name)
            self._rays_pose = pose
        ranges = self._caster.cast_fan(frame, directions, fan, range_min, range_max,
                                       exclude_body=self.body_id, same_rays=same_rays)
        # one draw per beam whether it hit or not, so the stream does not depend on the scene
        normals = self.rng.standard_normal(out=self._normals) if self._noisy else _NO_NOISE
        out = np.empty(len(ranges), dtype=np.float32)
        ray_kernel.noisy_ranges(ranges, normals, noise_mean, noise_stddev, range_min, range_max,
                                out)
        self._last = sim_time
        return LaserScanData(
            stamp=sim_time, angle_min=angle_min, angle_max=angle_max,
            angle_increment=self.angle_increment, time_increment=0.0, scan_time=self._period,
            range_min=range_min, range_max=range_max, ranges=out)
