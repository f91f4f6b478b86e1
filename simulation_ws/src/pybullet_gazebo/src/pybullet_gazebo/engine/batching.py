"""Quiet physics steps in one Bullet call, bit for bit as if stepped one at a time
(World.advance's helper; pybullet only, no ROS).

Bullet's stepSimulation with fixedTimeStep = k dt and numSubSteps = k runs k internal steps
of dt: the same arithmetic as k calls with dt, provided nothing happens between the steps.
What may not happen in between, and how each is ruled out:
- a part's hook acting: the World batches only steps before every part's next_hook_time
  and, for readings that are collected, next_reading_time (Part contract; the readings
  nobody collects are skipped after the call, at their own times);
- a force or joint effort of the wrench schedule (applied per call, not per internal step):
  no batch while it holds any job or weightless link;
- joint damping: pybullet adds it once per call, from the joint speeds at the call (a
  robot with damped joints is stepped one step at a time; see `has_joint_damping`);
- a contact starting or ending (contacts.py reads them after every step): batches run only
  while no robot can come near anything but itself and the ground models (`safe_time`).
  A point of a robot moves at most at S_r = max over its links of |v| + |w| r (v, w: the
  link's velocity, r: the radius about its centre of mass that holds its collision shapes)
  now, another dynamic model's at S_o (its own; a static model's is 0), and neither
  accelerates by more than MAX_ACCELERATION; so their gap closes by at most
  2 (S_r + S_o) t + MAX_ACCELERATION t^2 in t seconds (the 2 for good measure). The gap to each model near the robot is Bullet's
  own distance between their collision shapes (getClosestPoints; models farther away than
  what can close within the horizon are left out by one getOverlappingObjects); batches
  run until that closing plus CONTACT_SLACK could reach the smallest gap (Bullet makes a
  contact point within 0.02 m).
- floating point: k dt / k must give dt back exactly, and Bullet's own count of internal
  steps, int(k dt / dt), must be k with nothing left over (`exact_substeps`); otherwise a
  smaller k is used.
"""
import math

import numpy as np
import pybullet

MAX_BATCH = 20                  # physics steps in one call at most
MAX_ACCELERATION = 30.0         # [m/s^2] assumed bound on any body's acceleration (3 g)
CONTACT_SLACK = 0.05            # [m] added to every reach (Bullet's thresholds are 0.02 m)


def exact_substeps(step_size, k):
    """True when Bullet, given fixedTimeStep = k * step_size and numSubSteps = k, runs
    exactly k internal steps of exactly step_size with no time left over (its
    btDiscreteDynamicsWorld::stepSimulation arithmetic, in doubles as pybullet builds it)."""
    total = k * step_size
    sub = total / k
    return sub == step_size and int(total / sub) == k and total - k * sub == 0.0


def has_joint_damping(client, body):
    """True when a joint of the multibody has <dynamics damping> (see the module docstring)."""
    return any(client.getJointInfo(body, j)[6] != 0.0 for j in range(client.getNumJoints(body)))


def bounding_radius(client, body, link, shapes=None):
    """[m] radius about the link's centre of mass (base: link -1) of a sphere holding its
    collision shapes in any pose. `shapes`: [(geometry type, dimensions, local position,
    ...)] as bodies.shape_data gives them (for bodies pybullet cannot report: maximal
    ones); else pybullet's getCollisionShapeData (local frames relative to the centre of
    mass). The farthest corner of the link's bounding box when a shape is not a primitive."""
    if shapes is None:
        shapes = [entry[2:4] + entry[5:6] for entry in client.getCollisionShapeData(body, link)]
    radii = [_shape_radius(*shape[:3]) for shape in shapes]
    if radii and all(r is not None for r in radii):
        return max(radii)
    low, high = client.getAABB(body, link)
    if link < 0:
        centre = client.getBasePositionAndOrientation(body)[0]
    else:
        centre = client.getLinkState(body, link, computeForwardKinematics=True)[0]
    return math.sqrt(sum(max(abs(lo - c), abs(hi - c)) ** 2
                         for lo, hi, c in zip(low, high, centre)))


def _shape_radius(geometry, dimensions, position):
    """Distance from the link's centre of mass to the farthest point of a shape
    (getCollisionShapeData's conventions; a mesh given as its triangles (m, 3, 3)), None
    for what this cannot bound (planes, meshes known by file name only)."""
    offset = math.sqrt(sum(c * c for c in position))
    if geometry == pybullet.GEOM_BOX:
        return offset + 0.5 * math.sqrt(sum(d * d for d in dimensions))
    if geometry == pybullet.GEOM_SPHERE:
        return offset + dimensions[0]
    if geometry == pybullet.GEOM_CYLINDER:
        return offset + math.hypot(dimensions[1], 0.5 * dimensions[0])
    if geometry == pybullet.GEOM_CAPSULE:
        return offset + dimensions[1] + 0.5 * dimensions[0]
    if geometry == pybullet.GEOM_MESH and isinstance(dimensions, np.ndarray) and len(dimensions):
        return offset + float(np.sqrt((dimensions.reshape(-1, 3) ** 2).sum(axis=1).max()))
    return None


def closing(speed, seconds):
    """[m] the most a gap between two bodies whose points move at `speed` [m/s] together now
    can shrink in `seconds`, CONTACT_SLACK included."""
    return 2.0 * speed * seconds + MAX_ACCELERATION * seconds * seconds + CONTACT_SLACK


