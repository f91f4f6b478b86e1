"""Lockstep and real-time pacing without ROS: when the loop waits for a controller, and for
how long."""
import threading
import time

from pybullet_gazebo.ros.pacing import Lockstep, RealTimePacer


def make(enabled=True, timeout=0.5):
    timeouts = []
    lock = Lockstep(enabled, timeout, on_timeout=lambda: timeouts.append(time.monotonic()),
                    is_shutdown=lambda: False)
    return lock, timeouts


def test_no_wait_before_the_command_is_needed_or_when_nobody_commands():
    lock, timeouts = make()
    lock.expect_answer(commands_before=0, needed_at=0.05)
    start = time.monotonic()
    lock.wait_if_due(0.045, lambda: True)              # physics runs on until 0.05 s
    lock.wait_if_due(0.05, lambda: False)              # due, but no controller publishes
    assert time.monotonic() - start < 0.05 and timeouts == []


def test_waits_until_the_answer_arrives():
    lock, timeouts = make(timeout=5.0)
    lock.expect_answer(commands_before=lock.commands, needed_at=0.05)
    threading.Timer(0.2, lock.command_arrived).start()
    start = time.monotonic()
    lock.wait_if_due(0.05, lambda: True)
    waited = time.monotonic() - start
    assert 0.15 < waited < 2.0 and timeouts == []


def test_gives_up_after_the_timeout_and_says_so():
    lock, timeouts = make(timeout=0.2)
    lock.expect_answer(commands_before=lock.commands, needed_at=0.0)
    start = time.monotonic()
    lock.wait_if_due(0.0, lambda: True)
    assert 0.15 < time.monotonic() - start < 1.0 and len(timeouts) == 1


def test_disabled_or_forgotten_lockstep_never_waits():
    lock, timeouts = make(enabled=False, timeout=5.0)
    lock.expect_answer(0, 0.0)
    lock.wait_if_due(1.0, lambda: True)
    lock, timeouts = make(timeout=5.0)
    lock.expect_answer(0, 0.0)
    lock.forget()                                      # a reset
    start = time.monotonic()
    lock.wait_if_due(1.0, lambda: True)
    assert time.monotonic() - start < 0.1 and timeouts == []


def test_pacer_holds_the_real_time_factor():
    pacer = RealTimePacer(real_time_factor=2.0, sim_time=0.0)
    start = time.monotonic()
    pacer.pace(0.4)                                    # 0.4 s of sim at 2x: 0.2 s of wall
    assert 0.18 < time.monotonic() - start < 0.6
    unlimited = RealTimePacer(0.0)
    start = time.monotonic()
    unlimited.pace(100.0)
    assert time.monotonic() - start < 0.05
