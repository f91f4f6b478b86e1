"""gymnasium's own checker on every environment and space variant, and the creation call the
README shows (module-prefixed id: no import first)."""
import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

VARIANTS = [
    dict(task="avoid", observation="regions", action="discrete"),
    dict(task="avoid", observation="regions", action="continuous"),
    dict(task="avoid", observation="scan", action="discrete"),
    dict(task="avoid", observation="scan", downsample=8, action="continuous"),
    dict(task="goal", observation="regions", action="discrete"),
    dict(task="goal", observation="scan", downsample=20, action="continuous"),
    dict(task="avoid", world="world01", turning="legacy", control_rate=20.0, laser_noise=0.0),
]


@pytest.mark.parametrize("kwargs", VARIANTS, ids=lambda k: ",".join("%s=%s" % i for i in k.items()))
def test_check_env(kwargs):
    env = gymnasium.make("m2wr_gym:M2wrAvoid-v0", **kwargs)
    try:
        check_env(env.unwrapped, skip_render_check=True)
        obs, _ = env.reset(seed=1)
        assert env.observation_space.contains(obs)
    finally:
        env.close()


def test_spaces_have_the_documented_shapes():
    shapes = {}
    for kwargs in VARIANTS[:6]:
        env = gymnasium.make("m2wr_gym:M2wrAvoid-v0", **kwargs)
        shapes[tuple(sorted(kwargs.items()))] = (env.observation_space.shape, env.action_space)
        env.close()
    got = list(shapes.values())
    assert got[0][0] == (5,) and got[0][1] == gymnasium.spaces.Discrete(3)
    assert got[2][0] == (720,)
    assert got[3][0] == (90,) and got[3][1].shape == (2,)
    assert got[4][0] == (7,)                     # five regions + goal (x, y) in robot frame
    assert got[5][0] == (38,)


def test_make_in_a_fresh_interpreter_needs_no_import():
    code = ("import gymnasium; env = gymnasium.make('m2wr_gym:M2wrAvoid-v0'); "
            "o, _ = env.reset(seed=0); print(env.unwrapped.dt, o.shape)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "0.1 (5,)"


def test_rgb_array_is_a_top_down_picture():
    env = gymnasium.make("m2wr_gym:M2wrAvoid-v0", render_mode="rgb_array")
    env.reset(seed=0)
    picture = env.render()
    env.close()
    assert picture.dtype == np.uint8 and picture.ndim == 3 and picture.shape[2] == 3
    # obstacles drawn in grey, the robot in orange
    grey = np.all(np.abs(picture.astype(int) - 115) < 3, axis=2).mean()
    assert grey > 0.02
