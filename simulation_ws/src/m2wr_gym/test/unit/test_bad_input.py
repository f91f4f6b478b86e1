"""Bad input gives a clear error naming it; with invalid_action='end' a vectorised run goes
on past a bad action."""
import math

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AsyncVectorEnv

from m2wr_gym.actions import InvalidAction


def make(**kwargs):
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **kwargs)


@pytest.mark.parametrize("kwargs, words", [
    (dict(world="world99"), ["world99", "world01, world02"]),
    (dict(world="/nonexistent/x.world"), ["/nonexistent/x.world"]),
    (dict(wrold="world02"), ["unknown option wrold", "world"]),
    (dict(observation="camera"), ["observation='camera'", "regions, scan"]),
    (dict(action="joystick"), ["action='joystick'"]),
    (dict(turning="left"), ["turning='left'", "gazebo, legacy"]),
    (dict(observation="scan", downsample=7), ["downsample=7", "720"]),
    (dict(control_rate=7.0), ["control_rate=7.0", "physics steps"]),
    (dict(control_rate=float("nan")), ["control_rate=nan"]),
    (dict(laser_noise=-1.0), ["laser_noise=-1.0"]),
    (dict(start=[(0.0, 4.73, 0.0)]), ["start pose (x=0, y=4.73", "inside an obstacle"]),
    (dict(start="somewhere"), ["start='somewhere'"]),
    (dict(goal=(1, 2)), ["goal=", "task='goal'"]),
])
def test_bad_options_are_named(kwargs, words):
    with pytest.raises(ValueError) as err:
        make(**kwargs)
    for word in words:
        assert word in str(err.value), str(err.value)


def test_a_start_pose_inside_an_obstacle_at_reset_is_named():
    env = make()
    with pytest.raises(ValueError, match=r"start pose \(x=-0.94, y=4.73.*inside an obstacle"):
        env.reset(seed=0, options={"start": (-0.94, 4.73, 0.0)})
    env.reset(seed=0)                          # the env is still usable
    env.close()


@pytest.mark.parametrize("action, words", [
    (np.array([math.nan, 0.0], np.float32), "NaN"),
    (np.array([0.7, 0.0], np.float32), "out of range"),
    (np.array([0.1, 0.2, 0.3], np.float32), "3 values"),
])
def test_bad_continuous_actions_are_named(action, words):
    env = make(action="continuous")
    env.reset(seed=0)
    with pytest.raises(InvalidAction, match=words):
        env.step(action)
    env.step(np.array([0.1, 0.0], np.float32))           # and the env goes on
    env.close()


def test_bad_discrete_action_is_named():
    env = make()
    env.reset(seed=0)
    for bad in (3, -1, 1.5):
        with pytest.raises(InvalidAction, match="is not one of 0 .forward., 1 .left., 2 .right."):
            env.step(bad)
    env.close()


def _ending_env():
    return make(action="continuous", invalid_action="end")


def test_a_vectorised_run_goes_on_past_a_bad_action():
    vector = AsyncVectorEnv([_ending_env, _ending_env])
    try:
        vector.reset(seed=[0, 1])
        good = np.array([0.3, 0.0], np.float32)
        bad = np.array([math.nan, 0.0], np.float32)
        _, _, terminated, truncated, info = vector.step(np.stack([good, bad]))
        assert truncated.tolist() == [False, True] and not terminated.any()
        assert "NaN" in info["invalid_action"][1]
        for _ in range(3):                                  # both sub-envs keep stepping
            obs, _, _, truncated, _ = vector.step(np.stack([good, good]))
        assert not truncated.any() and np.all(np.isfinite(obs))
    finally:
        vector.close()
