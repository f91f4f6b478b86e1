"""Where things are now, read from an engine World (its pybullet client), as JSON-able data.

A frame: {"type": "frame", "t": sim time [s], "rtf": real-time factor (sim s per wall s over
the last second; None before one has passed), "paused": bool, "models": {model: [link pose
in the world per link]} (moving world models only), "robots": {robot: {"pose": model frame
[x, y, z, qx, qy, qz, qw], "yaw" [rad], "links": {link: pose}}}, "hits": {robot: {"from":
[x, y, z] (the first laser's origin), "points": [x0, y0, z0, x1, ...] (the lasers' returns in
the world [m], every k-th beam)}}.
"""
import time

import numpy as np

from ..engine.ray_sensor import RaySensor
from ..engine.transforms import Pose, yaw_from_quaternion
from .scene import pose_list

MAX_HITS = 360                  # laser returns sent per sensor (every k-th beam)


class FrameBuilder:
    """Builds frames of one World; `robots` are the engine Robots to draw."""

    def __init__(self, world):
        self.world = world
        self._rate_mark = None          # (wall, sim) at the start of the RTF window
        self._rtf = None

    def real_time_factor(self, now=None):
        now = time.monotonic() if now is None else now
        sim = self.world.sim_time
        if self._rate_mark is None or sim < self._rate_mark[1]:
            self._rate_mark = (now, sim)
        elif now - self._rate_mark[0] >= 1.0:
            self._rtf = (sim - self._rate_mark[1]) / (now - self._rate_mark[0])
            self._rate_mark = (now, sim)
        return self._rtf

    def moving_models(self):
        """{model: [link pose per body]} of world models that are not static."""
        world, client = self.world, self.world.client
        moving = {}
        for entity in list(world.entities.values()):
            if entity.static or entity.is_ground or entity.robot is not None:
                continue
            frames = []
            for body, inertial in zip(entity.body_ids, entity.inertial_offsets):
                raw = Pose(*client.getBasePositionAndOrientation(body))
                frames.append(pose_list(raw.compose(inertial.inverse()), 4))
            moving[entity.name] = frames
        return moving

    def robot(self, robot):
        """{"pose", "yaw", "links"} of a robot now."""
        world, client = self.world, self.world.client
        model = world.model_pose(robot.name)
        links = {}
        for name, index in robot.links.items():
            if index == -1:
                links[name] = pose_list(model, 4)
            else:
                state = client.getLinkState(robot.body_id, index, computeForwardKinematics=True)
                links[name] = pose_list(Pose(tuple(state[4]), tuple(state[5])), 4)
        return {"pose": pose_list(model, 4),
                "yaw": round(float(yaw_from_quaternion(model.orientation)), 4),
                "links": links}

    def frame(self, robots, scans, paused=False, now=None):
        """The frame now. `robots`: engine Robots; `scans`: {robot name: [(RaySensor,
        LaserScanData)]}, the latest scan of each sensor."""
        out = {"type": "frame", "t": round(self.world.sim_time, 4),
               "rtf": self.real_time_factor(now), "paused": bool(paused),
               "models": self.moving_models(), "robots": {}, "hits": {}}
        for robot in robots:
            if robot.name not in self.world.entities:
                continue
            out["robots"][robot.name] = self.robot(robot)
            hits = [laser_hits(sensor, scan) for sensor, scan in scans.get(robot.name, ())]
            if hits:
                out["hits"][robot.name] = {"from": hits[0][0],
                                           "points": [v for _, h in hits for v in h]}
        if out["rtf"] is not None:
            out["rtf"] = round(out["rtf"], 3)
        return out


def laser_hits(sensor, scan, limit=MAX_HITS, decimals=3):
    """(origin [x, y, z], flat [x, y, z, ...] of the returns of every k-th beam of `scan`) in
    the world, from `sensor`'s pose now ([m], rounded to `decimals` places: mm by default).
    Rounded as arrays: a replay rounds some 200,000 numbers, and Python's round() one by one
    was a third of its making."""
    ranges = np.asarray(scan.ranges, dtype=float)
    step = max(1, int(np.ceil(len(ranges) / float(limit))))
    index = np.arange(0, len(ranges), step)
    index = index[np.isfinite(ranges[index])]
    lengths = ranges[index]
    angles = scan.angle_min + scan.angle_increment * index
    local = np.stack([np.cos(angles) * lengths, np.sin(angles) * lengths,
                      np.zeros(len(index))], axis=1)
    pose = sensor.sensor_pose()
    ends = local @ pose.matrix.T + np.asarray(pose.position)
    return (np.round(np.asarray(pose.position, dtype=float), decimals).tolist(),
            np.round(ends.ravel(), decimals).tolist())


def ray_sensors(robot):
    """The robot's laser parts."""
    return robot.parts_with(RaySensor.KEY)
