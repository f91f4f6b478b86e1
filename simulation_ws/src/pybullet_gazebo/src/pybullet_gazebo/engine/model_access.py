"""The links and joints of the world's models, by Gazebo's names: what get/set_link_state,
get/set_link_properties, get_joint_properties, get_model_properties and
set_model_configuration read and change. pybullet only, no ROS.

Names, as Gazebo gives them
- A link is `model::link`; a bare `link` also finds the first model's link of that name
  (Gazebo's EntityByName matches either).
- A frame (reference_frame, relative_entity_name) is a model or a link; "", "world", "map"
  and "/map" are the world frame.
- A joint is `joint` or `model::joint`.
- Gazebo turns a URDF into SDF by merging every link attached by a fixed joint into its parent
  (its collisions become `parent_fixed_joint_lump__child_collision_N`), so such links and
  fixed joints are not listed, and the stand-in's wheel contact spheres never are.

States are the link frame's pose in the world and the velocity of its origin [m/s, rad/s],
as Gazebo reports them; Bullet keeps centre-of-mass states, converted here.
Errors are LookupError (an unknown name, with the names there are) or ValueError (a value
the stand-in cannot honour, saying why); nothing changes when one is raised.
"""
from dataclasses import dataclass
import math
from typing import List, Optional, Tuple

import numpy as np
import pybullet

from . import wheel_contact
from .placement import checked_pose
from .transforms import Pose

WORLD_FRAMES = ("", "world", "map", "/map")
JOINT_KINDS = {pybullet.JOINT_REVOLUTE: "revolute", pybullet.JOINT_PRISMATIC: "prismatic",
               pybullet.JOINT_SPHERICAL: "ball", pybullet.JOINT_PLANAR: "planar",
               pybullet.JOINT_FIXED: "fixed"}


@dataclass(frozen=True)
class LinkRef:
    model: str
    link: str                      # the link's own name
    body_id: int
    link_index: int                # Bullet's index in its body (-1: the base)
    body_slot: int                 # index into the entity's body_ids

    @property
    def scoped(self):
        return "%s::%s" % (self.model, self.link)


@dataclass(frozen=True)
class JointRef:
    model: str
    joint: str
    body_id: int
    index: int

    @property
    def scoped(self):
        return "%s::%s" % (self.model, self.joint)


@dataclass(frozen=True)
class LinkProperties:
    mass: float                                   # [kg]
    com: Pose                                     # centre of mass in the link frame
    inertia: Tuple[float, float, float]           # ixx iyy izz [kg m^2], about the com
    gravity_mode: bool


@dataclass(frozen=True)
class JointProperties:
    kind: str                                     # revolute, continuous, prismatic, ball
    damping: float
    position: float                               # [rad] or [m]
    rate: float                                   # [rad/s] or [m/s]


@dataclass(frozen=True)
class ModelProperties:
    body_names: List[str]
    geom_names: List[str]
    joint_names: List[str]
    is_static: bool


# --- names ----------------------------------------------------------------------------------
def links_of(world, model_name) -> List[LinkRef]:
    """The links of a model as Gazebo lists them (after the URDF's fixed-joint merge)."""
    entity = world.entity(model_name)
    if entity.robot is None:
        return [LinkRef(entity.name, name, body, -1, slot)
                for slot, (name, body) in enumerate(zip(entity.link_names, entity.body_ids))]
    robot = entity.robot
    kept = _robot_links(world.client, robot)
    return [LinkRef(entity.name, name, robot.body_id, robot.links[name], 0) for name in kept]


def _robot_links(client, robot):
    """Link names of a robot in Bullet's order, root first, without merged or contact links."""
    by_index = {index: name for name, index in robot.links.items()}
    names = [by_index[-1]]
    for index in range(client.getNumJoints(robot.body_id)):
        info = client.getJointInfo(robot.body_id, index)
        if info[2] != pybullet.JOINT_FIXED:
            names.append(by_index[index])
    return names


