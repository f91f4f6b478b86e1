"""pybullet_gazebo.ros.testing.wait_until, the one way a test waits: it returns the
predicate's first truthy value, and fails after its time-out naming what it waited for and
the last value it saw (no ROS master needed)."""
import time

import pytest

from pybullet_gazebo.ros.testing import wait_until


def test_returns_the_first_truthy_value_at_once():
    calls = []

    def ready():
        calls.append(1)
        return ["m2wr"]
    started = time.monotonic()
    assert wait_until(ready, 5.0, "a model") == ["m2wr"]
    assert calls == [1]
    assert time.monotonic() - started < 0.5


def test_polls_until_the_predicate_holds():
    values = iter([0, None, "", 3, 4])
    assert wait_until(lambda: next(values), 5.0, "a connection", interval=0.001) == 3


def test_fails_after_the_timeout_naming_what_and_the_last_value():
    values = iter(range(-1000, 0))
    started = time.monotonic()
    with pytest.raises(AssertionError) as failure:
        wait_until(lambda: next(values) * 0, 0.2, "a subscriber on /cmd_vel", interval=0.01)
    took = time.monotonic() - started
    assert 0.2 <= took < 1.0
    assert str(failure.value) == ("timed out waiting for a subscriber on /cmd_vel within 0.2 s "
                                  "(last value: 0)")


def test_the_predicate_is_asked_once_more_at_the_deadline():
    started = time.monotonic()
    # true only after 0.15 s: a 1 s interval would sleep past it, but the sleep ends at the
    # 0.2 s deadline and the predicate is asked there
    value = wait_until(lambda: time.monotonic() - started > 0.15, 0.2, "a late truth",
                       interval=1.0)
    assert value is True
    assert time.monotonic() - started < 0.5


def test_a_zero_timeout_asks_once():
    assert wait_until(lambda: 7, 0.0, "seven") == 7
    with pytest.raises(AssertionError, match="timed out waiting for nothing within 0.0 s"):
        wait_until(lambda: None, 0.0, "nothing")


def test_an_exception_in_the_predicate_is_not_swallowed():
    def broken():
        raise ValueError("the master is gone")
    with pytest.raises(ValueError, match="the master is gone"):
        wait_until(broken, 5.0, "anything")
