"""The contract of a robot part: what the World calls on each piece of a robot that Gazebo
would run as a model plugin or a sensor (a diff drive, a laser, a joint-state publisher...).

A part declares what it does by overriding the hooks below; every hook has a no-op default,
so the World calls them all and never probes a part for what it can do. Two tiers:

What every part gives (per physics step, and on demand):

    before_step(now, dt)   the step that starts at sim time `now` [s] is about to run (dt [s])
    after_step(now)        the step ended; `now` is the new sim time [s]
    due(now) -> bool       a reading is due now; if so the World calls measure(now) at once
    measure(now)           the reading (LaserScanData, Odometry, JointStates, ...): plain data
    reset()                simulation reset: forget commands, restart timers
    reseed(rng)            take this numpy Generator for any noise (reset_simulation)
    next_command_time()    [s] sim time at which the part next reads a command, or None if
                           it takes none (lockstep settles the controllers before it)
    positive_turn_direction()  'clockwise' / 'counter-clockwise' for a drive, else None

What a part adds to be skipped or batched (stepping.py; the defaults keep every step single
and every reading measured, which is always correct, only slower):

    skip(now)              instead of measure(now) when nobody reads it (World.step with
                           collect=False): the part's schedule and noise stream advance
                           exactly as if it had measured (default: measure, result dropped)
    next_hook_time(now) -> float   [s] asked after before_step(now): the part promises that
                           before_step and after_step at every sim time t with
                           now < t < the answer do nothing, so the World may run those steps
                           in one Bullet call. The default, `now`, makes it step one step at
                           a time: a part that does something every step (integrates,
                           applies forces) keeps it. A hook call that would change nothing in
                           Bullet may be left out of the promise, if the part keeps its own
                           schedule as if the call had been made (after_step(now) ends every
                           stretch; the diff drive's update with an unchanged command is one).
    next_reading_time(now) -> float   [s] the same promise for due(t): False for every
                           now < t < the answer (default `now`). A reading nobody collects
                           (skip) may then fall inside a stretch: after it, the World calls
                           due(t) and skip(t) at the sim times t inside the stretch from the
                           answer on, in step order, as single steps would have. So skip must
                           not touch Bullet, and due and skip must not need after_step first.
    next_activity_time(now)  the earlier of the two (not overridden)

A part class is built by `build(context, spec)` from the `<gazebo>` tag it stands in for
(a PluginSpec or a RaySensorSpec), with a PartContext: everything it may need of its robot.
`registry.py` maps each tag key to its class; the ROS adapter's `ros/bindings.py` maps the
same key to the publishers and subscribers of the part. A new part is one Part subclass in
the registry plus one binding.
"""
from dataclasses import dataclass
from types import MappingProxyType
from typing import Callable, Dict, Mapping, Optional

from .specs import RobotSpec


@dataclass
class PartContext:
    """What a part may use of the robot it belongs to. Nothing here is ROS."""
    client: object                  # the pybullet client (passed in, never a global)
    body_id: int                    # the robot's Bullet multibody
    model_name: str
    joints: Dict[str, int]          # URDF joint name -> Bullet joint index
    links: Dict[str, int]           # URDF link name -> Bullet link index (root: -1)
    description: RobotSpec          # the parsed URDF and its <gazebo> tags
    caster: object                  # the world's RayCaster
    rng: object                     # numpy Generator for noise
    warn: Callable[[str], None]     # reports a problem (prefixed with the model's name)
    command_timeout: float = 0.0    # [s] of sim time without a command before a drive stops
    legacy_mode_swaps: bool = False  # diff drives emulate Kinetic's legacyMode true
    kinetic_legacy_mode: bool = False   # ... and act as if every URDF said legacyMode true


SCHEDULE_SLACK = 2e-9      # [s] next_activity_time's margin under a schedule's 1e-9 s tolerance


def next_period_time(last, period, now):
    """next_activity_time of a schedule due once `period` [s] passed since `last` (None:
    due at once; period 0: every step), with the margin that keeps it on the safe side.
    A schedule is also due whenever the sim time is below `last` (time went back): a `last`
    above `now` by less than SCHEDULE_SLACK is rounding, not that (a schedule that adds its
    period to `last`, as the diff drive's does, runs a few 1e-17 s ahead of the steps'
    times), and the next step's time (more than SCHEDULE_SLACK after now) is past it;
    answering `now` there cost a Bullet call of its own at every such update."""
    if last is None or period <= 0.0 or now < last - SCHEDULE_SLACK:
        return now
    return last + period - SCHEDULE_SLACK


class Part:
    """Base class of every robot part; see the module docstring for the contract."""

    KEY: str = ""                   # the <plugin filename> or <sensor type> it stands in for
    # the <plugin>'s tags as written: the ROS side reads its names (topics, frames, the
    # plugin's own namespace) from them (ros/plugin_names.py); the engine keeps no ROS name
    plugin_params: Mapping[str, str] = MappingProxyType({})

    @classmethod
    def build(cls, context: PartContext, spec) -> "Part":
        raise NotImplementedError("%s does not say how to build it from a <gazebo> tag"
                                  % cls.__name__)

    def before_step(self, now: float, dt: float) -> None:
        pass

    def after_step(self, now: float) -> None:
        pass

    def due(self, now: float) -> bool:
        return False

    def measure(self, now: float):
        return None

    def reset(self) -> None:
        pass

    def reseed(self, rng) -> None:
        pass

    def next_command_time(self) -> Optional[float]:
        return None

    def positive_turn_direction(self) -> Optional[str]:
        return None

    # --- the scheduling tier (see the module docstring) ----------------------------------
    def skip(self, now: float) -> None:
        self.measure(now)

    def next_hook_time(self, now: float) -> float:
        return now

    def next_reading_time(self, now: float) -> float:
        return now

    def next_activity_time(self, now: float) -> float:
        return min(self.next_hook_time(now), self.next_reading_time(now))
