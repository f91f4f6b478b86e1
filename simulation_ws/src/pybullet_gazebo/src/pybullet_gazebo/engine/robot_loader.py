"""A URDF robot into Bullet: the description parsed once, cleaned for pybullet's loader (with
ground-contact spheres on the driven wheels, see wheel_contact), loaded at a pose, its joints
freed and its links given Gazebo's friction and contact stiffness/damping (surface.py), and the parts its `<gazebo>` tags ask for built
from the registry. A tag the registry does not know is reported by name.
"""
import os
import tempfile

import pybullet

from . import surface, wheel_contact
from .diff_drive import DiffDrive
from .entities import Robot
from .joint_states import JointStatePublisher
from .part import PartContext
from .registry import PLUGIN_PARTS, SENSOR_PARTS, SENSOR_PLUGINS
from .robot_description import (DEFAULT_KD, DEFAULT_KP, DEFAULT_MU, bullet_tree,
                                driven_wheel_links, effective_link_contact,
                                effective_link_friction, urdf_text)
from .specs import RobotSpec
from .transforms import Pose


class SpawnError(ValueError):
    """A model could not be spawned; the message says why and what to do. The world is
    left as it was."""


def load_body(client, spec: RobotSpec, pose: Pose):
    """Loads the robot's multibody at `pose` (its root link frame); returns (body, {wheel
    link: contact link}). SpawnError when Bullet refuses the URDF."""
    tree = bullet_tree(spec)
    contacts = wheel_contact.add_contact_links(tree, driven_wheel_links(spec, PLUGIN_PARTS))
    # the model name stays out of the file name: it may hold '/' or anything else
    handle, path = tempfile.mkstemp(prefix="pybullet_gazebo_", suffix=".urdf")
    try:
        with os.fdopen(handle, "w") as out:
            out.write(urdf_text(tree))
        # inertia as written (not recomputed from the shapes); cylinders as true
        # cylinders, not convex hulls (smooth wheel contact; the ray caster reads them)
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
        try:
            body = client.loadURDF(path, basePosition=pose.position,
                                   baseOrientation=pose.orientation, flags=flags)
        except pybullet.error as err:
            raise SpawnError("model '%s': Bullet could not load the URDF (%s); check the "
                             "description with check_urdf or xacro" % (spec.name, err))
    finally:
        os.unlink(path)
    return body, contacts


def make_robot(client, body, spec: RobotSpec, pose, namespace, contacts, caster, rng, warn,
               command_timeout=0.0, legacy_mode_swaps=False, kinetic_legacy_mode=False,
               ground_mu=None) -> Robot:
    """The Robot of a loaded body: joints freed (Gazebo's joints are free until a plugin
    drives them), friction and contact spring per link (surface.py; `ground_mu`: the
    ground's mu, None without a ground), collision groups, and its parts. SpawnError when a
    sensor sits on a link the URDF lacks or a part cannot be built; `warn` gets each tag the
    stand-in does not simulate."""
    joints, links = {}, {spec.root_link: -1}
    for index in range(client.getNumJoints(body)):
        info = client.getJointInfo(body, index)
        joints[info[1].decode()] = index
        links[info[12].decode()] = index
        client.setJointMotorControl2(body, index, pybullet.VELOCITY_CONTROL, force=0.0)
    friction = effective_link_friction(spec)      # Bullet's friction is per link
    contact = effective_link_contact(spec)
    surfaces = {}                                 # link: (Gazebo's mu, contact spring)
    for link, index in links.items():
        surfaces[link] = (friction.get(link, (DEFAULT_MU,))[0],
                          surface.Contact(*contact.get(link, (DEFAULT_KP, DEFAULT_KD))))
        surface.apply(client, body, index, surface.bullet_friction(surfaces[link][0]),
                      surfaces[link][1])
    wheel_contact.apply_groups(client, body, links, contacts, surfaces, ground_mu)
    robot = Robot(spec.name, body, namespace, joints, links, pose)
    context = PartContext(client, body, spec.name, joints, links, spec, caster, rng,
                          warn=lambda m: warn("model '%s': %s" % (spec.name, m)),
                          command_timeout=command_timeout,
                          legacy_mode_swaps=legacy_mode_swaps,
                          kinetic_legacy_mode=kinetic_legacy_mode)
    for plugin in spec.plugins:
        part_class = PLUGIN_PARTS.get(plugin.filename)
        if part_class is None:
            warn("model '%s': plugin '%s' (%s) is not simulated by the stand-in; ignored"
                 % (spec.name, plugin.name, plugin.filename))
            continue
        robot.parts.append(_build(part_class, context, plugin))
    if not robot.parts_with(JointStatePublisher.KEY):
        # the drive's wheel joint states, for rviz (see joint_states.py)
        for drive in robot.parts_with(DiffDrive.KEY):
            robot.parts.append(JointStatePublisher.for_wheels(context, drive))
    for sensor in spec.sensors:
        if sensor.link not in links:
            raise SpawnError("model '%s': sensor '%s' is on link '%s', which the URDF does "
                             "not have" % (spec.name, sensor.name, sensor.link))
        if sensor.plugin is not None and sensor.plugin.filename not in SENSOR_PLUGINS:
            warn("model '%s': sensor plugin '%s' is not simulated by the stand-in; sensor "
                 "'%s' publishes nothing" % (spec.name, sensor.plugin.filename, sensor.name))
            continue
        robot.parts.append(_build(SENSOR_PARTS["ray"], context, sensor))
    return robot


def _build(part_class, context, spec):
    try:
        return part_class.build(context, spec)
    except ValueError as err:        # a part names what is wrong with its tag
        raise SpawnError("model '%s': %s" % (context.model_name, err))