def _time_to_close(speed, gap):
    """[s] the time `closing(speed, t)` takes to reach `gap` [m] (0 when it already does)."""
    room = gap - CONTACT_SLACK
    if room <= 0.0:
        return 0.0
    # MAX_ACCELERATION t^2 + 2 speed t - room = 0, the positive root in its stable form
    return room / (speed + math.sqrt(speed * speed + MAX_ACCELERATION * room))


class GuardedRobot:
    """What the contact guard knows of one robot: its body, its links (-1: the base) and
    their radii."""

    def __init__(self, client, body):
        self.body = body
        self.links = list(range(client.getNumJoints(body)))
        self.base_radius = bounding_radius(client, body, -1)
        self.link_radii = [bounding_radius(client, body, link) for link in self.links]
        self.damped = has_joint_damping(client, body)


class Batcher:
    """Runs k physics steps in one Bullet call, and says how many may be run so."""

    def __init__(self, client):
        self._client = client
        self._step = client.stepSimulation            # bound once
        self._set = client.setPhysicsEngineParameter
        self._base_velocity = client.getBaseVelocity
        self._link_states = client.getLinkStates
        self._overlapping = client.getOverlappingObjects
        self._base_position = client.getBasePositionAndOrientation
        self._closest = client.getClosestPoints
        self._exact = {}                              # (step size, k) -> exact_substeps

    def largest_exact(self, step_size, k):
        """The largest k' <= k that exact_substeps allows (1 always is)."""
        while k > 1:
            key = (step_size, k)
            exact = self._exact.get(key)
            if exact is None:
                exact = self._exact[key] = exact_substeps(step_size, k)
            if exact:
                return k
            k -= 1
        return 1

    def step(self, step_size, k):
        """k physics steps of step_size [s] in one call (k = 1: one plain step). Bullet is
        set back to one step per call at once: pybullet turns a motor's force limit into an
        impulse limit with the time step set when the motor is commanded, so every other
        call must see the plain step."""
        if k == 1:
            self._step()
            return
        self._set(fixedTimeStep=k * step_size, numSubSteps=k)
        self._step()
        self._set(fixedTimeStep=step_size, numSubSteps=1)

    def safe_time(self, robots, others, grounds, horizon, statics=frozenset()):
        """[s] of sim time, up to `horizon`, during which no robot (GuardedRobot) can touch
        any body but its own and the bodies in `grounds` (see the module docstring);
        `others` [(body, radius)]: the dynamic bodies that are not robots; `statics`: bodies
        that never move (their gaps close at the robot's speed alone)."""
        velocity, sqrt = self._base_velocity, math.sqrt
        speeds = {}                   # body -> the speed of its fastest point now [m/s]
        for body, radius in others:
            (vx, vy, vz), (wx, wy, wz) = velocity(body)
            speeds[body] = sqrt(vx * vx + vy * vy + vz * vz) + radius * sqrt(
                wx * wx + wy * wy + wz * wz)
        other_speed = max(speeds.values(), default=0.0)
        reached = []
        for robot in robots:
            if robot.damped:
                return 0.0
            reached.append(self._reach(robot))
            speeds[robot.body] = reached[-1][2]
        safe = horizon
        for robot, (centre, extent, speed) in zip(robots, reached):
            fastest = max([other_speed] + [s for other, (_, _, s) in zip(robots, reached)
                                           if other is not robot])
            grow = extent + closing(speed + fastest, horizon)   # no gap closes by more
            hits = self._overlapping([c - grow for c in centre], [c + grow for c in centre])
            for body in {body for body, _ in hits or ()
                         if body != robot.body and body not in grounds}:
                # a static body's gap closes at the robot's speed, a moving one's at both
                # speeds (a body the World does not know: at the fastest known)
                pair = speed + (0.0 if body in statics else speeds.get(body, fastest))
                far = closing(pair, horizon)
                gap = far
                for point in self._closest(robot.body, body, far):
                    gap = min(gap, point[8])
                if gap < far:
                    safe = min(safe, _time_to_close(pair, gap))
        return safe

    def _reach(self, robot):
        """(centre, extent, speed): a cube's centre and half side [m] that hold the robot's
        collision shapes now, and the speed [m/s] of its fastest point."""
        body, sqrt = robot.body, math.sqrt
        (vx, vy, vz), (wx, wy, wz) = self._base_velocity(body)
        speed = sqrt(vx * vx + vy * vy + vz * vz) + robot.base_radius * sqrt(
            wx * wx + wy * wy + wz * wz)
        cx, cy, cz = self._base_position(body)[0]
        extent = robot.base_radius
        if robot.links:
            # (no computeForwardKinematics: it rewrites Bullet's cached link transforms, and
            # the next step would differ in the last bits; after a step they are current)
            states = self._link_states(body, robot.links, computeLinkVelocity=1)
            for state, radius in zip(states, robot.link_radii):
                (vx, vy, vz), (wx, wy, wz) = state[6], state[7]
                speed = max(speed, sqrt(vx * vx + vy * vy + vz * vz)
                            + radius * sqrt(wx * wx + wy * wy + wz * wz))
                px, py, pz = state[0]
                extent = max(extent, radius + max(abs(px - cx), abs(py - cy), abs(pz - cz)))
        return (cx, cy, cz), extent, speed
