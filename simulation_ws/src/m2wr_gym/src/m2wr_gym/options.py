"""The environments' options (keyword arguments of gymnasium.make), checked once: an
unknown option or value is a ValueError naming it and listing what is accepted.

  task                 "avoid" (episode 5: wander without touching) | "goal" (reach a pose)
  world                "world02" (default), "world01" or a path to an SDF .world file
  start                None: the tutorial's (0, 8, yaw 0) in world01/world02, a random free
                       pose in other worlds; "random": a free pose drawn each episode;
                       an int N: a pool of N free poses drawn from `start_seed`, one picked
                       per episode; or a list of (x [m], y [m], yaw [rad]) poses
  start_seed           seed of the pool of N start poses (default 0)
  observation          "regions" (episode 4's five, reading_laser.py's numbers) | "scan"
  downsample           "scan" only: keep the minimum of each group of this many beams (1)
  action               "discrete" (forward / left / right) | "continuous" (linear.x, angular.z)
  control_rate         [Hz] decisions per second of sim time (10); 1/rate must be a whole
                       number of physics steps
  laser_noise          [m] Gaussian stddev of the laser; None keeps the robot's own 0.01
  turning              "gazebo" (default: a positive angular.z turns m2wr clockwise, as in
                       Gazebo and episode 5) | "legacy" (Kinetic's legacyMode: counter-clockwise)
  max_episode_seconds  [s] of sim time before the episode is truncated (avoid 120, goal 60)
  goal                 goal task: (x, y) [m], or None for a free point drawn each episode
  goal_tolerance       [m] the goal is reached within this distance (0.3, go_to_point's)
  physics_step         [s] Bullet's fixed step (0.005, the simulator's default)
  end_on_contact       True (default): a contact ends the episode; False: it is only penalised
                       and reported in info["touched"] (for evaluations that count contacts)
  invalid_action       "raise" (default) | "end": log the error and truncate the episode, so a
                       vectorised run goes on
  backend              "inprocess" (default) | "ros": drive a running simulator in lockstep
"""
from dataclasses import dataclass, fields
import math
import numbers

from . import actions, observation

TASKS = ("avoid", "goal")
BACKENDS = ("inprocess", "ros")
TUTORIAL_START = (0.0, 8.0, 0.0)          # spawn.launch y:=8, as episode 5
DEFAULT_SECONDS = {"avoid": 120.0, "goal": 60.0}


@dataclass
class EnvOptions:
    task: str = "avoid"
    world: str = "world02"
    start: object = None
    start_seed: int = 0
    observation: str = "regions"
    downsample: int = 1
    action: str = "discrete"
    control_rate: float = 10.0
    laser_noise: object = None
    turning: str = "gazebo"
    max_episode_seconds: object = None
    goal: object = None
    goal_tolerance: float = 0.3
    physics_step: float = 0.005
    end_on_contact: bool = True
    invalid_action: str = "raise"
    backend: str = "inprocess"

    @classmethod
    def from_kwargs(cls, **kwargs):
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(kwargs) - set(known))
        if unknown:
            raise ValueError("unknown option%s %s; the options are: %s"
                             % ("s" if len(unknown) > 1 else "", ", ".join(unknown),
                                ", ".join(known)))
        options = cls(**kwargs)
        options.check()
        return options

    def check(self):
        def choice(name, allowed):
            value = getattr(self, name)
            if value not in allowed:
                raise ValueError("option %s=%r: choose one of %s" % (name, value, ", ".join(allowed)))
        choice("task", TASKS)
        choice("observation", observation.KINDS)
        choice("action", actions.KINDS)
        choice("turning", actions.TURNINGS)
        choice("invalid_action", ("raise", "end"))
        choice("backend", BACKENDS)
        choice("end_on_contact", (True, False))
        if not isinstance(self.downsample, numbers.Integral) or self.downsample < 1 \
                or observation.SCAN_BEAMS % self.downsample:
            raise ValueError("option downsample=%r: give a whole number that divides %d beams "
                             "(1, 2, 4, 8, 10, 20, 40, 72, ...)"
                             % (self.downsample, observation.SCAN_BEAMS))
        if self.downsample != 1 and self.observation != "scan":
            raise ValueError("option downsample=%r applies to observation='scan' only"
                             % self.downsample)
        _positive("physics_step", self.physics_step)
        _positive("control_rate", self.control_rate)
        steps = 1.0 / (self.control_rate * self.physics_step)
        if abs(steps - round(steps)) > 1e-6 or round(steps) < 1:
            raise ValueError("option control_rate=%r: 1/control_rate must be a whole number of "
                             "physics steps of %g s (e.g. 5, 10, 20 Hz)"
                             % (self.control_rate, self.physics_step))
        if self.laser_noise is not None:
            _positive("laser_noise", self.laser_noise, zero=True)
        if self.max_episode_seconds is None:
            self.max_episode_seconds = DEFAULT_SECONDS[self.task]
        _positive("max_episode_seconds", self.max_episode_seconds)
        _positive("goal_tolerance", self.goal_tolerance)
        if self.goal is not None:
            self.goal = _numbers("goal", self.goal, 2)
            if self.task != "goal":
                raise ValueError("option goal=%r applies to task='goal' only" % (self.goal,))
        self.start = _start(self.start)
        if not isinstance(self.start_seed, numbers.Integral):
            raise ValueError("option start_seed=%r: give an integer" % (self.start_seed,))

    @property
    def steps_per_action(self):
        return int(round(1.0 / (self.control_rate * self.physics_step)))

    @property
    def dt(self):
        """[s] of sim time per environment step."""
        return self.steps_per_action * self.physics_step


def _positive(name, value, zero=False):
    ok = isinstance(value, numbers.Real) and math.isfinite(value) and \
        (value >= 0 if zero else value > 0)
    if not ok:
        raise ValueError("option %s=%r: give a finite number %s 0"
                         % (name, value, ">=" if zero else ">"))


def _numbers(name, value, count):
    try:
        values = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ValueError("option %s=%r: give %d finite numbers" % (name, value, count))
    return values


def _start(start):
    if start is None or start == "random":
        return start
    if isinstance(start, numbers.Integral) and not isinstance(start, bool):
        if start < 1:
            raise ValueError("option start=%r: a number of start poses must be >= 1" % start)
        return int(start)
    if isinstance(start, str):
        raise ValueError("option start=%r: give None, 'random', a number N of free poses or a "
                         "list of (x, y, yaw)" % start)
    try:
        items = list(start)
    except TypeError:
        raise ValueError("option start=%r: give None, 'random', a number N of free poses or a "
                         "list of (x, y, yaw)" % (start,)) from None
    if items and all(isinstance(v, numbers.Real) for v in items):
        items = [items]                             # one pose given flat: (x, y, yaw)
    if not items:
        raise ValueError("option start=[]: give at least one (x, y, yaw)")
    poses = items
    return [_numbers("start", p, 3) for p in poses]
