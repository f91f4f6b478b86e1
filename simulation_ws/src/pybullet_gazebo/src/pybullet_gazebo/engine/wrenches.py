"""Forces, torques and joint efforts scheduled over sim time: what Gazebo's apply_body_wrench,
apply_joint_effort and a link's gravity_mode do. pybullet only, no ROS.

A job acts from `start` [s] of sim time for `duration` [s]; a negative duration means until
cleared (Gazebo's rule). As in Gazebo's scheduler, a job acts on every step whose start time t
has start <= t <= start + duration (so at least one step), and is dropped once t is past its
window. Bullet forgets external forces after each step: `apply(now)` runs before every step.

- A body wrench is a force [N] at the link's centre of mass and a torque [N m], both in the
  world frame.
- A joint effort [N m, or N for a prismatic joint] acts along the joint's axis: a torque
  (force) on the child link and its reaction on the parent, so it adds to whatever motor drives
  the joint (Gazebo's Joint::SetForce adds to the joint's force the same way).
- A link with gravity off gets -m g at its centre of mass each step.
"""
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np
import pybullet


@dataclass
class _Job:
    name: str                       # the scoped link or joint name it was asked for
    body_id: int
    start: float                    # [s] sim time
    end: Optional[float]            # [s] sim time; None = until cleared

    def active(self, now):
        return now >= self.start and (self.end is None or now <= self.end)

    def expired(self, now):
        return self.end is not None and now > self.end


@dataclass
class _BodyWrench(_Job):
    link_index: int = -1
    force: Tuple[float, float, float] = (0.0, 0.0, 0.0)     # [N], world frame
    torque: Tuple[float, float, float] = (0.0, 0.0, 0.0)    # [N m], world frame


@dataclass
class _JointEffort(_Job):
    joint_index: int = 0
    parent_index: int = -1
    prismatic: bool = False
    effort: float = 0.0             # [N m] or [N]


def _window(start, duration, now):
    """(start, end) of a job asked at sim time `now`: a start in the past means now."""
    start = max(start, now)
    return start, (None if duration < 0 else start + duration)


class WrenchSchedule:
    def __init__(self, client, gravity):
        self.client = client
        self.gravity = np.asarray(gravity, dtype=float)      # [m/s^2]
        self._wrenches = []
        self._efforts = []
        self._weightless = {}        # (body, link) -> name, links whose gravity is off

    # --- jobs -----------------------------------------------------------------------------
    def add_body_wrench(self, name, body_id, link_index, force, torque, start, duration, now):
        begin, end = _window(start, duration, now)
        self._wrenches.append(_BodyWrench(name, body_id, begin, end, link_index,
                                          tuple(map(float, force)), tuple(map(float, torque))))

    def add_joint_effort(self, name, body_id, joint_index, effort, start, duration, now):
        info = self.client.getJointInfo(body_id, joint_index)
        begin, end = _window(start, duration, now)
        self._efforts.append(_JointEffort(name, body_id, begin, end, joint_index, info[16],
                                          info[2] == pybullet.JOINT_PRISMATIC, float(effort)))

    def clear_body_wrenches(self, name) -> int:
        """Drops every wrench job on the link called `name`; returns how many."""
        before = len(self._wrenches)
        self._wrenches = [job for job in self._wrenches if job.name != name]
        return before - len(self._wrenches)

    def clear_joint_efforts(self, name) -> int:
        before = len(self._efforts)
        self._efforts = [job for job in self._efforts if job.name != name]
        return before - len(self._efforts)

    def pending(self):
        """(wrench jobs, effort jobs) not yet expired."""
        return len(self._wrenches), len(self._efforts)

    def idle(self):
        """True when nothing is scheduled and no link is weightless: apply() does nothing."""
        return not (self._wrenches or self._efforts or self._weightless)

    def set_gravity_mode(self, name, body_id, link_index, on):
        if on:
            self._weightless.pop((body_id, link_index), None)
        else:
            self._weightless[(body_id, link_index)] = name

    def gravity_mode(self, body_id, link_index):
        return (body_id, link_index) not in self._weightless

    def forget_bodies(self, body_ids):
        """A model is gone: its jobs go with it."""
        gone = set(body_ids)
        self._wrenches = [job for job in self._wrenches if job.body_id not in gone]
        self._efforts = [job for job in self._efforts if job.body_id not in gone]
        self._weightless = {key: name for key, name in self._weightless.items()
                            if key[0] not in gone}

    def clear(self):
        """Every timed job dropped (sim time went back to 0); gravity modes stay."""
        self._wrenches.clear()
        self._efforts.clear()

    # --- each step ------------------------------------------------------------------------
    def apply(self, now):
        """Pushes what is due at sim time `now` [s], just before the step that starts then."""
        if self._wrenches:
            for job in self._wrenches:
                if job.active(now):
                    self._wake(job.body_id)
                    self.client.applyExternalForce(job.body_id, job.link_index, job.force,
                                                   self._centre_of_mass(job.body_id, job.link_index),
                                                   pybullet.WORLD_FRAME)
                    self.client.applyExternalTorque(job.body_id, job.link_index, job.torque,
                                                    pybullet.WORLD_FRAME)
            self._wrenches = [job for job in self._wrenches if not job.expired(now)]
        if self._efforts:
            for job in self._efforts:
                if job.active(now):
                    self._wake(job.body_id)
                    self._push_joint(job)
            self._efforts = [job for job in self._efforts if not job.expired(now)]
        for (body, link) in self._weightless:
            mass = self.client.getDynamicsInfo(body, link)[0]
            self.client.applyExternalForce(body, link, tuple(-mass * self.gravity),
                                           self._centre_of_mass(body, link), pybullet.WORLD_FRAME)

    def _wake(self, body):
        """Bullet ignores forces on a sleeping body (Gazebo lets resting bodies sleep too,
        and wakes them when pushed)."""
        self.client.changeDynamics(body, -1, activationState=pybullet.ACTIVATION_STATE_WAKE_UP)

    def _centre_of_mass(self, body, link):
        if link < 0:
            return self.client.getBasePositionAndOrientation(body)[0]
        return self.client.getLinkState(body, link, computeForwardKinematics=True)[0]

    def _push_joint(self, job):
        client = self.client
        # pybullet gives the axis in the child's centre-of-mass frame (its "link frame")
        axis_local = client.getJointInfo(job.body_id, job.joint_index)[13]
        orientation = client.getLinkState(job.body_id, job.joint_index,
                                          computeForwardKinematics=True)[1]
        axis = np.asarray(pybullet.getMatrixFromQuaternion(orientation)).reshape(3, 3) \
            @ np.asarray(axis_local, dtype=float)
        push = tuple(job.effort * axis)
        reaction = tuple(-job.effort * axis)
        if job.prismatic:
            client.applyExternalForce(job.body_id, job.joint_index, push,
                                      self._centre_of_mass(job.body_id, job.joint_index),
                                      pybullet.WORLD_FRAME)
            client.applyExternalForce(job.body_id, job.parent_index, reaction,
                                      self._centre_of_mass(job.body_id, job.parent_index),
                                      pybullet.WORLD_FRAME)
        else:
            client.applyExternalTorque(job.body_id, job.joint_index, push, pybullet.WORLD_FRAME)
            client.applyExternalTorque(job.body_id, job.parent_index, reaction,
                                       pybullet.WORLD_FRAME)
