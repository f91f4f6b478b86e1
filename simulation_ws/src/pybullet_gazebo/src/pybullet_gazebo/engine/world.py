"""The simulated world: Bullet bodies built from a WorldSpec, robots spawned from URDF with
the components their `<gazebo>` tags ask for, fixed-step stepping, and what Gazebo's world
services need (model states, reset, delete, contacts).

Frames: a model's pose is its model frame in the world, as Gazebo reports it. A world model
becomes one Bullet body per link: a rigid body in maximal coordinates (world02 steps 15 %
faster than with multibodies), or a multibody when it holds a plane (pybullet cannot report a
maximal body's shapes, and the ground checks read the plane back). A robot is one Bullet
multibody loaded from its URDF, whose model frame is its root link's frame. Bullet reports a
body's inertial (centre-of-mass) frame; `_link_frame` converts, with the offsets kept in the
Entity (pybullet 3.2 reports garbage for a maximal body's inertial frame).
"""
from dataclasses import dataclass, field
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from typing import Callable, Dict, List, Optional

import numpy as np
import pybullet

from . import wheel_contact
from .raycast import RayCaster
from .registry import PLUGINS, SENSOR_PLUGINS, SENSORS
from .robot_description import DEFAULT_MU, effective_link_friction, parse_robot, strip_for_bullet
from .specs import Box, Cylinder, Mesh, Plane, Sphere, WorldSpec
from .transforms import Pose


# Bounds on what a request may ask: Bullet's state overflows to NaN for extreme values (a
# twist of 1e160 turns every touching body's pose into NaN), and far from the origin contacts
# and rays lose their precision. Nothing the tutorial does comes near them.
MAX_COORDINATE = 1.0e6          # [m] per axis, for a spawn or set_model_state position
MAX_VELOCITY = 1.0e6            # [m/s] and [rad/s] per axis, for a set_model_state twist


class SpawnError(ValueError):
    """A model could not be spawned; the message says why and what to do. The world is
    left as it was."""


class ModelNotFound(KeyError):
    def __str__(self):
        return str(self.args[0])


@dataclass
class Robot:
    """A model spawned from a URDF, with its components."""
    name: str
    body_id: int
    namespace: str
    joints: Dict[str, int]
    links: Dict[str, int]
    initial_pose: Pose
    components: list = field(default_factory=list)


@dataclass
class Entity:
    """A model in the world: its Bullet bodies (one per link) and where it started."""
    name: str
    body_ids: List[int]
    link_offsets: List[Pose]        # each body's link frame in the model frame
    inertial_offsets: List[Pose]    # each body's inertial frame in its link frame
    initial_pose: Pose              # model frame in the world at load/spawn
    static: bool
    is_ground: bool = False
    robot: Optional[Robot] = None
    # a world model's collision shapes per body, as getCollisionShapeData reports them
    # (which pybullet cannot do for maximal bodies): see _shape_data. Empty for a robot.
    shapes: List[list] = field(default_factory=list)


@dataclass(frozen=True)
class ContactEvent:
    """The start of a touch between a robot and another model (the ground excluded)."""
    sim_time: float                 # [s]
    robot: str
    other: str


@dataclass(frozen=True)
class Reading:
    """A component's output that is due this step (a scan, an odometry)."""
    robot: Robot
    component: object
    data: object


