"""Quiet physics steps in one Bullet call, bit for bit as if stepped one at a time
(World.advance's helper; pybullet only, no ROS).

Bullet's stepSimulation with fixedTimeStep = k dt and numSubSteps = k runs k internal steps
of dt: the same arithmetic as k calls with dt, provided nothing happens between the steps.
What may not happen in between, and how each is ruled out:
- a part's hook acting: the World batches only steps before every part's
  next_activity_time (Part contract);
- a force or joint effort of the wrench schedule (applied per call, not per internal step):
  no batch while it holds any job or weightless link;
- joint damping: pybullet adds it once per call, from the joint speeds at the call (a
  robot with damped joints is stepped one step at a time; see `has_joint_damping`);
- a contact starting or ending (contacts.py reads them after every step): a batch is taken
  only when no robot can come near anything but itself and the ground models within it.
  Each robot part (its base and links, as spheres about their centres of mass that hold
  their collision shapes) grows by how far it can move in the batch, 2 (|v| + |w| r) T +
  MAX_ACCELERATION T^2 / 2 + CONTACT_SLACK, and the box around them by the most any other
  dynamic body can move in that time; one getOverlappingObjects on that box must find
  nothing but the robot and the ground. Bullet's broadphase boxes already hold its contact
  threshold (0.02 m); CONTACT_SLACK adds more on top.
- floating point: k dt / k must give dt back exactly, and Bullet's own count of internal
  steps, int(k dt / dt), must be k with nothing left over (`exact_substeps`); otherwise a
  smaller k is used.
"""
import math

MAX_BATCH = 20                  # physics steps in one call at most
MAX_ACCELERATION = 50.0         # [m/s^2] assumed bound on any body's acceleration (5 g)
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


def bounding_radius(client, body, link):
    """[m] radius about the link's centre of mass (base: link -1) of a sphere holding its
    collision shapes in any pose: the farthest corner of its present bounding box."""
    low, high = client.getAABB(body, link)
    if link < 0:
        centre = client.getBasePositionAndOrientation(body)[0]
    else:
        centre = client.getLinkState(body, link, computeForwardKinematics=True)[0]
    return math.sqrt(sum(max(abs(lo - c), abs(hi - c)) ** 2
                         for lo, hi, c in zip(low, high, centre)))


def _reach(linear, angular, radius, seconds):
    """[m] how far any point of a sphere of `radius` about a centre moving at `linear` [m/s]
    and turning at `angular` [rad/s] can get in `seconds`, with margins."""
    speed = math.sqrt(linear[0] ** 2 + linear[1] ** 2 + linear[2] ** 2) + radius * math.sqrt(
        angular[0] ** 2 + angular[1] ** 2 + angular[2] ** 2)
    return 2.0 * speed * seconds + 0.5 * MAX_ACCELERATION * seconds * seconds + CONTACT_SLACK


class GuardedRobot:
    """What the contact guard knows of one robot: its body, its links and their radii."""

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
        self._base_pose = client.getBasePositionAndOrientation
        self._base_velocity = client.getBaseVelocity
        self._link_states = client.getLinkStates
        self._overlapping = client.getOverlappingObjects
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

    def contact_free(self, robots, others, grounds, seconds):
        """True when, within the next `seconds` of sim time, no robot (GuardedRobot) can
        touch any body but its own and the bodies in `grounds`; `others` [(body, radius)]:
        the dynamic bodies that are not robots (their motion widens the search)."""
        widen = 0.0
        for body, radius in others:
            linear, angular = self._base_velocity(body)
            widen = max(widen, _reach(linear, angular, radius, seconds))
        boxes = []
        for robot in robots:
            if robot.damped:
                return False
            boxes.append(self._robot_box(robot, seconds))
        for robot, (low, high, _) in zip(robots, boxes):
            grow = max([widen] + [reach for other, (_, _, reach) in zip(robots, boxes)
                                  if other is not robot])
            hits = self._overlapping([c - grow for c in low], [c + grow for c in high])
            for body, _ in hits or ():
                if body != robot.body and body not in grounds:
                    return False
        return True

    def _robot_box(self, robot, seconds):
        """(low, high, reach): the box that holds the robot wherever it can get in `seconds`,
        and the farthest any of its parts can move [m]."""
        position = self._base_pose(robot.body)[0]
        linear, angular = self._base_velocity(robot.body)
        most = _reach(linear, angular, robot.base_radius, seconds)
        extent = robot.base_radius + most
        low = [c - extent for c in position]
        high = [c + extent for c in position]
        if robot.links:
            # (no computeForwardKinematics: it rewrites Bullet's cached link transforms, and
            # the next step would differ in the last bits; after a step they are current)
            states = self._link_states(robot.body, robot.links, computeLinkVelocity=1)
            for state, radius in zip(states, robot.link_radii):
                reach = _reach(state[6], state[7], radius, seconds)
                most = max(most, reach)
                extent = radius + reach
                for axis, c in enumerate(state[0]):
                    if c - extent < low[axis]:
                        low[axis] = c - extent
                    if c + extent > high[axis]:
                        high[axis] = c + extent
        return low, high, most