def _lumped_into(client, robot):
    """{kept link: [merged child links]}: children on fixed joints, merged as Gazebo does."""
    by_index = {index: name for name, index in robot.links.items()}
    parent_of = {}
    for index in range(client.getNumJoints(robot.body_id)):
        info = client.getJointInfo(robot.body_id, index)
        parent_of[index] = (info[16], info[2] == pybullet.JOINT_FIXED)
    merged = {}
    for index, (parent, fixed) in parent_of.items():
        if not fixed or by_index[index].endswith(wheel_contact.SUFFIX):
            continue
        while parent >= 0 and parent_of[parent][1]:
            parent = parent_of[parent][0]
        merged.setdefault(by_index[parent], []).append(by_index[index])
    return merged


def find_link(world, name) -> LinkRef:
    if name and "::" in name:
        model, _, link = name.rpartition("::")
        if model in world.entities:
            for ref in links_of(world, model):
                if ref.link == link:
                    return ref
    elif name:
        for model in world.model_names():
            for ref in links_of(world, model):
                if ref.link == name:
                    return ref
    known = [ref.scoped for model in world.model_names() for ref in links_of(world, model)]
    raise LookupError("link '%s' does not exist; links are named model::link, e.g. %s"
                      % (name, ", ".join(known[:8]) + (", ..." if len(known) > 8 else "")
                         if known else "(no model in the world)"))


def find_joint(world, name) -> JointRef:
    model_part, _, joint_part = name.rpartition("::")
    known = []
    for model in world.model_names():
        robot = world.entities[model].robot
        if robot is None:
            continue
        for joint, index in robot.joints.items():
            if world.client.getJointInfo(robot.body_id, index)[2] == pybullet.JOINT_FIXED:
                continue
            known.append("%s::%s" % (model, joint))
            if name and joint == joint_part and model_part in ("", model):
                return JointRef(model, joint, robot.body_id, index)
    raise LookupError("joint '%s' does not exist; joints are %s"
                      % (name, ", ".join(known) or "(none: no model with joints)"))


def frame_state(world, name):
    """(pose, linear, angular) of a model or link in the world, or None for the world frame."""
    if name in WORLD_FRAMES:
        return None
    if name in world.entities:
        return model_state(world, name)
    try:
        return link_state(world, find_link(world, name))
    except LookupError:
        raise LookupError("reference frame '%s' does not exist (neither a model nor a link); "
                          "leave it empty for the world, or name a model (%s) or a link as "
                          "model::link"
                          % (name, ", ".join(world.model_names()) or "none"))


# --- states ---------------------------------------------------------------------------------
def _origin_velocity(linear_com, angular, com, origin):
    """Velocity of the point `origin` of a body whose centre of mass `com` moves at
    linear_com and turns at angular (all world frame). Plain floats: numpy's cross costs
    0.1 ms, and model_states computes this for every moving model."""
    wx, wy, wz = angular
    rx, ry, rz = origin[0] - com[0], origin[1] - com[1], origin[2] - com[2]
    return np.array((linear_com[0] + wy * rz - wz * ry, linear_com[1] + wz * rx - wx * rz,
                     linear_com[2] + wx * ry - wy * rx))


def model_state(world, name):
    """(model frame pose, its velocity, angular velocity) in the world: Gazebo's
    Model::WorldPose, WorldLinearVel (the first link's origin), WorldAngularVel."""
    entity = world.entity(name)
    pose, linear, angular = link_state(world, LinkRef(entity.name, "", entity.body_ids[0], -1, 0))
    return pose.compose(entity.link_offsets[0].inverse()), linear, angular


def model_twist(world, name):
    """The model frame's (linear, angular) velocity, world frame (see model_state)."""
    _, linear, angular = model_state(world, name)
    return linear, angular


def link_state(world, ref: LinkRef):
    """(pose of the link frame, linear velocity of its origin, angular velocity), world."""
    client = world.client
    if ref.link_index < 0:
        entity = world.entities[ref.model]
        pose = world._link_frame(entity, ref.body_slot)
        com = client.getBasePositionAndOrientation(ref.body_id)[0]
        linear, angular = client.getBaseVelocity(ref.body_id)
    else:
        state = client.getLinkState(ref.body_id, ref.link_index, computeLinkVelocity=True,
                                    computeForwardKinematics=True)
        pose = Pose(tuple(state[4]), tuple(state[5]))
        com, linear, angular = state[0], state[6], state[7]
    return pose, _origin_velocity(linear, angular, com, pose.position), np.asarray(angular)