class World:
    """Everything the simulator steps. `warn(message)` receives each problem once."""

    def __init__(self, client, spec: WorldSpec, step_size: float, seed: int = 0,
                 warn: Callable[[str], None] = print, command_timeout: float = 0.0):
        if not (step_size > 0.0 and math.isfinite(step_size)):
            raise ValueError("step_size %r must be a positive number of seconds" % step_size)
        self.client = client
        self.spec = spec
        self.step_size = step_size                   # [s]
        self.seed = seed
        self.command_timeout = command_timeout       # [s]; 0 = hold the last command for ever
        self.warn = warn
        self.rng = np.random.default_rng(seed)
        self.step_count = 0
        self.entities: Dict[str, Entity] = {}
        self.contact_events: List[ContactEvent] = []
        self._touching = set()                       # (robot, other) pairs touching now
        self._body_owner: Dict[int, str] = {}
        self._robots: Optional[List[Robot]] = None  # cache of robots()
        self.caster = RayCaster(client)

        client.resetSimulation()
        client.setGravity(*spec.physics.gravity)
        # collision groups filter with AND, Bullet's own rule (see wheel_contact)
        client.setPhysicsEngineParameter(fixedTimeStep=step_size, numSubSteps=1,
                                         collisionFilterMode=0)
        for message in spec.warnings:
            warn(message)
        for model in spec.models:
            self._add_world_model(model)

    # --- time ---------------------------------------------------------------------------
    @property
    def sim_time(self) -> float:
        return self.step_count * self.step_size

    def step(self) -> List[Reading]:
        """Advances physics by one fixed step; returns the components' outputs now due."""
        now = self.sim_time
        robots = self.robots()
        for robot in robots:
            for component in robot.components:
                if hasattr(component, "before_step"):
                    component.before_step(now, self.step_size)
        self.client.stepSimulation()
        self.step_count += 1
        now = self.sim_time
        readings = []
        for robot in robots:
            for component in robot.components:
                if hasattr(component, "after_step"):
                    component.after_step(now)
                if component.due(now):
                    readings.append(Reading(robot, component, self._read(component, now)))
        self._track_contacts(robots)
        return readings

    def next_command_time(self):
        """Earliest sim time [s] at which a drive next reads its command (None: no drive).
        A command given before the step starting at that time is used from then on."""
        times = [c.next_update_time() for robot in self.robots() for c in robot.components
                 if hasattr(c, "next_update_time")]
        return min(times) if times else None

    @staticmethod
    def _read(component, now):
        return component.measure(now) if hasattr(component, "measure") else component.odometry()

    # --- models -------------------------------------------------------------------------
    def model_names(self) -> List[str]:
        return list(self.entities)

    def robots(self) -> List[Robot]:
        if self._robots is None:         # stepped 200 times a second: kept until one comes or goes
            self._robots = [e.robot for e in self.entities.values() if e.robot is not None]
        return list(self._robots)

    def entity(self, name) -> Entity:
        try:
            return self.entities[name]
        except KeyError:
            raise ModelNotFound("model '%s' does not exist; models are: %s"
                                % (name, ", ".join(self.entities) or "(none)"))

    def model_pose(self, name) -> Pose:
        entity = self.entity(name)
        return self._link_frame(entity, 0).compose(entity.link_offsets[0].inverse())

    def model_twist(self, name):
        """(linear, angular) velocity of the model's first body, world frame [m/s], [rad/s]."""
        linear, angular = self.client.getBaseVelocity(self.entity(name).body_ids[0])
        return np.array(linear), np.array(angular)

    def set_model_state(self, name, pose: Pose, linear=(0, 0, 0), angular=(0, 0, 0)):
        """Teleports a model (its model frame to `pose`, world frame) and sets its velocity."""
        values = list(pose.position) + list(pose.orientation) + list(linear) + list(angular)
        if not all(math.isfinite(v) for v in values):
            raise ValueError("model state for '%s' has a non-finite value; nothing changed" % name)
        if max(abs(v) for v in pose.position) > MAX_COORDINATE:
            raise ValueError("position of '%s' %s is over %g m from the origin; nothing changed"
                             % (name, tuple(pose.position), MAX_COORDINATE))
        if max(abs(v) for v in list(linear) + list(angular)) > MAX_VELOCITY:
            raise ValueError("twist of '%s' (linear %s, angular %s) is over %g m/s or rad/s; "
                             "nothing changed"
                             % (name, tuple(linear), tuple(angular), MAX_VELOCITY))
        norm = math.sqrt(sum(q * q for q in pose.orientation))
        if norm < 1e-9:
            raise ValueError("orientation of '%s' is a zero quaternion; nothing changed" % name)
        pose = Pose(pose.position, tuple(q / norm for q in pose.orientation))
        entity = self.entity(name)
        for index, body in enumerate(entity.body_ids):
            self._place(entity, index, pose.compose(entity.link_offsets[index]))
            self.client.resetBaseVelocity(body, list(linear), list(angular))
        if entity.static:
            self.caster.reset()             # it caches static shapes where they were
        if entity.robot is not None:
            for index in entity.robot.joints.values():
                self.client.resetJointState(entity.body_ids[0], index, 0.0, 0.0)

    def delete_model(self, name):
        entity = self.entity(name)
        for body in entity.body_ids:
            self.caster.remove_body(body)
            self.client.removeBody(body)
            self._body_owner.pop(body, None)
        del self.entities[name]
        self._robots = None
        self._touching = {pair for pair in self._touching if name not in pair}

    def reset_world(self):
        """Every model back to its initial pose at rest; components forget their commands.
        Sim time goes on (Gazebo's reset_world)."""
        for entity in self.entities.values():
            self.set_model_state(entity.name, entity.initial_pose)
            if entity.robot is not None:
                for component in entity.robot.components:
                    component.reset()
        self._touching.clear()

    def reset_simulation(self):
        """reset_world, and sim time back to 0 (Gazebo's reset_simulation)."""
        self.reset_world()
        self.step_count = 0
        self.rng = np.random.default_rng(self.seed)
        for robot in self.robots():
            for component in robot.components:
                if hasattr(component, "rng"):
                    component.rng = self.rng

    # --- spawning -----------------------------------------------------------------------
    def spawn_urdf(self, name: str, urdf_xml: str, pose: Pose, namespace: str = "") -> Robot:
        """Loads a URDF robot at `pose` (its root link frame, world) with the components its
        `<gazebo>` tags ask for. Raises SpawnError (world unchanged) when it cannot."""
        if not name or not name.strip():
            raise SpawnError("model name is empty; pass -model NAME")
        if name in self.entities:
            raise SpawnError("SpawnModel: Failure - entity already exists: model '%s' is in the "
                             "world; delete it first or choose another -model name" % name)
        values = list(pose.position) + list(pose.orientation)
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
            raise SpawnError("spawn pose of '%s' is not finite: %s; pass numbers for -x -y -z"
                             % (name, values))
        if max(abs(v) for v in pose.position) > MAX_COORDINATE:
            raise SpawnError("spawn position of '%s' %s is over %g m from the origin; pass -x -y "
                             "-z within the world" % (name, tuple(pose.position), MAX_COORDINATE))
        norm = math.sqrt(sum(q * q for q in pose.orientation))
        if norm < 1e-9:          # Bullet would keep it and the robot's sensors would see NaN
            raise SpawnError("spawn orientation of '%s' is a zero quaternion %s; pass a unit "
                             "quaternion (or -R -P -Y)" % (name, tuple(pose.orientation)))
        pose = Pose(pose.position, tuple(q / norm for q in pose.orientation))
        try:
            spec = parse_robot(urdf_xml, name)
        except Exception as err:   # the parser names what is wrong with the description
            raise SpawnError("model '%s': %s" % (name, err))
        urdf_text, contacts = wheel_contact.add_contact_links(
            strip_for_bullet(urdf_xml), self._driven_wheel_links(urdf_xml, spec))
        body = self._load_urdf(name, urdf_text, pose)
        try:
            robot = self._make_robot(name, body, spec, pose, namespace)
            wheel_contact.apply_groups(self.client, body, robot.links, contacts)
            inside = self._overlapping_models(body)
            if inside:
                raise SpawnError("spawn pose (%.3f, %.3f, %.3f) puts '%s' inside %s; choose a "
                                 "free pose" % (pose.position + (name, ", ".join(inside))))
            below = self._grounds_above(body)
            if below:
                raise SpawnError("spawn pose (%.3f, %.3f, %.3f) puts all of '%s' under %s; "
                                 "raise -z" % (pose.position + (name, ", ".join(below))))
        except Exception:
            self.client.removeBody(body)
            raise
        for message in spec.warnings:
            self.warn("model '%s': %s" % (name, message))
        inertial = Pose(*self.client.getDynamicsInfo(body, -1)[3:5])   # reliable for multibodies
        self._robots = None
        self.entities[name] = Entity(name, [body], [Pose()], [inertial], pose, static=False,
                                     robot=robot)
        self._body_owner[body] = name
        self.caster.add_body(body, static=False)
        return robot

    @staticmethod
    def _driven_wheel_links(urdf_xml, spec):
        """Child links of the joints the robot's drive plugins name."""
        joint_names = {value for plugin in spec.plugins if plugin.filename in PLUGINS
                       for key, value in plugin.params.items() if key in ("leftJoint", "rightJoint")}
        root = ET.fromstring(urdf_xml)
        return {joint.find("child").get("link") for joint in root.findall("joint")
                if joint.get("name") in joint_names and joint.find("child") is not None}

    def _load_urdf(self, name, urdf_text, pose):
        # the model name stays out of the file name: it may hold '/' or anything else
        handle, path = tempfile.mkstemp(prefix="pybullet_gazebo_", suffix=".urdf")
        try:
            with os.fdopen(handle, "w") as out:
                out.write(urdf_text)
            # inertia as written (not recomputed from the shapes); cylinders as true
            # cylinders, not convex hulls (smooth wheel contact; the ray caster reads them)
            flags = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
            try:
                body = self.client.loadURDF(path, basePosition=pose.position,
                                            baseOrientation=pose.orientation, flags=flags)
            except pybullet.error as err:
                raise SpawnError("model '%s': Bullet could not load the URDF (%s); check the "
                                 "description with check_urdf or xacro" % (name, err))
        finally:
            os.unlink(path)
        return body

    def _make_robot(self, name, body, spec, pose, namespace) -> Robot:
        client = self.client
        joints, links = {}, {spec.root_link: -1}
        for index in range(client.getNumJoints(body)):
            info = client.getJointInfo(body, index)
            joints[info[1].decode()] = index
            links[info[12].decode()] = index
            # Bullet motorises every joint by default; Gazebo's joints are free until a
            # plugin drives them.
            client.setJointMotorControl2(body, index, pybullet.VELOCITY_CONTROL, force=0.0)
        friction = effective_link_friction(spec)      # Bullet's friction is per link
        for link, index in links.items():
            client.changeDynamics(body, index, lateralFriction=friction.get(link, (DEFAULT_MU,))[0])
        robot = Robot(name, body, namespace, joints, links, pose)
        for plugin in spec.plugins:
            component_class = PLUGINS.get(plugin.filename)
            if component_class is None:
                self.warn("model '%s': plugin '%s' (%s) is not simulated by the stand-in; "
                          "ignored" % (name, plugin.name, plugin.filename))
                continue
            robot.components.append(component_class(
                client, body, joints, plugin, warn=lambda m: self.warn("model '%s': %s" % (name, m)),
                command_timeout=self.command_timeout))
        for sensor in spec.sensors:
            if sensor.link not in links:
                raise SpawnError("model '%s': sensor '%s' is on link '%s', which the URDF does "
                                 "not have" % (name, sensor.name, sensor.link))
            if sensor.plugin is not None and sensor.plugin.filename not in SENSOR_PLUGINS:
                self.warn("model '%s': sensor plugin '%s' is not simulated by the stand-in; "
                          "sensor '%s' publishes nothing" % (name, sensor.plugin.filename, sensor.name))
                continue
            robot.components.append(SENSORS["ray"](client, body, links[sensor.link], sensor,
                                                   self.caster, self.rng))
        return robot

    def _overlapping_models(self, body) -> List[str]:
        """Names of the models (the ground excluded) the body penetrates."""
        self.client.performCollisionDetection()
        names = set()
        for other_body, owner in self._body_owner.items():
            if self.entities[owner].is_ground:
                continue
            for point in self.client.getClosestPoints(body, other_body, distance=0.0):
                if point[8] < -0.001:      # contact distance [m]; negative = penetration
                    names.add(owner)
        return sorted(names)

    def _grounds_above(self, body) -> List[str]:
        """Names of the ground models whose plane has the whole body (every corner of its
        links' bounding boxes) on its underside. Bullet's plane is a half-space: a body
        under it would be thrown out of the ground, not left to fall."""
        corners = []
        for link in range(-1, self.client.getNumJoints(body)):
            low, high = self.client.getAABB(body, link)
            corners += [(x, y, z) for x in (low[0], high[0]) for y in (low[1], high[1])
                        for z in (low[2], high[2])]
        corners = np.array(corners)
        names = set()
        for entity in self.entities.values():
            if not entity.is_ground:
                continue
            for ground in entity.body_ids:
                position, orientation = self.client.getBasePositionAndOrientation(ground)
                frame = Pose(tuple(position), tuple(orientation))    # shapes sit in this frame
                for shape in self.client.getCollisionShapeData(ground, -1):
                    if shape[2] != pybullet.GEOM_PLANE:
                        continue
                    plane = frame.compose(Pose(tuple(shape[5]), tuple(shape[6])))
                    normal = plane.matrix @ np.asarray(shape[3], dtype=float)
                    if np.max((corners - np.asarray(plane.position)) @ normal) < 0.0:
                        names.add(entity.name)
        return sorted(names)

    def positive_turn_direction(self, robot) -> Optional[str]:
        """'clockwise' or 'counter-clockwise': which way a positive angular.z turns the robot
        seen from above, given where the drive's named joints really are. None without a drive.

        gazebo_ros_diff_drive gives the joint *named* by rightJoint the faster wheel for a
        positive angular.z, whatever side it is on; if it sits on the robot's left (+y), the
        robot turns clockwise."""
        for component in robot.components:
            if not hasattr(component, "right_joint"):
                continue
            root = self.model_pose(robot.name)
            def lateral(joint):
                world_position = self.client.getLinkState(
                    robot.body_id, robot.joints[joint], computeForwardKinematics=True)[4]
                return root.inverse().transform_point(world_position)[1]
            faster_on_left = lateral(component.right_joint) > lateral(component.left_joint)
            if getattr(component, "legacy_mode", False):
                faster_on_left = not faster_on_left
            return "clockwise" if faster_on_left else "counter-clockwise"
        return None

    # --- contacts -----------------------------------------------------------------------
    def _track_contacts(self, robots):
        touching = set()
        for robot in robots:
            for point in self.client.getContactPoints(bodyA=robot.body_id):
                owner = self._body_owner.get(point[2])
                if owner is None or owner == robot.name or self.entities[owner].is_ground:
                    continue
                touching.add((robot.name, owner))
        for pair in sorted(touching - self._touching):
            self.contact_events.append(ContactEvent(self.sim_time, *pair))
        self._touching = touching

    def touching(self):
        """(robot, other model) pairs in contact after the last step."""
        return sorted(self._touching)

    # --- building world models ------------------------------------------------------------
    def _add_world_model(self, model):
        bodies, offsets, inertials, shapes = [], [], [], []
        all_planes = True
        for link in model.links:
            collisions = [c for c in link.collisions if not isinstance(c.geometry, Mesh)]
            if not collisions:
                continue
            all_planes &= all(isinstance(c.geometry, Plane) for c in collisions)
            body = self._create_link_body(model, link, collisions)
            bodies.append(body)
            offsets.append(link.pose)
            inertials.append(link.inertial.pose)
            shapes.append([_shape_data(c, link.inertial.pose) for c in collisions])
        if not bodies:
            self.warn("model '%s' has no collision the stand-in can simulate; it is not in the "
                      "physics world" % model.name)
            return
        entity = Entity(model.name, bodies, offsets, inertials, model.pose, model.static,
                        is_ground=all_planes, shapes=shapes)
        self.entities[model.name] = entity
        for body, body_shapes in zip(bodies, shapes):
            self._body_owner[body] = model.name
            if all_planes:
                wheel_contact.mark_ground(self.client, body)
            else:
                self.caster.add_body(body, static=model.static, base_shapes=body_shapes)

    def _create_link_body(self, model, link, collisions):
        client = self.client
        if len(collisions) == 1 and isinstance(collisions[0].geometry, Plane):
            shape = client.createCollisionShape(pybullet.GEOM_PLANE,
                                                planeNormal=collisions[0].geometry.normal)
        else:
            kwargs = dict(shapeTypes=[], radii=[], halfExtents=[], lengths=[], planeNormals=[],
                          collisionFramePositions=[], collisionFrameOrientations=[])
            for collision in collisions:
                self._append_shape(kwargs, collision)
            shape = client.createCollisionShapeArray(**kwargs)
        world_pose = model.pose.compose(link.pose)
        inertial = link.inertial
        mass = 0.0 if model.static else inertial.mass
        body = client.createMultiBody(
            baseMass=mass, baseCollisionShapeIndex=shape,
            basePosition=world_pose.position, baseOrientation=world_pose.orientation,
            baseInertialFramePosition=inertial.pose.position,
            baseInertialFrameOrientation=inertial.pose.orientation,
            useMaximalCoordinates=not any(isinstance(c.geometry, Plane) for c in collisions))
        if mass > 0.0:
            # Gazebo lets resting bodies sleep (auto-disable); so does Bullet, when asked
            # (the mass again: without it pybullet 3.2 sets a maximal body's mass to 0 -> NaN)
            client.changeDynamics(body, -1, mass=mass, localInertiaDiagonal=list(inertial.inertia),
                                  activationState=pybullet.ACTIVATION_STATE_ENABLE_SLEEPING)
        client.changeDynamics(body, -1, lateralFriction=collisions[0].mu)
        return body

    @staticmethod
    def _append_shape(kwargs, collision):
        kind, dimensions = _bullet_geometry(collision)
        radius, half, length, normal = 0.0, [0.0, 0.0, 0.0], 0.0, [0.0, 0.0, 1.0]
        if kind == pybullet.GEOM_BOX:
            half = [s / 2.0 for s in dimensions]
        elif kind == pybullet.GEOM_CYLINDER:
            length, radius = dimensions[0], dimensions[1]
        elif kind == pybullet.GEOM_SPHERE:
            radius = dimensions[0]
        else:
            normal = list(dimensions)
        kwargs["shapeTypes"].append(kind)
        kwargs["radii"].append(radius)
        kwargs["halfExtents"].append(half)
        kwargs["lengths"].append(length)
        kwargs["planeNormals"].append(normal)
        kwargs["collisionFramePositions"].append(list(collision.pose.position))
        kwargs["collisionFrameOrientations"].append(list(collision.pose.orientation))

    # --- frames -------------------------------------------------------------------------
    def _link_frame(self, entity, index) -> Pose:
        """World pose of the link frame of an entity's `index`th body (Bullet reports its
        inertial frame)."""
        position, orientation = self.client.getBasePositionAndOrientation(entity.body_ids[index])
        inertial = Pose(tuple(position), tuple(orientation))
        return inertial.compose(entity.inertial_offsets[index].inverse())

    def _place(self, entity, index, link_pose: Pose):
        inertial = link_pose.compose(entity.inertial_offsets[index])
        self.client.resetBasePositionAndOrientation(entity.body_ids[index], inertial.position,
                                                    inertial.orientation)


