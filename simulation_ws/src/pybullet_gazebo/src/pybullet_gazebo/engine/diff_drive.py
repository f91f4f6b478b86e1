"""gazebo_ros_diff_drive (ROS Noetic) as an engine component: two wheel joints driven as
Bullet velocity motors from a (linear.x, angular.z) command, and odometry.

Plugin parameters, read as Noetic reads them (default in brackets):
  leftJoint [left_joint], rightJoint [right_joint]  joint names
  wheelDiameter [0.15 m], wheelSeparation [0.34 m]
  wheelTorque [5 N m]        motor force limit. The tag `torque` of older releases is NOT
                             read by Noetic: when only `torque` is given, a warning says so
                             and 5 N m is used, as in Gazebo.
  wheelAcceleration [0 = no limit, m/s^2 of wheel rim speed]
  updateRate [100 Hz; <= 0 = every step]  wheel targets and odometry are updated at this
                             rate of sim time
  robotNamespace, commandTopic, odometryTopic, odometryFrame, robotBaseFrame: ROS names,
                             kept in plugin_params and read by the ROS side
                             (ros/plugin_names.py)
  odometrySource [world | encoder]
  publishTf [true]           false: Noetic publishes no odometry at all (due() stays false)
  publishOdomTF [true], publishWheelTF [false], publishWheelJointState [false: the
                             stand-in publishes the wheel joint states whatever it says,
                             see joint_states.py]
  legacyMode                 removed in Melodic (gazebo_ros_pkgs #707) and not read by Noetic:
                             `true` only draws a warning, unless the component is built with
                             legacy_mode_swaps=True to emulate Kinetic and older, where
                             legacyMode true swapped the two wheels' formulas.
                             kinetic_legacy_mode=True (the simulator's `legacy_mode` option)
                             emulates Kinetic's drive with legacyMode true whatever the URDF
                             says: the swapped formulas, so that m2wr turns counter-clockwise
                             for a positive w (REP 103), as the series' later programs expect.

Wheel speeds for a command (v [m/s], w [rad/s]): the joint NAMED by leftJoint turns at
(v - w * separation / 2) / radius and the joint named by rightJoint at
(v + w * separation / 2) / radius [rad/s], whatever side of the robot they are on (for m2wr,
whose "right" joint sits on its left, a positive w turns the robot clockwise, as in Gazebo).
A speed above the joint's URDF velocity limit is clamped to it (reported once per joint);
Bullet, besides, never turns a joint faster than its maxJointVelocity (100 rad/s by default,
10 m/s at m2wr's rim). Under such a command m2wr may rear up and turn over: physics, as in
Gazebo. The last command is held for ever, as in Gazebo, unless command_timeout [s of sim
time] > 0. Unlike Gazebo, a command with a non-finite value is refused (set_command returns
False) and the previous one kept.

Odometry (odometrySource world): the true pose of the base link frame in the world and its
velocity, linear (of the link frame's origin) and angular, both expressed in the base link
frame (Noetic rotates by yaw only; on flat ground the two agree). odometrySource encoder
integrates the wheel joints' speeds as Noetic does (planar pose, heading from the wheels).
"""
from dataclasses import dataclass
import math

import numpy as np
import pybullet

from .parameters import ParameterReader
from .part import SCHEDULE_SLACK, Part, PartContext, next_period_time
from .transforms import Pose, cross

_TOLERANCE = 1e-9            # [s] slack for sim times accumulated in floating point
HOLD_SLACK = 0.01            # [rad] a stopped wheel turned further than this is held anew
HOLD_GAIN = 0.1              # Bullet's position gain (fraction of the angle error per step)


@dataclass
class Odometry:
    """What a nav_msgs/Odometry carries, without ROS."""
    pose: Pose                  # base link frame in the odometry frame (the world) [m]
    linear: np.ndarray          # (3,) [m/s], in the base link frame
    angular: np.ndarray         # (3,) [rad/s], in the base link frame


class _Cadence:
    """Noetic's update timing: due once `period` [s] of sim time has passed since the last
    update; the schedule advances by whole periods (and restarts after a reset or a lag)."""

    def __init__(self, period):
        self.period = period
        self.last = None

    def take(self, sim_time):
        """True (and the update is counted) when an update is due at sim_time."""
        if self.last is None or sim_time < self.last:
            self.last = sim_time
            return True
        if sim_time - self.last < self.period - _TOLERANCE:
            return False
        self.last += self.period
        if sim_time - self.last >= self.period - _TOLERANCE:
            self.last = sim_time
        return True


