"""reset(seed=...) makes episodes repeatable: the same seed and actions give identical
observations, in one process (fresh env, or after other episodes) and in two subprocesses
of gymnasium's AsyncVectorEnv, whose merged info a learner reads holds the in-process
info's keys and values."""
import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AsyncVectorEnv

KWARGS = dict(start="random", observation="scan", downsample=4, action="continuous")
ACTIONS = np.random.default_rng(42).uniform([-0.6, -1.0], [0.6, 1.0], size=(40, 2)).astype(np.float32)


def make():
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **KWARGS)


def rollout(env, seed, infos=None):
    obs, info = env.reset(seed=seed)
    out = [obs]
    if infos is not None:
        infos.append(info)
    for action in ACTIONS:
        obs, _, terminated, truncated, info = env.step(action)
        out.append(obs)
        if infos is not None:
            infos.append(info)
        if terminated or truncated:
            break
    return np.array(out)


def test_same_seed_same_observations_in_process():
    a, b = make(), make()
    first = rollout(a, 7)
    rollout(b, 3)                            # another episode before: nothing carries over
    again = rollout(b, 7)
    a.close(), b.close()
    assert first.shape == again.shape
    assert np.array_equal(first, again)      # bit for bit, laser noise included


def test_different_seeds_differ():
    env = make()
    assert not np.array_equal(rollout(env, 7)[:3], rollout(env, 8)[:3])
    env.close()


@pytest.fixture(scope="module")
def two_subprocesses():
    """20 steps of two AsyncVectorEnv workers given the same seed and actions, and the same
    episode in process: (vector observations, vector infos, local observations, local infos)."""
    vector = AsyncVectorEnv([make, make])
    try:
        obs, info = vector.reset(seed=[11, 11])
        trace, infos = [obs], [info]
        for action in ACTIONS[:20]:
            obs, _, _, _, info = vector.step(np.stack([action, action]))
            trace.append(obs)
            infos.append(info)
    finally:
        vector.close()
    local = make()
    local_infos = []
    here = rollout(local, 11, local_infos)[:len(trace)]
    local.close()
    return np.array(trace), infos, here, local_infos[:len(trace)]


def test_same_seed_same_observations_in_two_subprocesses(two_subprocesses):
    trace, _, here, _ = two_subprocesses     # trace: (steps, 2 envs, n)
    assert np.array_equal(trace[:, 0], trace[:, 1])
    assert np.array_equal(trace[:len(here), 0], here)


def test_the_vector_info_holds_the_in_process_info(two_subprocesses):
    _, infos, _, local_infos = two_subprocesses
    assert len(local_infos) > 10
    for step, (merged, info) in enumerate(zip(infos, local_infos)):
        assert {key for key in merged if not key.startswith("_")} == set(info), step
        for key, value in info.items():
            assert list(merged["_" + key]) == [True, True], (step, key)     # both envs have it
            assert merged[key][0] == value and merged[key][1] == value, (step, key, merged[key])
    # sim time went on, m2wr moved, a command was sent: not just the reset's values
    assert local_infos[-1]["sim_time"] > 0.5 and local_infos[-1]["distance"] > 0.0
    assert local_infos[-1]["command"] != (0.0, 0.0)
