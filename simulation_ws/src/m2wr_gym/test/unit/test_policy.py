"""The deploy path with numpy only: a policy exported to .npz loads and acts the same, files
of the wrong shape are refused naming the file, and the shipped policy. (The ROS node that
runs it, motion_plan/scripts/learned_avoidance.py, is tested in motion_plan's unit tests.)"""
import os
import subprocess
import sys

import numpy as np
import pytest

from m2wr_gym import actions, resources
from m2wr_gym.policy import NumpyPolicy, PolicyFileError, load

SHIPPED = os.path.join(resources.package_path("m2wr_gym"), "policies", "avoid_world02.npz")


def small_policy(rng, n_in=5, hidden=8):
    layers = [(rng.normal(size=(hidden, n_in)), rng.normal(size=hidden)),
              (rng.normal(size=(3, hidden)), rng.normal(size=3))]
    return NumpyPolicy(layers, np.full(n_in, 0.1), actions.discrete_table("gazebo"), "regions")


def test_export_and_load_give_the_same_decisions(tmp_path):
    rng = np.random.default_rng(0)
    policy = small_policy(rng)
    path = str(tmp_path / "p.npz")
    policy.save(path)
    loaded = load(path)
    for _ in range(50):
        obs = rng.uniform(0, 10, 5)
        assert loaded.act(obs) == policy.act(obs)
        assert np.allclose(loaded.scores(obs), policy.scores(obs))
    assert loaded.command(np.full(5, 10.0)) in [tuple(r) for r in actions.discrete_table("gazebo")]


def test_loading_needs_neither_torch_nor_pybullet(tmp_path):
    path = str(tmp_path / "p.npz")
    small_policy(np.random.default_rng(1)).save(path)
    code = ("import sys; from m2wr_gym.policy import load; from m2wr_gym import observation; "
            "p = load(%r); print(p.act([1, 2, 3, 4, 5])); "
            "print(sorted(m for m in ('torch', 'pybullet', 'stable_baselines3') if m in sys.modules))"
            % path)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"


@pytest.mark.parametrize("change, words", [
    (lambda a: a.update(W1=np.zeros((3, 9))), "layer 1 takes 9 inputs but layer 0 gives 8"),
    (lambda a: a.update(b0=np.zeros(3)), "b0 (3,)"),
    (lambda a: a.update(actions=np.zeros((4, 2))), "actions has shape (4, 2)"),
    (lambda a: a.update(obs_scale=np.zeros(7)), "obs_scale has shape (7,)"),
    (lambda a: a.pop("W0"), "lacks W0"),
    (lambda a: a.update(format=np.array("other")), "format is other"),
    (lambda a: a.update(W0=np.full((8, 5), np.nan)), "NaN"),
])
def test_wrong_policy_files_are_named(tmp_path, change, words):
    path = str(tmp_path / "p.npz")
    small_policy(np.random.default_rng(2)).save(path)
    arrays = dict(np.load(path))
    change(arrays)
    with open(path, "wb") as f:
        np.savez(f, **arrays)
    with pytest.raises(PolicyFileError) as err:
        load(path)
    assert path in str(err.value) and words in str(err.value), str(err.value)


def test_missing_and_foreign_files_are_named(tmp_path):
    with pytest.raises(PolicyFileError, match="not found"):
        load(str(tmp_path / "none.npz"))
    junk = tmp_path / "junk.npz"
    junk.write_text("not numpy")
    with pytest.raises(PolicyFileError, match="junk.npz is not a numpy .npz"):
        load(str(junk))


def wall_ahead(d):
    """The five regions of a straight wall d [m] ahead, across the robot's path: the
    front-left/right regions' nearest beams are 18 deg off, the left/right ones 54 deg."""
    return np.array([d / np.cos(np.radians(54)), d / np.cos(np.radians(18)), d,
                     d / np.cos(np.radians(18)), d / np.cos(np.radians(54))])


def test_shipped_policy_drives_forward_in_the_open_and_turns_at_a_wall():
    policy = load(SHIPPED)
    assert policy.observation == "regions" and policy.input_size == 5
    assert policy.control_period == pytest.approx(0.1)
    forward, left, right = (tuple(r) for r in actions.discrete_table("gazebo"))
    assert policy.command(np.full(5, 10.0)) == forward
    assert policy.command(wall_ahead(3.0)) == forward
    for d in (0.9, 0.6, 0.4):
        assert policy.command(wall_ahead(d)) in (left, right), d
