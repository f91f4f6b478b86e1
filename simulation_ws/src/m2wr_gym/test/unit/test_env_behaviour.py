"""What a user of the environments sees: exact steps of dt, the robot's motion for each
action and turning choice, the five regions as reading_laser.py prints them, episodes that
end on contact, free random starts."""
import math

import gymnasium
import numpy as np
import pytest

from m2wr_gym import observation


def make(**kwargs):
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **kwargs).unwrapped


def yaw_change(env, action, steps=10):
    _, info0 = env.reset(seed=0)
    for _ in range(steps):
        _, _, _, _, info = env.step(action)
    return math.atan2(math.sin(info["yaw"] - info0["yaw"]), math.cos(info["yaw"] - info0["yaw"]))


def test_one_step_is_exactly_dt_of_sim_time():
    env = make(control_rate=20.0)
    assert env.dt == pytest.approx(0.05)
    _, info = env.reset(seed=0)
    times = [info["sim_time"]]
    for _ in range(5):
        times.append(env.step(0)[4]["sim_time"])
    assert np.allclose(np.diff(times), 0.05, atol=1e-9)
    env.close()


def test_forward_drives_at_the_commanded_speed():
    env = make(action="continuous")
    _, info0 = env.reset(seed=0)
    for _ in range(20):                          # 2 s at 0.4 m/s
        _, _, term, _, info = env.step(np.array([0.4, 0.0], np.float32))
    assert not term
    assert info["x"] - info0["x"] == pytest.approx(0.8, abs=0.06)   # first 0.05 s: no command
    assert abs(info["y"] - info0["y"]) < 0.02
    env.close()


def test_discrete_left_turns_left_in_both_turning_modes():
    for turning in ("gazebo", "legacy"):
        env = make(turning=turning)
        assert yaw_change(env, 1) > 0.4, turning      # counter-clockwise, seen from above
        assert yaw_change(env, 2) < -0.4, turning
        env.close()


def test_positive_angular_z_turns_clockwise_as_in_gazebo_and_counter_clockwise_in_legacy():
    env = make(action="continuous")
    assert yaw_change(env, np.array([0.0, 0.5], np.float32)) < -0.3
    env.close()
    env = make(action="continuous", turning="legacy")
    assert yaw_change(env, np.array([0.0, 0.5], np.float32)) > 0.3
    env.close()


def test_regions_are_reading_laser_numbers():
    ranges = np.full(720, np.inf, np.float32)
    ranges[100] = 2.5           # right
    ranges[143] = 0.5           # reading_laser's slices skip beam 143
    ranges[300] = 1.25          # front
    ranges[713] = 0.2           # ... and beams 713-719
    assert observation.regions(ranges).tolist() == [2.5, 10.0, 1.25, 10.0, 10.0]


def test_first_observation_at_the_tutorial_start_sees_the_north_wall_on_the_left():
    env = make(laser_noise=0.0)
    obs, info = env.reset(seed=0)
    assert (info["x"], info["y"]) == pytest.approx((0.0, 8.0), abs=1e-3)
    right, fright, front, fleft, left = obs
    assert left < 1.2 and fleft < 1.5          # the north wall, 1.4 m from the laser
    assert right > 2.0                         # row A is 3.3 m to the south
    env.close()


def test_contact_ends_the_episode_with_a_penalty():
    env = make(max_episode_seconds=60.0)
    env.reset(seed=0)                           # (0, 8) facing east: a barrel 8 m ahead
    for step in range(400):
        _, reward, terminated, truncated, info = env.step(0)
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert info["touched"], info
    assert reward < -4.0
    assert info["x"] > 7.0
    env.close()


def test_time_limit_truncates():
    env = make(max_episode_seconds=1.0)
    env.reset(seed=0)
    ends = [env.step(1)[3] for _ in range(10)]
    assert ends == [False] * 9 + [True]
    env.close()


def test_random_starts_are_free_and_follow_the_seed():
    env = make(start="random")
    starts = []
    for seed in (1, 2, 1):
        _, info = env.reset(seed=seed)
        starts.append((info["x"], info["y"]))
        assert env.clearance() > 0.3
    assert starts[0] == pytest.approx(starts[2], abs=1e-6) and starts[0] != starts[1]
    env.close()


def test_goal_task_rewards_approach_and_ends_at_the_goal():
    env = make(task="goal", action="continuous", goal=(1.5, 8.0))
    obs, _ = env.reset(seed=0)
    assert obs[-2:] == pytest.approx([1.5, 0.0], abs=0.01)      # goal ahead, in robot frame
    total = 0.0
    for _ in range(60):
        obs, reward, terminated, _, info = env.step(np.array([0.5, 0.0], np.float32))
        total += reward
        if terminated:
            break
    assert terminated and not info["touched"]
    assert math.hypot(info["x"] - 1.5, info["y"] - 8.0) <= 0.3
    assert total > 5.0
    env.close()
