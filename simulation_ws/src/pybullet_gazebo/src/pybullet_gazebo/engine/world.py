"""The simulated world: stepping at a fixed step, the models in it, and what Gazebo's world
services need (model states, reset, delete, spawn, contacts).

Jobs elsewhere: stepping.py advances time (World.advance delegates to its Stepper),
bodies.py builds world models' bodies, robot_loader.py loads URDF robots and their parts,
placement.py checks requested poses and overlaps, contacts.py tracks touches, batching.py
runs quiet stretches of steps in one Bullet call.

Frames: a model's pose is its model frame in the world, as Gazebo reports it. A robot is one
Bullet multibody whose model frame is its root link's frame. Bullet reports a body's inertial
(centre-of-mass) frame; `_link_frame` converts, with the offsets kept in the Entity (pybullet
3.2 reports garbage for a maximal body's inertial frame).
"""
import math
from dataclasses import replace
from typing import Callable, Dict, List, Optional

import numpy as np
import pybullet

from . import wheel_contact
from .batching import GuardedRobot, bounding_radius
from .bodies import build_model
from .contacts import ContactTracker
from .entities import Entity, Reading, Robot
from .placement import checked_pose, grounds_above, overlapping
from .raycast import RayCaster
from .robot_description import parse_robot
from .robot_loader import SpawnError, load_body, make_robot
from .sdf_world import load_model_text
from .stepping import Stepper
from .specs import WorldSpec
from .transforms import Pose
from .wrenches import WrenchSchedule

__all__ = ["World", "SpawnError", "ModelNotFound", "Robot", "Entity", "Reading"]

PARKING_HEIGHT = 1000.0      # [m] above its pose, where a teleported body sheds its contacts


class ModelNotFound(KeyError):
    def __str__(self):
        return str(self.args[0])


