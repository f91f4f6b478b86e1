"""M2wrEnv: a gymnasium.Env for m2wr on the stand-in (see options.py for every option).

Each step holds one action for exactly `dt` = 1/control_rate [s] of sim time (a whole number
of physics steps) and returns the observation of the laser's latest scan at the end of it.
The action reaches the wheels at the diff drive's next update (20 Hz), as a cmd_vel does
in the ROS simulator. Sim time restarts at 0 on each reset.

Observation: Box float32, the laser part (5 regions or the scan, [m], see observation.py),
then for the goal task the goal (x, y) [m] in the robot's frame.
Action: see actions.py. Reward and endings: see tasks.py.
info: sim_time [s], x, y, yaw (model frame in the world, [m], [rad]), nearest [m] (the
nearest laser return), touched (models touched this step), distance [m] travelled in the
episode, command (linear.x, angular.z) sent; "invalid_action" when one ended the episode.
render_mode "rgb_array": a top-down picture; "human": pybullet's GUI window.
"""
import logging
import math
import os

import gymnasium
import numpy as np
from gymnasium import spaces

from . import actions, geometry, observation, resources, tasks
from .options import TUTORIAL_START, EnvOptions

LOG = logging.getLogger("m2wr_gym")
GOAL_RANGE = 30.0          # [m] bound of the goal's coordinates in the observation


def _nearest(ranges):
    """[m] the nearest laser return (inf when none: no return is +inf; NaN is no return)."""
    nearest = float(np.fmin.reduce(ranges)) if len(ranges) else math.inf
    return math.inf if math.isnan(nearest) else nearest


