"""SharedMemoryVectorEnv returns what gymnasium's AsyncVectorEnv returns for the same seeds
and actions (observations, rewards, flags, merged infos, autoreset), reports an error in one
sub-environment naming it and goes on, notices a dead worker, and leaves no process."""
import functools
import math
import os
import signal
import time

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AsyncVectorEnv, AutoresetMode

from m2wr_gym.actions import InvalidAction
from m2wr_gym.info_slots import MAX_SLOTS, decode_info, encode_info
from m2wr_gym.shared_vector import SharedMemoryVectorEnv, SubEnvironmentError, WorkerDiedError

# 1 s episodes (10 steps): 25 steps see two autoresets
KWARGS = dict(start="random", observation="scan", downsample=4, action="continuous",
              max_episode_seconds=1.0)


def make():
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **KWARGS)


def make_discrete():
    return gymnasium.make("m2wr_gym:M2wrAvoid-v0", **dict(KWARGS, action="discrete"))


def actions_for(space, steps, seed=42):
    space.seed(seed)
    return [space.sample() for _ in range(steps)]


def trace(vector, actions, seed):
    """[reset's (obs, info), then each step's (obs, reward, terminated, truncated, info)]."""
    out = [vector.reset(seed=seed)]
    for action in actions:
        out.append(vector.step(action))
    return out


def assert_same(a, b, where):
    """Equal values, types, dtypes and (for dicts) key order."""
    if isinstance(a, dict):
        assert list(a) == list(b), where
        for key in a:
            assert_same(a[key], b[key], "%s[%r]" % (where, key))
    elif isinstance(a, (tuple, list)):
        assert type(a) is type(b) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, "%s[%d]" % (where, k))
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, \
            (where, a, b)
        if a.dtype == object:
            for k, (x, y) in enumerate(zip(a, b)):
                assert_same(x, y, "%s[%d]" % (where, k))
        else:
            assert np.array_equal(a, b, equal_nan=True), (where, a, b)
    else:
        assert type(a) is type(b) and (a == b or (a != a and b != b)), (where, a, b)


@pytest.mark.parametrize("maker, mode, local, spin", [
    (make, AutoresetMode.NEXT_STEP, False, 0.0),
    (make, AutoresetMode.SAME_STEP, False, 0.0),
    (make_discrete, AutoresetMode.NEXT_STEP, False, 0.0),
    (make, AutoresetMode.NEXT_STEP, True, 0.0),
    (make, AutoresetMode.SAME_STEP, True, 0.002)])
def test_same_results_as_async_vector_env(maker, mode, local, spin):
    """local: sub-environment 0 stepped in the learner's process; spin: both sides poll."""
    results = {}
    for cls in (AsyncVectorEnv, SharedMemoryVectorEnv):
        options = {"local": local, "spin": spin} if cls is SharedMemoryVectorEnv else {}
        vector = cls([maker, maker], autoreset_mode=mode, **options)
        try:
            actions = actions_for(vector.action_space, 25)
            results[cls] = trace(vector, actions, seed=[3, 4])
        finally:
            vector.close()
    ours, theirs = results[SharedMemoryVectorEnv], results[AsyncVectorEnv]
    for step, (a, b) in enumerate(zip(theirs, ours)):
        assert_same(a, b, "step %d" % step)
    assert len(vector.processes) == (1 if local else 2)
    # what was compared: episodes ended and restarted, m2wr moved
    ended = [r for r in ours[1:] if r[3].any()]
    assert len(ended) == 2 and ours[-1][4]["distance"].max() > 0
    if mode is AutoresetMode.SAME_STEP:
        assert "final_obs" in ended[0][4] and "final_info" in ended[0][4]


def test_same_observations_as_in_process_envs():
    vector = SharedMemoryVectorEnv([make, make])
    try:
        actions = actions_for(vector.action_space, 8)
        ours = trace(vector, actions, seed=[5, 9])
    finally:
        vector.close()
    for k, seed in enumerate((5, 9)):
        env = make()
        obs, info = env.reset(seed=seed)
        assert np.array_equal(ours[0][0][k], obs)
        for step, action in enumerate(actions, 1):
            obs, reward, terminated, truncated, info = env.step(action[k])
            assert np.array_equal(ours[step][0][k], obs) and ours[step][1][k] == reward
            merged = ours[step][4]
            assert merged["x"][k] == info["x"] and merged["command"][k] == info["command"]
        env.close()


def test_api_spaces_metadata_and_a_gymnasium_vector_wrapper():
    vector = SharedMemoryVectorEnv([make, make])
    try:
        assert vector.metadata["autoreset_mode"] is AutoresetMode.NEXT_STEP
        assert vector.num_envs == 2 and vector.single_observation_space == make().observation_space
        assert vector.observation_space.shape == (2, 180)
        assert vector.action_space.shape == (2, 2)
        recorded = gymnasium.wrappers.vector.RecordEpisodeStatistics(vector)
        obs, _ = recorded.reset(seed=0)
        assert obs in vector.observation_space
        vector.action_space.seed(0)
        episodes = None
        for _ in range(11):
            obs, rewards, terminated, truncated, infos = recorded.step(vector.action_space.sample())
            assert obs in vector.observation_space and rewards.dtype == np.float64
            if "episode" in infos:
                episodes = infos["episode"]
        assert episodes is not None and list(episodes["l"]) == [10, 10]
        assert vector.call("dt") == (0.1, 0.1)
        assert len(vector.get_attr("max_steps")) == 2
    finally:
        vector.close()