def relative_state(state, frame):
    """A (pose, linear, angular) world state seen from `frame`'s state (None = world), as
    Gazebo's get_*_state computes it: pose in the frame, velocities relative to the frame's,
    rotated into it."""
    if frame is None:
        return state
    pose, linear, angular = state
    frame_pose, frame_linear, frame_angular = frame
    rotation = frame_pose.matrix.T
    return (frame_pose.inverse().compose(pose), rotation @ (linear - frame_linear),
            rotation @ (angular - frame_angular))


def absolute_state(pose, linear, angular, frame):
    """A pose and twist given in `frame` (None = world) as world values: the pose composed
    onto the frame's, the velocities rotated into the world (Gazebo's set_model_state)."""
    if frame is None:
        return pose, np.asarray(linear, dtype=float), np.asarray(angular, dtype=float)
    frame_pose = frame[0]
    rotation = frame_pose.matrix
    return (frame_pose.compose(pose), rotation @ np.asarray(linear, dtype=float),
            rotation @ np.asarray(angular, dtype=float))


def set_link_state(world, ref: LinkRef, pose: Pose, linear, angular):
    """Moves one link (world frame) and sets its origin's velocity. A robot's links other than
    its root move with their joints: ValueError (use set_model_configuration)."""
    entity = world.entities[ref.model]
    if entity.robot is not None and ref.link_index >= 0:
        raise ValueError("link '%s' hangs on a joint of '%s'; the stand-in moves a robot's "
                         "root link only (use set_model_configuration for its joints)"
                         % (ref.scoped, ref.model))
    pose = checked_pose(pose, "link state of '%s'" % ref.scoped, "nothing changed",
                        linear=linear, angular=angular, zero_is_identity=True)
    world.layout_version += 1
    world._place(entity, ref.body_slot, pose)
    com = world.client.getBasePositionAndOrientation(ref.body_id)[0]
    linear_com = _origin_velocity(linear, angular, pose.position, com)
    world.client.resetBaseVelocity(ref.body_id, list(linear_com), list(angular))
    if not entity.static:                   # a sleeping body would ignore its new twist
        world.client.changeDynamics(ref.body_id, -1,
                                    activationState=pybullet.ACTIVATION_STATE_WAKE_UP)
    if entity.static:
        world.caster.reset()


# --- properties -------------------------------------------------------------------------------
def link_properties(world, ref: LinkRef) -> LinkProperties:
    entity = world.entities[ref.model]
    if entity.robot is None:
        inertial = entity.link_specs[ref.body_slot].inertial
        return LinkProperties(inertial.mass, inertial.pose, tuple(inertial.inertia),
                              world.wrenches.gravity_mode(ref.body_id, ref.link_index))
    info = world.client.getDynamicsInfo(ref.body_id, ref.link_index)
    robot = entity.robot
    merged = _lumped_into(world.client, robot).get(ref.link, [])
    mass = info[0] + sum(world.client.getDynamicsInfo(ref.body_id, robot.links[child])[0]
                         for child in merged)           # Gazebo lumps their masses in
    return LinkProperties(mass, Pose(tuple(info[3]), tuple(info[4])), tuple(info[2]),
                          world.wrenches.gravity_mode(ref.body_id, ref.link_index))