class DiffDrive(Part):
    """A differential drive on two joints of a body."""

    KEY = "libgazebo_ros_diff_drive.so"

    @classmethod
    def build(cls, context: PartContext, plugin):
        # anchored while the robot stands: the wheels' ground-contact spheres (wheel_contact)
        # and every other link that may touch the ground (a caster, a skid), not the wheels'
        # own cylinders, which never do
        joints = context.description.joints
        wheels = set()
        for tag, default in (("leftJoint", "left_joint"), ("rightJoint", "right_joint")):
            joint = plugin.params.get(tag, default).strip()
            if joint in joints:
                wheels.add(joints[joint][1])
        anchor_links = [index for link, index in context.links.items() if link not in wheels]
        return cls(context.client, context.body_id, context.joints, plugin, context.warn,
                   command_timeout=context.command_timeout,
                   legacy_mode_swaps=context.legacy_mode_swaps,
                   kinetic_legacy_mode=context.kinetic_legacy_mode, anchor_links=anchor_links)

    def __init__(self, client, body_id, joints, plugin, warn, command_timeout=0.0,
                 legacy_mode_swaps=False, kinetic_legacy_mode=False, anchor_links=()):
        # Bullet links whose friction anchors hold a standing robot; set before reset(),
        # which stands the robot (and so anchors it) from the first step on, as after a reset
        self.anchor_links = list(anchor_links)
        self._anchored = None
        self._client = client
        self._set_motor = client.setJointMotorControl2    # bound once: 40 calls a second
        self.body_id = body_id
        self._warn = warn
        self._warned = set()
        self.name = plugin.name
        params = dict(plugin.params)
        where = "diff drive plugin '%s' (%s)" % (plugin.name, plugin.filename)
        read = ParameterReader(params, where, label="<%s>")
        text, number, boolean = read.text, read.number, read.boolean

        self.plugin_params = params             # its topic and frame names: the ROS side's
        self.publish_tf = boolean("publishTf", True)
        self.publish_wheel_tf = boolean("publishWheelTF", False)
        self.publish_odom_tf = boolean("publishOdomTF", True)
        self.publish_wheel_joint_state = boolean("publishWheelJointState", False)
        self.wheel_separation = number("wheelSeparation", 0.34, above=0.0)          # [m]
        self.wheel_diameter = number("wheelDiameter", 0.15, above=0.0)              # [m]
        self.wheel_radius = self.wheel_diameter / 2.0                                # [m]
        self.wheel_acceleration = number("wheelAcceleration", 0.0, minimum=0.0)     # [m/s^2]
        self.wheel_torque = number("wheelTorque", 5.0, minimum=0.0)                 # [N m]
        self.update_rate = number("updateRate", 100.0)                              # [Hz]
        for tag in ("publishWheelTF",):     # publishWheelJointState: see joint_states.py
            if boolean(tag, False):
                self._warn_once("%s: <%s>true is not simulated by the stand-in; ignored"
                                % (where, tag))
        for tag in ("wheelSeparation", "wheelDiameter"):
            if tag not in params:
                self._warn_once("%s: <%s> missing; Noetic's default %s m is used"
                                % (where, tag, {"wheelSeparation": 0.34,
                                                "wheelDiameter": 0.15}[tag]))
        if "torque" in params and "wheelTorque" not in params:
            self._warn_once("%s: <torque>%s</torque> is not read by ROS Noetic's "
                            "gazebo_ros_diff_drive (the tag is <wheelTorque>); the wheels get "
                            "Noetic's default 5 N m, as in Gazebo"
                            % (where, params["torque"].strip()))
        self.odometry_source = text("odometrySource", "world")
        if self.odometry_source not in ("world", "encoder"):
            self._warn_once("%s: <odometrySource> '%s' is neither world nor encoder; world is "
                            "used" % (where, self.odometry_source))
            self.odometry_source = "world"
        legacy = boolean("legacyMode", False)
        # whether the wheels swap
        self.legacy_mode = bool(kinetic_legacy_mode or (legacy and legacy_mode_swaps))
        if legacy and not (legacy_mode_swaps or kinetic_legacy_mode):
            self._warn_once("%s: <legacyMode>true is ignored, as ROS Noetic ignores it (removed "
                            "in Melodic): leftJoint gets (v - w*sep/2)/r and rightJoint "
                            "(v + w*sep/2)/r" % where)

        self.left_joint = text("leftJoint", "left_joint")
        self.right_joint = text("rightJoint", "right_joint")
        self._joints = []                                 # (index, name, velocity limit)
        for tag, name in (("leftJoint", self.left_joint), ("rightJoint", self.right_joint)):
            if name not in joints:
                raise ValueError("%s: <%s> names joint '%s', which the model does not have; its "
                                 "joints are: %s" % (where, tag, name,
                                                     ", ".join(sorted(joints)) or "(none)"))
            index = joints[name]
            limit = client.getJointInfo(body_id, index)[11]      # URDF <limit velocity>
            self._joints.append((index, name, limit if limit > 0 else math.inf))

        self.command_timeout = float(command_timeout)             # [s]; 0 = hold for ever
        period = 1.0 / self.update_rate if self.update_rate > 0 else 0.0   # [s]
        self._control = _Cadence(period)
        self._publish = _Cadence(period)
        base = client.getDynamicsInfo(body_id, -1)
        self._base_inertial = Pose(base[3], base[4])   # centre of mass in the base link frame
        self.reset()

    # --- commands ---------------------------------------------------------------------------
    def set_command(self, linear_x, angular_z):
        """Takes a cmd_vel (linear.x [m/s], angular.z [rad/s]). Returns False, keeping the
        previous command, when a value is not a finite number."""
        try:
            v, w = float(linear_x), float(angular_z)
        except (TypeError, ValueError):
            v = w = math.nan
        if not (math.isfinite(v) and math.isfinite(w)):
            self._warn_once("non-finite", "diff drive '%s': ignored a command with a "
                            "non-finite value (%s, %s); the previous command stays (reported "
                            "once)" % (self.name, linear_x, angular_z))
            return False
        self.command = (v, w)
        self._fresh = True
        return True

    def _command_at(self, sim_time):
        """The command an update at sim_time [s] applies: the last one, or a stop when
        command_timeout > 0 and no command came within it (or none came since the reset)."""
        if self.command_timeout > 0 and (self._command_time is None or
                                         sim_time - self._command_time > self.command_timeout):
            return 0.0, 0.0
        return self.command

    def next_command_time(self):
        """Sim time [s] of the next update, at which a command is read; a command set before
        the step that starts at this time takes effect then."""
        if self._control.last is None:
            return 0.0
        return self._control.last + self._control.period - _TOLERANCE

    def wheel_speeds(self, linear_x, angular_z):
        """Target speeds [rad/s] of (leftJoint, rightJoint) for a command, before clamping."""
        half = angular_z * self.wheel_separation / 2.0
        left = (linear_x - half) / self.wheel_radius
        right = (linear_x + half) / self.wheel_radius
        return (right, left) if self.legacy_mode else (left, right)

    def reset(self):
        """Simulation reset: no command, wheels told to stop, timers and encoder restarted."""
        self.command = (0.0, 0.0)
        self._fresh = False
        self._command_time = None
        self._control.last = None
        self._publish.last = None
        self._idle_update = None       # [s] the update next_hook_time let a batch skip
        self._step = None              # [s] the physics step of the last before_step
        self._rim_speed = [0.0, 0.0]                       # [m/s] last applied, per wheel
        self._held = [None, None]                          # [rad] where a stopped wheel stays
        self._encoder = [0.0, 0.0, 0.0]                    # x [m], y [m], heading [rad]
        self._encoder_twist = (0.0, 0.0)                   # [m/s], [rad/s]
        self._encoder_time = None
        self._apply(0.0, 0.0)

    # --- stepping ---------------------------------------------------------------------------
    def before_step(self, sim_time, dt):
        """Called before each physics step at sim_time [s]; dt [s] is the step."""
        self._step = dt
        if self._idle_update is not None:
            self._count_idle_update(sim_time - dt)
        if self._fresh:
            self._command_time = sim_time
            self._fresh = False
        if self.odometry_source == "encoder":
            self._integrate_encoder(sim_time)
        previous = self._control.last
        if not self._control.take(sim_time):
            return
        elapsed = sim_time - previous if previous is not None and sim_time > previous else dt
        v, w = self._command_at(sim_time)
        targets = [s * self.wheel_radius for s in self.wheel_speeds(v, w)]   # [m/s]
        for i, target in enumerate(targets):
            if self.wheel_acceleration > 0:
                step = self.wheel_acceleration * elapsed
                target = min(max(target, self._rim_speed[i] - step), self._rim_speed[i] + step)
            self._rim_speed[i] = target
        self._apply(self._rim_speed[0] / self.wheel_radius, self._rim_speed[1] / self.wheel_radius)

    def after_step(self, sim_time):
        """The end of a stretch of steps (see _count_idle_update)."""
        if self._idle_update is not None:
            self._count_idle_update(sim_time - self._step)

    def _count_idle_update(self, last_step_start):
        """Counts the update next_hook_time let a stretch of steps skip (it would have
        changed nothing) if its step ran, that is if it was due by the start of the last
        step run (`last_step_start` [s]): the schedule stays as if every step's before_step
        had been called. Forgotten otherwise: next_hook_time says it anew."""
        idle, self._idle_update = self._idle_update, None
        if idle is not None and last_step_start >= idle - _TOLERANCE:
            self._control.take(idle)

    def _update_changes_nothing(self, sim_time):
        """True when the wheel update due at sim_time [s] would give the wheels the motor
        commands they already have: the same rim speeds as the last update (the command's
        own, not ramped by wheelAcceleration, not stopped by command_timeout), neither of them
        zero (a stopped wheel's hold reads its angle anew at each update). Bullet's motors
        then stay as they are, to the bit, whether the update runs or not."""
        v, w = self._command_at(sim_time)
        rims = self._rim_speed
        radius = self.wheel_radius
        for rim, speed in zip(rims, self.wheel_speeds(v, w)):
            if speed * radius != rim or rim / radius == 0.0:
                return False
        return True

    def _apply(self, left, right):
        """Drive (leftJoint, rightJoint) at these speeds [rad/s], within their limits; a
        wheel told to stop is held where it stopped (see _hold)."""
        self._anchor(left == 0.0 and right == 0.0)
        for slot, ((index, name, limit), speed) in enumerate(zip(self._joints, (left, right))):
            if abs(speed) > limit:
                self._warn_once(("clamped", name),
                                "diff drive '%s': wheel speed %.4g rad/s for joint '%s' is over "
                                "its URDF velocity limit %.4g rad/s; clamped (reported once)"
                                % (self.name, speed, name, limit))
                speed = math.copysign(limit, speed)
            if speed == 0.0:
                self._hold(slot, index)
                continue
            self._held[slot] = None
            self._set_motor(self.body_id, index, pybullet.VELOCITY_CONTROL,
                            targetVelocity=speed, force=self.wheel_torque)

    def _anchor(self, standing):
        """Friction anchors on the robot's ground contacts (the wheels' and a caster's) while
        it is told to stand (see wheel_contact.FRICTION_ANCHOR): they stop the last sideways
        slip, and cost about a third of a step while on, so a driving robot goes without."""
        if standing == self._anchored:
            return
        self._anchored = standing
        for link in self.anchor_links:
            self._client.changeDynamics(self.body_id, link, frictionAnchor=int(standing))

    def _hold(self, slot, index):
        """A zero speed target, without Bullet's creep. Bullet's velocity motor leaves a
        residual error (its iterative solver does not converge under the robot's weight:
        m2wr rolled backwards at 6e-5 m/s with a zero command, 0.2 m per hour); ODE's motor
        in Gazebo holds the wheel. The same motor, same force limit, also pulls the joint
        back to the angle where it stopped, which cancels that residual. A wheel turned
        further than HOLD_SLACK from it (pushed against the torque limit, or a teleport that
        zeroed the joints) is held where it now is: no spring back."""
        angle = self._client.getJointState(self.body_id, index)[0]
        held = self._held[slot]
        if held is None or abs(angle - held) > HOLD_SLACK:
            held = self._held[slot] = angle
        self._set_motor(self.body_id, index, pybullet.POSITION_CONTROL,
                        targetPosition=held, targetVelocity=0.0, positionGain=HOLD_GAIN,
                        velocityGain=1.0, force=self.wheel_torque)

    def _integrate_encoder(self, sim_time):
        """Noetic's encoder odometry: dead reckoning from the wheel joints' speeds."""
        if self._encoder_time is None or sim_time <= self._encoder_time:
            self._encoder_time = sim_time
            return
        elapsed = sim_time - self._encoder_time
        self._encoder_time = sim_time
        left, right = (self._client.getJointState(self.body_id, index)[1]
                       for index, _, _ in self._joints)
        s_left = left * self.wheel_radius * elapsed
        s_right = right * self.wheel_radius * elapsed
        s_sum, s_diff = s_left + s_right, s_right - s_left
        heading = self._encoder[2] + s_diff / (2.0 * self.wheel_separation)
        dx, dy = s_sum / 2.0 * math.cos(heading), s_sum / 2.0 * math.sin(heading)
        dtheta = s_diff / self.wheel_separation
        self._encoder = [self._encoder[0] + dx, self._encoder[1] + dy, self._encoder[2] + dtheta]
        speed = math.hypot(dx, dy) / elapsed
        self._encoder_twist = (-speed if s_sum < 0 else speed, dtheta / elapsed)

    # --- odometry ---------------------------------------------------------------------------
    def due(self, sim_time):
        """True once per 1/updateRate [s] of sim time (each true answer starts the next
        period); always false when publishTf is false, as Noetic then publishes nothing."""
        return self.publish_tf and self._publish.take(sim_time)

    def measure(self, now):
        """The reading due at `now` [s]: the odometry."""
        return self.odometry()

    def skip(self, now):
        pass                    # due() already advanced the schedule; no noise

    def next_hook_time(self, now):
        """The next wheel update (see Part); every step with encoder odometry, which
        integrates the wheel speeds each step, or while a new command waits to be
        time-stamped (the next before_step does it)."""
        if self.odometry_source == "encoder" or self._fresh:
            return now
        control = self._control
        soonest = next_period_time(control.last, control.period, now)
        if soonest > now and self._update_changes_nothing(control.last + control.period):
            # the next update would change nothing: a batch may run through it (after_step
            # counts it), up to the one after, which the command given then may change
            self._idle_update = control.last + control.period
            soonest = self._idle_update + control.period - SCHEDULE_SLACK
        return soonest

    def next_reading_time(self, now):
        """The next odometry (see Part); never when publishTf is false."""
        if not self.publish_tf:
            return math.inf
        return next_period_time(self._publish.last, self._publish.period, now)

    def odometry(self):
        """Odometry of the base link now (see the module docstring)."""
        if self.odometry_source == "encoder":
            x, y, heading = self._encoder
            return Odometry(Pose.from_xyz_rpy(x, y, 0.0, 0.0, 0.0, heading),
                            np.array([self._encoder_twist[0], 0.0, 0.0]),
                            np.array([0.0, 0.0, self._encoder_twist[1]]))
        client = self._client
        com_position, com_orientation = client.getBasePositionAndOrientation(self.body_id)
        link = Pose(com_position, com_orientation).compose(self._base_inertial.inverse())
        linear, angular = client.getBaseVelocity(self.body_id)
        # velocity of the link frame's origin, from the centre of mass's
        lever = cross(angular, [a - b for a, b in zip(link.position, com_position)])
        linear = np.array(linear) + lever
        angular = np.array(angular)
        to_base = link.matrix.T
        return Odometry(link, to_base @ linear, to_base @ angular)

    def positive_turn_direction(self):
        """'clockwise' or 'counter-clockwise': which way a positive angular.z turns the robot,
        seen from above, given where the named joints really are. gazebo_ros_diff_drive gives
        the joint *named* by rightJoint the faster wheel for a positive angular.z, whatever
        side it is on; if it sits on the robot's left (+y), the robot turns clockwise."""
        client = self._client
        com = Pose(*client.getBasePositionAndOrientation(self.body_id))
        root = com.compose(self._base_inertial.inverse())
        lateral = {}
        for index, name, _ in self._joints:
            world_position = client.getLinkState(self.body_id, index,
                                                 computeForwardKinematics=True)[4]
            lateral[name] = root.inverse().transform_point(world_position)[1]
        faster_on_left = lateral[self.right_joint] > lateral[self.left_joint]
        if self.legacy_mode:
            faster_on_left = not faster_on_left
        return "clockwise" if faster_on_left else "counter-clockwise"

    def _warn_once(self, key, message=None):
        """Report `message` (default: the key itself) the first time `key` comes up."""
        if key not in self._warned:
            self._warned.add(key)
            self._warn(key if message is None else message)
