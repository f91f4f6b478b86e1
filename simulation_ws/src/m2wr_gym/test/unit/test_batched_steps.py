"""The in-process environment steps physics through World.advance, which runs quiet
stretches in one Bullet call: its episodes are bit for bit those of stepping one physics
step at a time (observations with laser noise, rewards, endings, poses, contacts)."""
import gymnasium
import numpy as np

from pybullet_gazebo.engine.stepping import Stepper

ACTIONS = np.random.default_rng(5).uniform([-0.6, -1.0], [0.6, 1.0], size=(60, 2)).astype(np.float32)
AHEAD = np.array([0.6, 0.0], dtype=np.float32)          # full speed ahead: into obstacles


def rollout(seed):
    env = gymnasium.make("m2wr_gym:M2wrAvoid-v0", start="random", observation="scan",
                         action="continuous", end_on_contact=False)
    obs, info = env.reset(seed=seed)
    trace = [(obs.tobytes(), info["x"], info["y"], info["yaw"], info["sim_time"])]
    for index, action in enumerate(ACTIONS):
        obs, reward, terminated, truncated, info = env.step(AHEAD if index % 3 else action)
        trace.append((obs.tobytes(), reward, terminated, truncated, info["x"], info["y"],
                      info["yaw"], info["sim_time"], info["touched"]))
    env.close()
    return trace


def test_batched_episodes_equal_step_by_step_ones(monkeypatch):
    batched = [rollout(seed) for seed in (3, 5)]
    assert any(step[-1] for trace in batched for step in trace[1:])    # some touched a model
    monkeypatch.setattr(Stepper, "_quiet_steps", lambda self, most, now, skipped=None: (1, ()))
    single = [rollout(seed) for seed in (3, 5)]
    assert batched == single