def set_link_properties(world, ref: LinkRef, mass, com: Pose, inertia, products, gravity_mode):
    """Mass [kg], principal inertia ixx iyy izz [kg m^2] and gravity mode of a link. The
    stand-in cannot move a link's centre of mass nor take products of inertia: a request that
    changes them is refused (ValueError), as is one on a static model's link."""
    values = [mass] + list(inertia) + list(products) + list(com.position) + list(com.orientation)
    if not all(math.isfinite(v) for v in values):
        raise ValueError("properties of link '%s' hold NaN or inf: %s" % (ref.scoped, values))
    if not mass > 0.0 or min(inertia) < 0.0:
        raise ValueError("link '%s': mass %g must be > 0 kg and ixx iyy izz %s >= 0"
                         % (ref.scoped, mass, tuple(inertia)))
    if any(abs(v) > 1e-12 for v in products):
        raise ValueError("link '%s': products of inertia (ixy ixz iyz) %s are not supported "
                         "by the stand-in (Bullet takes principal moments); send 0"
                         % (ref.scoped, tuple(products)))
    entity = world.entities[ref.model]
    if entity.static:
        raise ValueError("link '%s' belongs to static model '%s'; its mass has no effect"
                         % (ref.scoped, ref.model))
    current = link_properties(world, ref)
    if np.max(np.abs(np.subtract(com.position, current.com.position))) > 1e-9:
        raise ValueError("link '%s': moving the centre of mass (from %s to %s in the link "
                         "frame) is not supported by the stand-in; send the com "
                         "get_link_properties gives"
                         % (ref.scoped, tuple(current.com.position), tuple(com.position)))
    merged = [] if entity.robot is None else [
        entity.robot.links[child]
        for child in _lumped_into(world.client, entity.robot).get(ref.link, [])]
    own_mass = float(mass) - sum(world.client.getDynamicsInfo(ref.body_id, index)[0]
                                 for index in merged)
    if own_mass <= 0.0:
        raise ValueError("link '%s': mass %g kg is not more than what Gazebo merged into it "
                         "(%g kg of fixed child links)" % (ref.scoped, mass, mass - own_mass))
    world.client.changeDynamics(ref.body_id, ref.link_index, mass=own_mass,
                                localInertiaDiagonal=[float(v) for v in inertia])
    for index in [ref.link_index] + merged:
        world.wrenches.set_gravity_mode(ref.scoped, ref.body_id, index, bool(gravity_mode))


def joint_properties(world, ref: JointRef) -> JointProperties:
    info = world.client.getJointInfo(ref.body_id, ref.index)
    kind = JOINT_KINDS.get(info[2], "revolute")
    if kind == "revolute" and info[9] < info[8]:        # URDF continuous: no limits
        kind = "continuous"
    position, rate = world.client.getJointState(ref.body_id, ref.index)[:2]
    return JointProperties(kind, info[6], position, rate)


def model_properties(world, name) -> ModelProperties:
    entity = world.entity(name)
    if entity.robot is None:
        bodies = list(entity.link_names)
        geoms = [c.name for link in entity.link_specs for c in link.collisions]
        return ModelProperties(bodies, geoms, [], entity.static)
    client, robot = world.client, entity.robot
    bodies = [ref.link for ref in links_of(world, name)]
    merged = _lumped_into(client, robot)
    geoms = []
    for link in bodies:
        if client.getCollisionShapeData(robot.body_id, robot.links[link]):
            geoms.append("%s_collision" % link)
        for number, child in enumerate(c for c in merged.get(link, [])
                                       if client.getCollisionShapeData(robot.body_id,
                                                                       robot.links[c])):
            geoms.append("%s_fixed_joint_lump__%s_collision_%d" % (link, child, number + 1))
    joints = [joint for joint, index in robot.joints.items()
              if client.getJointInfo(robot.body_id, index)[2] != pybullet.JOINT_FIXED]
    return ModelProperties(bodies, geoms, joints, entity.static)


def set_model_configuration(world, name, joint_names, positions):
    """Puts the named joints of a model at these positions [rad or m], velocities kept;
    the model's root stays where it is."""
    entity = world.entity(name)
    if len(joint_names) != len(positions):
        raise ValueError("%d joint names but %d positions; send one position per joint"
                         % (len(joint_names), len(positions)))
    if not all(math.isfinite(p) for p in positions):
        raise ValueError("joint positions %s hold NaN or inf" % (list(positions),))
    robot = entity.robot
    movable = {} if robot is None else {
        joint: index for joint, index in robot.joints.items()
        if world.client.getJointInfo(robot.body_id, index)[2] != pybullet.JOINT_FIXED}
    unknown = [j for j in joint_names if j.rpartition("::")[2] not in movable
               or j.rpartition("::")[0] not in ("", name)]
    if unknown:
        raise LookupError("model '%s' has no joint %s; its joints are %s"
                          % (name, ", ".join("'%s'" % j for j in unknown),
                             ", ".join(movable) or "(none)"))
    for joint, position in zip(joint_names, positions):
        index = movable[joint.rpartition("::")[2]]
        velocity = world.client.getJointState(robot.body_id, index)[1]
        world.client.resetJointState(robot.body_id, index, float(position), velocity)
