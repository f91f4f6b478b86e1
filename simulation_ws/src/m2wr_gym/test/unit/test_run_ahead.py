"""M2wrEnv.run_ahead, called between steps (as SharedMemoryVectorEnv's workers do while the
learner chooses), changes nothing a user sees: every step returns, bit for bit, what it
returns without it (observation, reward, flags, info), over episodes that drive into
obstacles, at several control rates, for both tasks, both action spaces and with laser
noise; and it really runs physics ahead of the last step."""
import gymnasium
import numpy as np
import pytest

CASES = [   # (options, whether its episodes meet an obstacle)
    (dict(world="world02", start="random", observation="scan", action="continuous"), True),
    (dict(world="world01", start=8, observation="regions", action="discrete",
          control_rate=20.0), False),
    (dict(world="world02", start="random", observation="scan", downsample=8,
          action="continuous", laser_noise=0.01, control_rate=5.0), True),
    (dict(world="world02", start="random", observation="regions", action="continuous",
          control_rate=8.0, end_on_contact=False), True),
]


def episodes(kwargs, ahead, env_id="m2wr_gym:M2wrAvoid-v0", seeds=(0, 1), steps=250):
    """Every step's (observation, reward, terminated, truncated, info) of episodes with
    random actions (forward-biased, so they reach walls), and how far physics had run
    ahead of the last step when each next step began [physics steps]."""
    env = gymnasium.make(env_id, max_episode_seconds=10.0, **kwargs)
    rng = np.random.default_rng(5)
    out, lead = [], []
    for seed in seeds:
        env.reset(seed=seed)
        for _ in range(steps):
            if ahead:
                env.unwrapped.run_ahead()
            sim = env.unwrapped.sim
            lead.append(sim.world.step_count - round(env.unwrapped._snapshot.sim_time
                                                     / sim.physics_step))
            if env.unwrapped.options.action == "discrete":
                action = int(rng.choice(3, p=[0.6, 0.2, 0.2]))
            else:
                action = rng.uniform([-0.2, -1.0], [0.6, 1.0]).astype(np.float32)
            result = env.step(action)
            out.append(result)
            if result[2] or result[3]:
                env.reset()
    env.close()
    return out, lead


def assert_identical(plain, ahead):
    assert len(plain) == len(ahead)
    for k, (a, b) in enumerate(zip(plain, ahead)):
        assert np.array_equal(a[0], b[0], equal_nan=True), k
        assert a[1:4] == b[1:4], k
        assert list(a[4]) == list(b[4]) and all(
            a[4][key] == b[4][key] or a[4][key] != a[4][key] for key in a[4]), k


@pytest.mark.parametrize("kwargs, contact", CASES)
def test_steps_are_identical_with_and_without_running_ahead(kwargs, contact):
    plain, lead_plain = episodes(kwargs, ahead=False)
    ahead, lead = episodes(kwargs, ahead=True)
    assert_identical(plain, ahead)
    assert max(lead_plain) == 0          # without it, physics stops where a step ends
    assert max(lead) > 1                 # physics did run ahead of the last step
    # what was compared: episodes that ended and began anew, and contacts
    assert sum(step[2] or step[3] for step in plain) >= 2
    assert any(step[4]["touched"] for step in plain) == contact


def test_goal_task_identical_too():
    kwargs = dict(world="world02", start="random", observation="scan", downsample=4,
                  action="continuous")
    plain, _ = episodes(kwargs, False, "m2wr_gym:M2wrGoal-v0", seeds=(3,), steps=100)
    ahead, _ = episodes(kwargs, True, "m2wr_gym:M2wrGoal-v0", seeds=(3,), steps=100)
    assert_identical(plain, ahead)


def test_what_a_user_reads_between_steps_stays_at_the_last_step():
    env = gymnasium.make("m2wr_gym:M2wrAvoid-v0", world="world02", start="random",
                         action="continuous", render_mode="rgb_array")
    env.reset(seed=2)
    last = env.step(np.array([0.4, 0.3], np.float32))[4]["sim_time"]
    picture, clearance = env.render(), env.unwrapped.clearance()
    count = env.unwrapped.sim.world.step_count
    env.unwrapped.run_ahead()
    env.unwrapped.run_ahead()                        # a second call adds nothing
    assert env.unwrapped.sim.world.step_count == count + 9   # up to the drive's next update
    assert np.array_equal(env.render(), picture) and env.unwrapped.clearance() == clearance
    info = env.step(np.array([0.4, 0.3], np.float32))[4]
    assert info["sim_time"] == pytest.approx(last + 0.1)
    env.close()
