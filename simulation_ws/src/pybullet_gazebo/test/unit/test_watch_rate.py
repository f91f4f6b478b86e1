"""The wall-time limit of the watching topics (ros/watch_rate.py): at real time every message
goes out, as in Gazebo; faster than real time at most the limit per wall second."""
import math
import random

import pytest

from pybullet_gazebo.ros.watch_rate import WallRateLimit, topic_limit


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def run(limit, times):
    """How many of the calls at wall `times` [s] the limit lets through."""
    clock = FakeClock()
    gate = WallRateLimit(limit, clock=clock)
    passed = 0
    for t in times:
        clock.now = 100.0 + t
        passed += gate.allow()
    return passed, gate.skipped


def test_real_time_with_jitter_loses_nothing():
    rng = random.Random(3)
    # 50 Hz of sim time at real time, each call up to 8 ms early or late
    times = [i / 50.0 + rng.uniform(-0.008, 0.008) for i in range(3000)]
    passed, skipped = run(topic_limit(30.0, 50.0), sorted(times))
    assert (passed, skipped) == (3000, 0)


def test_catching_up_after_a_stall_loses_nothing():
    # the pacer stalls 0.4 s, then steps at full speed until sim time is back on schedule
    times = [i / 50.0 for i in range(50)]
    times += [1.4 + i * 1e-4 for i in range(20)]        # 20 messages due during the stall
    times += [1.4 + (i + 1) / 50.0 for i in range(50)]
    passed, skipped = run(topic_limit(30.0, 50.0), times)
    assert skipped == 0 and passed == len(times)


def test_faster_than_real_time_is_held_to_the_limit():
    # 50 Hz of sim time at 30x real time: 1500 calls per wall second for 10 s
    times = [i / 1500.0 for i in range(15000)]
    passed, skipped = run(topic_limit(30.0, 50.0), times)
    # 50 per wall second, plus the half second's burst allowed at the start
    assert 10 * 50 <= passed <= 10 * 50 + 0.5 * 50 + 2
    assert skipped == 15000 - passed


def test_passed_calls_are_evenly_spread_when_limited():
    clock = FakeClock()
    gate = WallRateLimit(30.0, clock=clock)
    passed_at = []
    for i in range(20000):
        clock.now = 100.0 + i / 2000.0
        if gate.allow():
            passed_at.append(clock.now)
    steady = [b - a for a, b in zip(passed_at, passed_at[1:])][40:]
    assert max(steady) == pytest.approx(1 / 30.0, abs=1e-3)
    assert min(steady) == pytest.approx(1 / 30.0, abs=1e-3)


def test_zero_means_no_limit():
    times = [i / 10000.0 for i in range(5000)]
    assert run(topic_limit(0.0, 50.0), times) == (5000, 0)
    assert run(0.0, times) == (5000, 0)


def test_topic_limit_never_below_the_topics_own_rate():
    assert topic_limit(30.0, 20.0) == 30.0        # m2wr's wheel joint states, 20 Hz sim
    assert topic_limit(30.0, 50.0) == 50.0        # model_states at 50 Hz sim
    assert topic_limit(30.0, 100.0) == 100.0      # a joint_state_publisher at 100 Hz
    assert topic_limit(30.0, math.inf) == 0.0     # every step: not limited
    assert topic_limit(0.0, 20.0) == 0.0


def test_ready_foretells_allow_and_takes_nothing():
    # the loop asks ready() to decide whether to stop at the next model_states step: it
    # must say what allow() would say at that moment, and asking must not use up the limit
    clock = FakeClock()
    gate = WallRateLimit(50.0, clock=clock)
    asked = WallRateLimit(50.0, clock=clock)
    rng = random.Random(4)
    t = 0.0
    for _ in range(5000):
        t += rng.expovariate(300.0)              # ~300 calls per wall second: limited
        clock.now = 100.0 + t
        for _ in range(3):
            expected = asked.ready()
        assert asked.allow() == expected
        assert gate.allow() == expected          # the twin that was never asked
    assert 0 < gate.skipped == asked.skipped < 5000


def test_ready_without_a_limit_is_always_true():
    gate = WallRateLimit(0.0, clock=FakeClock())
    assert all(gate.ready() for _ in range(10))