class M2wrEnv(gymnasium.Env):
    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}

    def __init__(self, render_mode=None, **kwargs):
        self.options = EnvOptions.from_kwargs(**kwargs)
        if render_mode not in (None, "rgb_array", "human"):
            raise ValueError("render_mode=%r: choose None, 'rgb_array' or 'human'" % (render_mode,))
        self.render_mode = render_mode
        self.metadata = dict(self.metadata, render_fps=self.options.control_rate)
        options = self.options
        self.world_path = resources.resolve_world(options.world)
        self.spec = resources.world_spec(self.world_path)
        self.footprints = geometry.Footprints(self.spec)
        self.dt = options.dt                                     # [s] of sim time per step
        self.max_steps = int(math.ceil(options.max_episode_seconds / self.dt - 1e-9))
        laser = observation.size(options.observation, options.downsample)
        high = np.full(laser, observation.upper_bound(options.observation, 10.0), np.float32)
        low = np.zeros(laser, np.float32)
        if options.task == "goal":
            low = np.concatenate([low, [-GOAL_RANGE, -GOAL_RANGE]]).astype(np.float32)
            high = np.concatenate([high, [GOAL_RANGE, GOAL_RANGE]]).astype(np.float32)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self.action_space = actions.space(options.action)
        self._start_pool = self._draw_start_pool()
        self.sim = self._make_backend()
        self._picture = None
        self._snapshot = None
        self._ended = False
        self._goal = None
        self._path = None         # [(x, y, yaw)] of the episode, kept for rgb_array pictures only
        self._steps_per_action = options.steps_per_action
        self._goal_task = options.task == "goal"
        self._laser_size = laser

    # --- construction -----------------------------------------------------------------
    def _make_backend(self):
        o = self.options
        if o.backend == "ros":
            from .sim_ros import RosSim              # rospy only when asked for
            return RosSim(self.world_path, o.physics_step, o.laser_noise,
                          legacy_mode=o.turning == "legacy")
        from .sim_inprocess import InProcessSim
        gui = self.render_mode == "human"
        if gui and not os.environ.get("DISPLAY"):
            LOG.warning("m2wr_gym: render_mode='human' but there is no display (DISPLAY is "
                        "unset): running without pybullet's window")
            gui = False
        return InProcessSim(self.world_path, o.physics_step, o.laser_noise, gui=gui,
                            legacy_mode=o.turning == "legacy")

    def _draw_start_pool(self):
        start = self.options.start
        if start is None:
            name = self.options.world.replace(".world", "") if isinstance(self.options.world, str) else ""
            return [TUTORIAL_START] if name in ("world01", "world02") else None
        if isinstance(start, int):
            rng = np.random.default_rng(self.options.start_seed)
            return [self.footprints.free_pose(rng) for _ in range(start)]
        if start == "random":
            return None
        for pose in start:
            self.check_start(pose)
        return list(start)

    def check_start(self, pose):
        """ValueError naming the pose when m2wr would overlap an obstacle there."""
        x, y, yaw = pose
        if self.footprints.clearance(x, y, yaw) <= 0.0:
            raise ValueError("start pose (x=%g, y=%g, yaw=%g) puts m2wr inside an obstacle of "
                             "%s; choose a free pose" % (x, y, yaw, self.world_path))

    # --- gymnasium API -------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = sorted(set(options) - {"start", "goal"})
        if unknown:
            raise ValueError("reset options %s unknown; use start=(x, y, yaw) and goal=(x, y)"
                             % ", ".join(unknown))
        rng = self.np_random
        if "start" in options:
            start = tuple(float(v) for v in options["start"])
            if len(start) != 3 or not all(math.isfinite(v) for v in start):
                raise ValueError("reset option start=%r: give (x, y, yaw)" % (options["start"],))
            self.check_start(start)
        elif self._start_pool is None:
            start = self.footprints.free_pose(rng)
        else:
            start = self._start_pool[int(rng.integers(len(self._start_pool)))]
        if self.options.task == "goal":
            if "goal" in options:
                self._goal = tuple(float(v) for v in options["goal"])
            elif self.options.goal is not None:
                self._goal = self.options.goal
            else:
                self._goal = self._draw_goal(rng, start)
        world_seed = int(rng.integers(2 ** 31 - 1))
        self._snapshot = self.sim.reset(*start, seed=world_seed)
        self._steps = 0
        self._ended = False
        self._distance = 0.0
        if self.render_mode == "rgb_array":
            self._path = [(self._snapshot.x, self._snapshot.y, self._snapshot.yaw)]
        return self._observe(), self._info((0.0, 0.0))

    def _draw_goal(self, rng, start):
        for _ in range(1000):
            x, y, _ = self.footprints.free_pose(rng)
            if math.hypot(x - start[0], y - start[1]) >= 1.0:
                return (x, y)
        raise RuntimeError("no goal found at least 1 m from the start; pass goal=(x, y)")

    def step(self, action):
        # (once per step: locals instead of repeated attribute look-ups, no numpy on tiny
        # arrays; the results are bit for bit those of the plain version)
        before = self._snapshot
        if before is None:
            raise RuntimeError("call reset() before step()")
        options = self.options
        try:
            command = actions.to_command(options.action, action, options.turning)
        except actions.InvalidAction as err:
            if options.invalid_action == "raise":
                raise
            LOG.error("m2wr_gym: %s; the episode is truncated (invalid_action='end')", err)
            info = self._info((0.0, 0.0))
            info["invalid_action"] = str(err)
            self._ended = True
            return self._observe(), 0.0, False, True, info
        after = self.sim.run(command[0], command[1], steps=self._steps_per_action)
        self._snapshot = after
        self._steps += 1
        x, y, yaw, touched = after.x, after.y, after.yaw, after.touched
        self._distance += math.hypot(x - before.x, y - before.y)
        if self._path is not None:
            self._path.append((x, y, yaw))
        pose0, pose1 = (before.x, before.y, before.yaw), (x, y, yaw)
        nearest = _nearest(after.ranges)
        if self._goal_task:
            reward, terminated = tasks.goal_reward(pose0, pose1, self._goal,
                                                   options.goal_tolerance, nearest, touched)
        else:
            reward, terminated = tasks.avoid_reward(pose0, pose1, nearest, touched)
        if terminated and touched and not options.end_on_contact:
            terminated = False
        truncated = not terminated and self._steps >= self.max_steps
        self._ended = terminated or truncated
        return self._observe(), float(reward), terminated, truncated, self._info(command, nearest)

    def run_ahead(self):
        """Does now the part of the next step that no action can change (see
        InProcessSim.run_ahead), so that step() has less left to do; what any call returns
        stays exactly as it would have been. For a vector env's worker, in the time it would
        otherwise wait for the learner's next actions. Nothing to do after an episode's
        end, before the first reset, or with the ROS backend."""
        if self._snapshot is not None and not self._ended and hasattr(self.sim, "run_ahead"):
            self.sim.run_ahead(self._steps_per_action)

    def _observe(self):
        s = self._snapshot
        options = self.options
        laser = observation.laser_features(options.observation, s.ranges, s.range_max,
                                           options.downsample)
        if self._goal_task:
            # the goal rounded to float32 then clipped to +-GOAL_RANGE, as np.clip of
            # goal_in_robot_frame would: clipping first gives the same float32 (+-30 is exact)
            n = self._laser_size
            features = np.empty(n + 2, np.float32)
            features[:n] = laser
            gx, gy = observation.goal_offset(self._goal, s.x, s.y, s.yaw)
            features[n] = min(max(gx, -GOAL_RANGE), GOAL_RANGE)
            features[n + 1] = min(max(gy, -GOAL_RANGE), GOAL_RANGE)
            return features
        return laser          # (float32 and a new array already: see observation.py)

    def _info(self, command, nearest=None):
        s = self._snapshot
        info = {"sim_time": s.sim_time, "x": s.x, "y": s.y, "yaw": s.yaw,
                "nearest": _nearest(s.ranges) if nearest is None else nearest,
                "touched": s.touched, "distance": self._distance, "command": command}
        if self._goal is not None:
            info["goal"] = self._goal
        return info

    def render(self):
        if self.render_mode != "rgb_array":
            return None               # "human": pybullet's window shows the world as it steps
        if self._picture is None:
            from .render import TopDown
            self._picture = TopDown(self.footprints)
        s = self._snapshot
        scan = None if s is None else (s.ranges, -math.pi / 2, math.pi / (len(s.ranges) - 1))
        title = "%s, t = %.1f s" % (self.options.task, s.sim_time if s else 0.0)
        return self._picture.draw(self._path or [], scan, self._goal, title)

    @property
    def snapshot(self):
        """What the robot senses and where it is after the last reset or step (the backend's
        Snapshot: the whole scan [m], x, y [m], yaw [rad], sim_time [s], touched); None
        before the first reset."""
        return self._snapshot

    def clearance(self, within=np.inf):
        """Smallest distance [m] from m2wr's footprint to an obstacle's, now (0 = touching;
        inf when nothing is within `within` [m])."""
        s = self._snapshot
        return self.footprints.clearance(s.x, s.y, s.yaw, within)

    def close(self):
        if getattr(self, "sim", None) is not None:
            self.sim.close()
            self.sim = None