class World:
    """Everything the simulator steps. `warn(message)` receives each problem once.
    `legacy_mode_swaps`: diff drives with <legacyMode>true swap their wheels as Kinetic did.
    `legacy_mode`: every diff drive behaves as Kinetic's with <legacyMode>true, whatever the
    URDF says (the simulator's legacy_mode:=true)."""

    def __init__(self, client, spec: WorldSpec, step_size: float, seed: int = 0,
                 warn: Callable[[str], None] = print, command_timeout: float = 0.0,
                 legacy_mode_swaps: bool = False, legacy_mode: bool = False):
        if not (step_size > 0.0 and math.isfinite(step_size)):
            raise ValueError("step_size %r must be a positive number of seconds" % step_size)
        self.client = client
        self.spec = spec
        self.step_size = step_size                   # [s]
        self.seed = seed
        self.command_timeout = command_timeout       # [s]; 0 = hold the last command for ever
        self.legacy_mode_swaps = legacy_mode_swaps
        self.legacy_mode = legacy_mode
        self.warn = warn
        self.rng = np.random.default_rng(seed)
        self.step_count = 0
        self.entities: Dict[str, Entity] = {}
        self.contacts = ContactTracker()
        self._body_owner: Dict[int, str] = {}
        self._robots: Optional[List[Robot]] = None  # cache of robots()
        self._stepped = ([], [])                    # cache: (robot, part) pairs, (name, body)
        self._guarded = ([], [], frozenset())       # cache: GuardedRobots, others, ground bodies
        self._statics = frozenset()                 # cache: bodies of static models
        self.stepper = Stepper(self, client)        # stepping.py: advance's machinery
        self._grounds = set()                       # names of the ground models
        self.caster = RayCaster(client)
        self.gravity = tuple(spec.physics.gravity)   # [m/s^2]
        self.wrenches = WrenchSchedule(client, self.gravity)   # apply_body_wrench & co.
        self.layout_version = 0     # counts teleports and deletions (caches of static poses)
        self._time_before = 0.0     # [s] sim time before the step size last changed ...
        self._steps_before = 0      # ... and the step count then

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
        return self._time_at(self.step_count)

    def sim_time_ns(self) -> int:
        """Sim time in integer nanoseconds: exact, never drifts over millions of steps."""
        return int(round(self._time_before * 1e9)) + \
            (self.step_count - self._steps_before) * int(round(self.step_size * 1e9))

    def set_step_size(self, step_size):
        """A new fixed physics step [s] from the next step on; sim time runs on from where it
        is (Gazebo's set_physics_properties time_step)."""
        if not (isinstance(step_size, (int, float)) and math.isfinite(step_size)
                and 0.0 < step_size <= 1.0):
            raise ValueError("time_step %r must be a number of seconds in (0, 1]" % (step_size,))
        self._time_before = self.sim_time
        self._steps_before = self.step_count
        self.step_size = float(step_size)
        self.client.setPhysicsEngineParameter(fixedTimeStep=self.step_size)

    def set_gravity(self, gravity):
        """Gravity [m/s^2], world frame, from the next step on."""
        if len(gravity) != 3 or not all(math.isfinite(g) for g in gravity):
            raise ValueError("gravity %s must be three finite numbers [m/s^2]" % (tuple(gravity),))
        self.gravity = tuple(float(g) for g in gravity)
        self.wrenches.gravity = np.asarray(self.gravity)
        self.client.setGravity(*self.gravity)
        for entity in self.entities.values():     # sleeping bodies would not feel the change
            if not entity.static:
                for body in entity.body_ids:
                    self.client.changeDynamics(
                        body, -1, activationState=pybullet.ACTIVATION_STATE_WAKE_UP)

    def _time_at(self, count: int) -> float:
        """Sim time [s] at step count `count` of the present step size (as sim_time reads
        it then, to the last bit)."""
        return self._time_before + (count - self._steps_before) * self.step_size

    def time_after(self, steps: int) -> float:
        """Sim time [s] after `steps` more physics steps of the present size (as sim_time will
        then read, to the last bit)."""
        return self._time_at(self.step_count + steps)

    def times_after(self, steps: int) -> List[float]:
        """[time_after(1), ..., time_after(steps)], to the last bit."""
        at, count = self._time_at, self.step_count
        return [at(count + k) for k in range(1, steps + 1)]

    def step(self, collect=True) -> List[Reading]:
        """Advances physics by one fixed step; returns the parts' readings now due. `collect`:
        True = every part's, or a collection of the parts whose readings are wanted (empty:
        none); the other parts due now skip theirs (Part.skip), their schedules and noise
        going on as if they had measured."""
        return self.advance(1, collect)

    def advance(self, steps, collect=True, touched=None, until_news=False,
                collect_from=0, continues=False, horizon=None) -> List[Reading]:
        """`steps` fixed physics steps from now; the readings due in them (see
        stepping.Stepper.advance for every argument)."""
        return self.stepper.advance(steps, collect, touched, until_news, collect_from,
                                    continues, horizon)

    def next_command_time(self):
        """Earliest sim time [s] at which a part next reads its command (None: no part takes
        commands). A command given before the step starting at that time is used from then."""
        times = [t for robot in self.robots() for part in robot.parts
                 for t in (part.next_command_time(),) if t is not None]
        return min(times) if times else None

    # --- models -------------------------------------------------------------------------
    def model_names(self) -> List[str]:
        return list(self.entities)

    def robots(self) -> List[Robot]:
        if self._robots is None:         # stepped 200 times a second: kept until one comes or goes
            self._robots = [e.robot for e in self.entities.values() if e.robot is not None]
            self._stepped = ([(r, p) for r in self._robots for p in r.parts],
                             [(r.name, r.body_id) for r in self._robots])
            self._guarded = self._guard_lists()
            self._statics = frozenset(body for e in self.entities.values()
                                      if e.static and not e.is_ground for body in e.body_ids)
            self.stepper.layout_changed()
        return list(self._robots)

    def _guard_lists(self):
        """(GuardedRobots, [(body, radius)] of the other dynamic models, ground bodies):
        what batching.Batcher.contact_free needs."""
        robots = [GuardedRobot(self.client, r.body_id) for r in self._robots]
        others = [(body, bounding_radius(self.client, body, -1, shapes))
                  for e in self.entities.values()
                  if e.robot is None and not e.static and not e.is_ground
                  for body, shapes in zip(e.body_ids, e.shapes or [None] * len(e.body_ids))]
        grounds = frozenset(b for b, owner in self._body_owner.items() if owner in self._grounds)
        return robots, others, grounds

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
        """Teleports a model (its model frame to `pose`, world frame) and sets its velocity.
        An all-zero quaternion is the identity, as Gazebo normalizes it."""
        entity = self.entity(name)
        pose = checked_pose(pose, "model state of '%s'" % name, "nothing changed",
                            linear=linear, angular=angular, zero_is_identity=True)
        self._teleport(entity, pose, linear, angular)
        if entity.static:
            self.caster.reset()             # it caches static shapes where they were

    def _teleport(self, entity, pose, linear=(0, 0, 0), angular=(0, 0, 0)):
        """set_model_state's move, without the caster's refresh of static shapes."""
        self.layout_version += 1
        if not entity.static:
            self._drop_cached_contacts(entity)
        for index, body in enumerate(entity.body_ids):
            self._place(entity, index, pose.compose(entity.link_offsets[index]))
            self.client.resetBaseVelocity(body, list(linear), list(angular))
            if not entity.static:           # a sleeping body would ignore its new twist
                self.client.changeDynamics(body, -1,
                                           activationState=pybullet.ACTIVATION_STATE_WAKE_UP)
        if entity.robot is not None:
            for index in entity.robot.joints.values():
                self.client.resetJointState(entity.body_ids[0], index, 0.0, 0.0)

    def delete_model(self, name):
        entity = self.entity(name)
        self.wrenches.forget_bodies(entity.body_ids)
        self.layout_version += 1
        for body in entity.body_ids:
            self.caster.remove_body(body)
            self.client.removeBody(body)
            self._body_owner.pop(body, None)
        del self.entities[name]
        self._grounds.discard(name)
        self._robots = None
        self.contacts.forget(name)

    def reset_world(self):
        """Every model back to its initial pose at rest; parts forget their commands.
        Sim time goes on (Gazebo's reset_world)."""
        for entity in self.entities.values():
            self._teleport(entity, entity.initial_pose)
            if entity.robot is not None:
                for part in entity.robot.parts:
                    part.reset()
        self.caster.reset()       # once for all static models (per model: 50 ms in world02)
        self.contacts.forget()

    def reset_simulation(self):
        """reset_world, and sim time back to 0 (Gazebo's reset_simulation)."""
        self.reset_world()
        self.wrenches.clear()               # their windows are in the sim time left behind
        self.step_count = 0
        self._time_before, self._steps_before = 0.0, 0
        self.rng = np.random.default_rng(self.seed)
        for robot in self.robots():
            for part in robot.parts:
                part.reseed(self.rng)

    # --- contacts -----------------------------------------------------------------------
    @property
    def contact_events(self):
        """The most recent touch onsets (ContactEvent), oldest first; bounded."""
        return list(self.contacts.events)

    def touching(self):
        """(robot, other model) pairs in contact after the last step."""
        return self.contacts.touching()

    # --- spawning -----------------------------------------------------------------------
    def spawn_urdf(self, name: str, urdf_xml: str, pose: Pose, namespace: str = "") -> Robot:
        """Loads a URDF robot at `pose` (its root link frame, world) with the parts its
        `<gazebo>` tags ask for. Raises SpawnError (world unchanged) when it cannot."""
        pose = self._checked_new_model(name, pose)
        try:
            spec = parse_robot(urdf_xml, name)
        except Exception as err:   # the parser names what is wrong with the description
            raise SpawnError("model '%s': %s" % (name, err))
        body, contacts = load_body(self.client, spec, pose)
        try:
            robot = make_robot(self.client, body, spec, pose, namespace, contacts, self.caster,
                               self.rng, self.warn, command_timeout=self.command_timeout,
                               legacy_mode_swaps=self.legacy_mode_swaps,
                               kinetic_legacy_mode=self.legacy_mode,
                               ground_mu=self._ground_mu())
            self._warn_overlap(name, [body], pose)
            grounds = [(b, owner) for b, owner in self._body_owner.items()
                       if self.entities[owner].is_ground]
            below = grounds_above(self.client, body, grounds)
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
                                     robot=robot, link_names=[spec.root_link])
        self._body_owner[body] = name
        self.caster.add_body(body, static=False)
        return robot

    def _ground_mu(self):
        """Gazebo's mu of the ground (the first ground model by name, its lowest), for the
        wheels' ground contact (wheel_contact); None without a ground."""
        for name in sorted(self._grounds):
            mus = [c.mu for link in self.entities[name].link_specs for c in link.collisions]
            if mus:
                return min(mus)
        return None

    def _checked_new_model(self, name, pose) -> Pose:
        """The spawn pose, normalised; SpawnError for an empty or taken name or a bad pose."""
        if not name or not name.strip():
            raise SpawnError("model name is empty; pass -model NAME")
        if name in self.entities:
            raise SpawnError("SpawnModel: Failure - entity already exists: model '%s' is in the "
                             "world; delete it first or choose another -model name" % name)
        return checked_pose(pose, "spawn pose of '%s'" % name,
                            "pass finite -x -y -z within the world and a unit quaternion "
                            "(or -R -P -Y)", error=SpawnError)

    def spawn_sdf(self, name: str, sdf_xml: str, pose: Pose, model_path=()):
        """Adds the `<sdf><model>` (or `<sdf><include>`) of `sdf_xml` as model `name`, its
        model frame at `pose` (world), as Gazebo's spawn_sdf_model does. Links with box,
        cylinder, sphere or plane collisions become bodies; meshes are reported and left out.
        Raises SpawnError (world unchanged) when it cannot."""
        pose = self._checked_new_model(name, pose)
        try:
            model, warnings = load_model_text(sdf_xml, model_path)
        except ValueError as err:
            raise SpawnError("model '%s': %s" % (name, err))
        model = replace(model, name=name, pose=pose)
        for message in warnings:
            self.warn("spawned %s" % message.replace("model '%s'" % model.name, "'%s'" % name))
        self._add_world_model(model)
        if name not in self.entities:
            raise SpawnError("model '%s' has no collision the stand-in can simulate (box, "
                             "cylinder, sphere, plane); nothing spawned" % name)
        entity = self.entities[name]
        self._warn_overlap(name, entity.body_ids, pose)
        return entity

    def _warn_overlap(self, name, bodies, pose):
        """Gazebo spawns a model inside another (physics then pushes them apart): so does
        the stand-in, with a warning naming both."""
        others = [(b, owner) for b, owner in self._body_owner.items()
                  if owner != name and not self.entities[owner].is_ground]
        inside = sorted({owner for body in bodies
                         for owner in overlapping(self.client, body, others)})
        if inside:
            self.warn("spawn pose (%.3f, %.3f, %.3f) puts '%s' inside %s; spawned anyway, as "
                      "Gazebo does (physics will push them apart)"
                      % (tuple(pose.position) + (name, ", ".join("'%s'" % m for m in inside))))

    def positive_turn_direction(self, robot) -> Optional[str]:
        """Which way a positive angular.z turns the robot, as its drive says; None without
        a drive."""
        for part in robot.parts:
            direction = part.positive_turn_direction()
            if direction is not None:
                return direction
        return None

    # --- world models -------------------------------------------------------------------
    def _add_world_model(self, model):
        built = build_model(self.client, model)
        if not built.body_ids:
            self.warn("model '%s' has no collision the stand-in can simulate; it is not in the "
                      "physics world" % model.name)
            return
        self.entities[model.name] = Entity(
            model.name, built.body_ids, built.link_offsets, built.inertial_offsets, model.pose,
            model.static, is_ground=built.is_ground, shapes=built.shapes,
            link_names=[link.name for link in built.links], link_specs=built.links)
        if built.is_ground:
            self._grounds.add(model.name)
        self._robots = None                 # the step caches list the dynamic models too
        for body, body_shapes in zip(built.body_ids, built.shapes):
            self._body_owner[body] = model.name
            if built.is_ground:
                wheel_contact.mark_ground(self.client, body)
            else:
                self.caster.add_body(body, static=model.static, base_shapes=body_shapes)

    # --- frames -------------------------------------------------------------------------
    def _link_frame(self, entity, index) -> Pose:
        """World pose of the link frame of an entity's `index`th body (Bullet reports its
        inertial frame)."""
        position, orientation = self.client.getBasePositionAndOrientation(entity.body_ids[index])
        inertial = Pose(tuple(position), tuple(orientation))
        return inertial.compose(entity.inertial_offsets[index].inverse())

    def _drop_cached_contacts(self, entity):
        """Bullet keeps a body's contact points from step to step (warm-start impulses, the
        friction anchors of a standing robot). A teleported body must not carry them to its
        new pose: they would act on its first steps there, and a run after a reset would not
        repeat a fresh start. Parking the body far above everything and running collision
        detection makes Bullet drop them itself (each point is now beyond its breaking
        distance), without rebuilding anything, so the solver's order stays as it was."""
        for index, body in enumerate(entity.body_ids):
            position, orientation = self.client.getBasePositionAndOrientation(body)
            self.client.resetBasePositionAndOrientation(
                body, (position[0], position[1], position[2] + PARKING_HEIGHT), orientation)
        self.client.performCollisionDetection()

    def _place(self, entity, index, link_pose: Pose):
        inertial = link_pose.compose(entity.inertial_offsets[index])
        self.client.resetBasePositionAndOrientation(entity.body_ids[index], inertial.position,
                                                    inertial.orientation)