def _shape_data(collision, inertial_pose):
    """A collision as pybullet's getCollisionShapeData reports one: (geometry type,
    dimensions, position, orientation), the pose in the link's inertial frame. The caster
    needs it for the bodies whose shapes pybullet cannot report."""
    kind, dimensions = _bullet_geometry(collision)
    local = inertial_pose.inverse().compose(collision.pose)
    return kind, dimensions, local.position, local.orientation


def _bullet_geometry(collision):
    """(Bullet geometry type, dimensions as getCollisionShapeData gives them: box full
    extents, cylinder (length, radius, 0), sphere (r, r, r), plane normal) of a collision;
    ValueError for a geometry the stand-in cannot simulate."""
    geometry = collision.geometry
    if isinstance(geometry, Box):
        kind, dimensions = pybullet.GEOM_BOX, tuple(geometry.size)
    elif isinstance(geometry, Cylinder):
        kind, dimensions = pybullet.GEOM_CYLINDER, (geometry.length, geometry.radius, 0.0)
    elif isinstance(geometry, Sphere):
        kind, dimensions = pybullet.GEOM_SPHERE, (geometry.radius,) * 3
    elif isinstance(geometry, Plane):
        kind, dimensions = pybullet.GEOM_PLANE, tuple(geometry.normal)
    else:
        raise ValueError("collision '%s': geometry %r is not supported"
                         % (collision.name, geometry))
    return kind, dimensions