def test_reset_with_a_seed_repeats_and_another_differs():
    vector = SharedMemoryVectorEnv([make, make])
    try:
        actions = actions_for(vector.action_space, 4)
        first = trace(vector, actions, seed=7)
        again = trace(vector, actions, seed=7)
        other = trace(vector, actions, seed=8)
    finally:
        vector.close()
    for step, (a, b) in enumerate(zip(first, again)):
        assert_same(a, b, "step %d" % step)
    assert not np.array_equal(first[0][0], other[0][0])


def test_an_error_in_one_worker_is_named_and_the_run_goes_on():
    vector = SharedMemoryVectorEnv([make, make])
    try:
        vector.reset(seed=0)
        good = np.array([0.3, 0.0], np.float32)
        bad = np.array([math.nan, 0.0], np.float32)
        before = vector.step(np.stack([good, good]))[0]
        with pytest.raises(SubEnvironmentError) as caught:
            vector.step(np.stack([good, bad]))
        error = caught.value
        pid = vector.processes[1].pid
        message = str(error)
        for words in ("sub-environment 1", "pid %d" % pid, "InvalidAction", "step", "nan",
                      "NaN"):
            assert words in message, message
        assert isinstance(error.__cause__, InvalidAction) and error.index == 1
        obs, rewards, terminated, truncated, infos = error.result
        assert not np.array_equal(obs[0], before[0])      # sub-environment 0 stepped
        assert np.array_equal(obs[1], before[1])          # 1 did not
        assert list(infos["_x"]) == [True, False] and rewards[1] == 0.0
        for _ in range(3):                                 # both go on
            obs, _, terminated, truncated, infos = vector.step(np.stack([good, good]))
        assert not (terminated.any() or truncated.any()) and np.all(np.isfinite(obs))
        assert infos["sim_time"][0] - infos["sim_time"][1] == pytest.approx(0.1)   # one step less
        with pytest.raises(SubEnvironmentError, match=r"sub-environment 0 .*reset\(seed=0, "
                                                      r"options=.*inside an obstacle"):
            vector.reset(seed=0, options={"start": (-0.94, 4.73, 0.0)})
        obs, _ = vector.reset(seed=0)
        assert obs.shape == (2, 180)
    finally:
        vector.close()
    assert_gone(vector)


def assert_gone(vector):
    for process in vector.processes:
        assert process.exitcode is not None
        assert not os.path.exists("/proc/%d" % process.pid), process.pid   # reaped too


def test_close_leaves_no_process_and_workers_ignore_ctrl_c():
    vector = SharedMemoryVectorEnv([make, make])
    pids = [process.pid for process in vector.processes]
    vector.reset(seed=0)
    for pid in pids:
        os.kill(pid, signal.SIGINT)            # blocked in workers: a Ctrl-C is the learner's
    obs, *_ = vector.step(np.zeros((2, 2), np.float32))
    assert obs.shape == (2, 180)
    vector.close()
    assert_gone(vector)
    with pytest.raises(gymnasium.error.ClosedEnvironmentError):
        vector.step(np.zeros((2, 2), np.float32))


def test_a_dead_worker_is_reported_not_waited_for():
    vector = SharedMemoryVectorEnv([make, make])
    try:
        vector.reset(seed=0)
        victim = vector.processes[1].pid
        os.kill(victim, signal.SIGKILL)
        started = time.monotonic()
        with pytest.raises(WorkerDiedError, match=r"sub-environment 1's worker \(pid %d\) died "
                                                  r"during step \(killed by SIGKILL\)" % victim):
            vector.step(np.zeros((2, 2), np.float32))
        assert time.monotonic() - started < 5.0
        with pytest.raises(WorkerDiedError):
            vector.step(np.zeros((2, 2), np.float32))
    finally:
        vector.close()
    assert_gone(vector)


def test_info_encoding_round_trip_keeps_types_and_order():
    info = {"t": 0.25, "n": 3, "ok": True, "f32": np.float32(1.5), "i32": np.int32(-4),
            "command": (0.1, -0.2), "none": (), "touched": ("wall_1", "box"),
            "final_info": {"x": 1.0}, "big": 2 ** 60, "inf": math.inf}
    slots = np.zeros(MAX_SLOTS)
    layout, extras = encode_info(info, slots)
    assert set(extras) == {"touched", "final_info", "big"}      # the rest went into slots
    back = decode_info(layout, slots, extras)
    assert list(back) == list(info)
    for key, value in info.items():
        assert type(back[key]) is type(value) and back[key] == value, key


