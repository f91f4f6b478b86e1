"""The short ways a step takes give what the plain ways give: the command for an action, the
five regions (reading_laser.py's numbers, NaN and inf included), the scan with no-returns
set to range_max, the goal part of the
goal task's observation (np.clip of goal_in_robot_frame), bit for bit."""
import math

import gymnasium
import numpy as np
import pytest

from m2wr_gym import actions, observation
from m2wr_gym.actions import InvalidAction


def plain_command(action):
    """to_command's continuous result as its full checks compute it."""
    v, w = np.asarray(action, dtype=np.float64).reshape(-1)
    return float(v), float(w)


@pytest.mark.parametrize("dtype", [np.float16, np.float32, np.float64])
def test_continuous_commands_equal_the_plain_conversion(dtype):
    rng = np.random.default_rng(1)
    edges = [(0.6, -1.0), (-0.6, 1.0), (0.6 + 1e-6, 1.0 + 1e-6), (-0.0, 0.0)]
    samples = [np.array(edge, dtype) for edge in edges]
    samples += [rng.uniform((-0.6, -1.0), (0.6, 1.0)).astype(dtype) for _ in range(200)]
    for action in samples:
        v, w = plain_command(action)
        if abs(v) > 0.6 + 1e-6 or abs(w) > 1.0 + 1e-6:     # float16 rounds 0.6 up to 0.6001
            with pytest.raises(InvalidAction, match="out of range"):
                actions.to_command("continuous", action, "gazebo")
            continue
        command = actions.to_command("continuous", action, "gazebo")
        assert command == (v, w)
        assert [math.copysign(1.0, c) for c in command] == \
            [math.copysign(1.0, c) for c in plain_command(action)]          # -0.0 kept
        assert all(type(c) is float for c in command)
    for other in ([0.3, -0.5], (0.3, -0.5), np.array([[0.3, -0.5]]), np.array([0, 1])):
        assert actions.to_command("continuous", other, "gazebo") == plain_command(other)


@pytest.mark.parametrize("action, words", [
    (np.array([0.6 + 2e-6, 0.0]), "out of range"),
    (np.array([0.0, -1.0 - 2e-6], np.float32), "out of range"),
    (np.array([math.inf, 0.0]), "NaN or inf"),
    (np.array([0.0, math.nan], np.float16), "NaN or inf"),
])
def test_continuous_errors_keep_their_messages(action, words):
    with pytest.raises(InvalidAction, match=words):
        actions.to_command("continuous", action, "gazebo")


def test_a_two_number_action_is_not_a_discrete_one():
    with pytest.raises(InvalidAction, match="is not one of 0"):
        actions.to_command("discrete", np.array([0.1, 0.0], np.float32), "gazebo")


def test_discrete_commands_are_the_table_rows():
    for turning in actions.TURNINGS:
        table = actions.discrete_table(turning)
        for index in range(3):
            for action in (index, np.int64(index), float(index)):
                command = actions.to_command("discrete", action, turning)
                assert command == tuple(float(c) for c in table[index])
                assert all(type(c) is float for c in command)


def reading_laser_regions(ranges):
    """The five regions as one numpy min per slice, then min(..., 10), to float32."""
    return np.array([min(float(ranges[a:b].min()), 10.0) for a, b in observation.REGION_SLICES],
                    dtype=np.float32)


def test_regions_equal_one_min_per_slice_with_inf_and_nan():
    rng = np.random.default_rng(2)
    for k in range(300):
        ranges = rng.uniform(0.1, 12.0, 720).astype(np.float32)
        ranges[rng.integers(0, 720, 200)] = np.inf
        if k % 3 == 0:
            ranges[rng.integers(0, 720, 2)] = np.nan
        if k % 5 == 0:
            ranges[rng.integers(0, 720, 50)] = 10.0
        if k % 7 == 0:                  # nothing on the right, only far things front-right
            ranges[0:143] = np.inf
            ranges[144:287] = rng.uniform(10.5, 12.0, 143)
        got, want = observation.regions(ranges), reading_laser_regions(ranges)
        assert got.dtype == np.float32 and got.tobytes() == want.tobytes()
    as_tuple = tuple(float(r) for r in ranges)           # as a LaserScan's ranges arrive
    assert observation.regions(as_tuple).tobytes() == reading_laser_regions(ranges).tobytes()


@pytest.mark.parametrize("downsample", [1, 4])
def test_scan_replaces_every_non_finite_range_by_range_max(downsample):
    rng = np.random.default_rng(3)
    ranges = rng.uniform(0.1, 12.0, 720).astype(np.float32)
    ranges[rng.integers(0, 720, 200)] = np.inf
    ranges[[5, 6, 400]] = [np.nan, -np.inf, np.nan]
    want = np.where(np.isfinite(ranges), ranges, np.float32(10.0))
    want = want.reshape(-1, downsample).min(axis=1)
    got = observation.scan(ranges, 10.0, downsample)
    assert got.dtype == np.float32 and got.tobytes() == want.tobytes()
    assert np.isinf(ranges).sum() >= 150                    # the scan given is left as it was
    as_tuple = tuple(float(r) for r in ranges)               # as a LaserScan's ranges arrive
    assert observation.scan(as_tuple, 10.0, downsample).tobytes() == want.tobytes()


@pytest.mark.parametrize("goal", [(1.5, 7.0), (100.0, 8.0), (-50.0, -40.0)])
def test_goal_part_of_the_observation_is_the_clipped_goal_in_the_robot_frame(goal):
    env = gymnasium.make("m2wr_gym:M2wrGoal-v0", goal=goal).unwrapped
    obs, info = env.reset(seed=0)
    for step in range(3):
        want = np.clip(observation.goal_in_robot_frame(goal, info["x"], info["y"], info["yaw"]),
                       -30.0, 30.0)
        assert obs.dtype == np.float32 and obs[-2:].tobytes() == want.tobytes()
        obs, _, _, _, info = env.step(0)
    if goal[0] == 100.0:
        assert obs[-2] == 30.0                 # 100 m ahead: clipped to the bound
    env.close()
