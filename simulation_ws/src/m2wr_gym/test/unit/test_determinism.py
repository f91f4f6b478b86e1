"""reset(seed=...) makes episodes repeatable: the same seed and actions give identical
observations, in one process (fresh env, or after other episodes) and in two subprocesses
of gymnasium's AsyncVectorEnv."""
import gymnasium
import numpy as np
from gymnasium.vector import AsyncVectorEnv

KWARGS = dict(start="random", observation="scan", downsample=4, action="continuous")
ACTIONS = np.random.default_rng(42).uniform([-0.6, -1.0], [0.6, 1.0], size=(40, 2)).astype(np.float32)


def make():
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **KWARGS)


def rollout(env, seed):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for action in ACTIONS:
        obs, _, terminated, truncated, _ = env.step(action)
        out.append(obs)
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


def test_same_seed_same_observations_in_two_subprocesses():
    vector = AsyncVectorEnv([make, make])
    try:
        obs, _ = vector.reset(seed=[11, 11])
        trace = [obs]
        for action in ACTIONS[:20]:
            obs, _, _, _, _ = vector.step(np.stack([action, action]))
            trace.append(obs)
    finally:
        vector.close()
    trace = np.array(trace)                  # (steps, 2 envs, n)
    assert np.array_equal(trace[:, 0], trace[:, 1])
    local = make()
    here = rollout(local, 11)[:len(trace)]
    local.close()
    assert np.array_equal(trace[:len(here), 0], here)