def test_sb3_adapter_gives_what_subproc_vec_env_gives():
    pytest.importorskip("stable_baselines3")       # the training extra (scripts/train.sh)
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import SubprocVecEnv
    from m2wr_gym.sb3_vector import SharedMemoryVecEnv
    results = {}
    for name, cls, options in (("sb3", SubprocVecEnv, {"start_method": "fork"}),
                               ("ours", SharedMemoryVecEnv, {})):
        venv = cls([make_monitored, make_monitored], **options)
        try:
            venv.seed(3)
            out = [venv.reset(), [dict(info) for info in venv.reset_infos]]
            for action in actions_for(make().action_space, 2 * 12, seed=1)[::2]:
                out.append(venv.step(np.stack([action, -action])))
                out.append([dict(info) for info in venv.reset_infos])
            assert venv.env_is_wrapped(Monitor) == [True, True]
            assert venv.get_attr("dt", indices=[1]) == [0.1]
        finally:
            venv.close()
        results[name] = out
    for step, (a, b) in enumerate(zip(results["sb3"], results["ours"])):
        if isinstance(a, tuple):                     # a step: SB3 gives its infos as a tuple
            a = a[:3] + (list(a[3]),)
        for infos in (a, b):
            for info in (infos[3] if isinstance(infos, tuple) else infos):
                if isinstance(info, dict) and "episode" in info:
                    del info["episode"]["t"]         # the episode's wall time
        assert_same(a, b, "step %d" % step)
    dones = [r[2] for r in results["ours"] if isinstance(r, tuple)]
    assert sum(d.sum() for d in dones) == 2                # one episode ended in each


def make_monitored():
    from stable_baselines3.common.monitor import Monitor
    return Monitor(make())


def test_forkserver_workers_wait_for_a_slow_learner():
    """Workers of a forkserver are not the learner's children: they still wait (> their 1 s
    liveness check) for the next step."""
    # (a function the forkserver can import: this test module may not be importable there)
    vector = SharedMemoryVectorEnv([functools.partial(gymnasium.make, "m2wr_gym:M2wrAvoid-v0",
                                                      **KWARGS)], context="forkserver")
    try:
        vector.reset(seed=0)
        time.sleep(1.5)
        obs, *_ = vector.step(np.zeros((1, 2), np.float32))
        assert obs.shape == (1, 180)
    finally:
        vector.close()
    assert_gone(vector)


def test_an_error_in_the_learners_own_sub_environment_is_named_too():
    vector = SharedMemoryVectorEnv([make, make], local=True)
    try:
        vector.reset(seed=0)
        good = np.array([0.3, 0.0], np.float32)
        with pytest.raises(SubEnvironmentError, match=r"sub-environment 0 \(the learner's "
                                                      r"process, pid %d\) raised InvalidAction "
                                                      r"in step, given array\(\[nan" % os.getpid()):
            vector.step(np.stack([np.array([math.nan, 0.0], np.float32), good]))
        obs, _, _, _, infos = vector.step(np.stack([good, good]))
        assert infos["sim_time"][1] - infos["sim_time"][0] == pytest.approx(0.1)
        assert vector.call("dt") == (0.1, 0.1)
    finally:
        vector.close()
    assert_gone(vector)


def physics_lead(env):
    """[physics steps] the world has run past what the last step returned."""
    sim = env.unwrapped.sim
    return sim.world.step_count - round(env.unwrapped._snapshot.sim_time / sim.physics_step)


def make_with_a_failing_run_ahead():
    """An env whose run_ahead raises on its second call (the one after the first step)."""
    env = make()
    calls = []

    def run_ahead():
        calls.append(None)
        if len(calls) == 2:
            raise RuntimeError("run_ahead broke on purpose")
    env.unwrapped.run_ahead = run_ahead
    return env


def test_workers_run_ahead_while_the_learner_waits_and_its_errors_are_named():
    vector = SharedMemoryVectorEnv([make, make])
    plain = SharedMemoryVectorEnv([make, make], run_ahead=False)
    try:
        vector.reset(seed=1)
        plain.reset(seed=1)
        action = np.array([[0.4, 0.2], [0.2, -0.5]], np.float32)
        for _ in range(3):
            ours, theirs = vector.step(action), plain.step(action)
            assert_same(theirs, ours, "step")
        assert vector.apply(physics_lead) == (9, 9)   # up to the drive's next update
        assert plain.apply(physics_lead) == (0, 0)
    finally:
        vector.close()
        plain.close()
    vector = SharedMemoryVectorEnv([make, make_with_a_failing_run_ahead])
    try:
        vector.reset(seed=0)
        zeros = np.zeros((2, 2), np.float32)
        vector.step(zeros)                           # its run_ahead fails after this step
        with pytest.raises(SubEnvironmentError, match=r"sub-environment 1 .*RuntimeError in "
                                                      r"step.*run_ahead broke on purpose"):
            vector.step(zeros)
        obs, *_ = vector.step(zeros)                  # and it goes on
        assert obs.shape == (2, 180)
    finally:
        vector.close()
    assert_gone(vector)
