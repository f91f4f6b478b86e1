"""scripts/train.sh's pipeline end to end in a few seconds: PPO on a tiny budget writes a
policy .npz that the numpy loader runs and a learning-curve PNG. Needs the training extra."""
import os

import numpy as np
import pytest

from m2wr_gym.policy import load

pytest.importorskip("stable_baselines3", reason="training extra not installed (scripts/train.sh "
                    "installs requirements-train.txt on first use)")
pytest.importorskip("torch", reason="training extra not installed (torch)")


def test_a_short_training_run_writes_a_runnable_policy_and_a_curve(tmp_path):
    from m2wr_gym import train
    out = str(tmp_path / "run")
    code = train.main(["--timesteps", "300", "--envs", "1", "--episode-seconds", "5",
                       "--report-every", "100", "--out", out, "--hidden", "16"])
    assert code == 0
    policy = load(os.path.join(out, "policy.npz"))
    assert policy.input_size == 5 and len(policy.actions) == 3
    assert 0 <= policy.act(np.full(5, 3.0)) < 3
    with open(os.path.join(out, "learning_curve.png"), "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_two_environments_train_through_the_shared_memory_vector_env(tmp_path):
    from m2wr_gym import train
    out = str(tmp_path / "run")
    code = train.main(["--timesteps", "256", "--envs", "2", "--episode-seconds", "3",
                       "--report-every", "128", "--out", out, "--hidden", "16"])
    assert code == 0
    monitors = [os.path.join(out, "%d.monitor.csv" % i) for i in range(2)]
    steps, returns = train.read_monitor(monitors)
    assert len(returns) >= 2 * 4                 # 128 steps each, episodes of 30 steps
    assert all(os.path.getsize(m) > 0 for m in monitors)
    assert os.path.exists(os.path.join(out, "policy.npz"))
