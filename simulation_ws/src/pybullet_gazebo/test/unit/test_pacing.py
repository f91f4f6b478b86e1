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


def test_a_loop_controller_is_woken_before_the_wait_and_its_command_counts():
    """A controller on rospy.Rate publishes when /clock reaches its tick, not on a scan: the
    loop brings /clock up to now (before_wait) and that command is the awaited answer."""
    woken = []
    lock = Lockstep(True, 5.0, on_timeout=lambda: None, is_shutdown=lambda: False,
                    before_wait=lambda: (woken.append(True),
                                         threading.Timer(0.05, lock.command_arrived).start()))
    lock.expect_answer(commands_before=lock.commands, needed_at=0.05)
    start = time.monotonic()
    lock.wait_if_due(0.05, lambda: True)
    assert woken == [True] and time.monotonic() - start < 2.0 and lock.commands == 1


def test_no_wake_up_when_the_answer_came_already():
    woken = []
    lock = Lockstep(True, 5.0, on_timeout=lambda: None, is_shutdown=lambda: False,
                    before_wait=lambda: woken.append(True))
    lock.expect_answer(commands_before=lock.commands, needed_at=0.05)
    lock.command_arrived()
    lock.wait_if_due(0.05, lambda: True)
    assert woken == []


def test_silent_controllers_cost_one_timeout_until_a_command_comes_again():
    """Controllers switched off: one wait of `timeout`, then none, until a command arrives;
    then lockstep waits for answers again."""
    lock, timeouts = make(timeout=0.2)
    start = time.monotonic()
    for scan in range(5):
        lock.expect_answer(commands_before=lock.commands, needed_at=0.05 * scan)
        lock.wait_if_due(0.05 * scan, lambda: True)
    assert len(timeouts) == 1 and time.monotonic() - start < 0.6
    lock.command_arrived()                             # a controller is back
    lock.expect_answer(commands_before=lock.commands, needed_at=1.0)
    threading.Timer(0.1, lock.command_arrived).start()
    lock.wait_if_due(1.0, lambda: True)
    assert lock.commands == 2 and len(timeouts) == 1
    lock.expect_answer(commands_before=lock.commands, needed_at=1.05)
    lock.wait_if_due(1.05, lambda: True)               # silent again: waits and says so
    assert len(timeouts) == 2


def test_a_pause_is_not_silence():
    """An agent pauses physics after each observation and thinks as long as it likes: the
    wait ends without a timeout, no step is allowed, and after the pause the same answer is
    awaited again (a timeout here made the next episode's first steps skip lockstep)."""
    paused = [False]
    timeouts = []
    lock = Lockstep(True, 0.3, on_timeout=lambda: timeouts.append(True),
                    is_shutdown=lambda: False, is_paused=lambda: paused[0])
    lock.expect_answer(commands_before=lock.commands, needed_at=0.05)
    threading.Timer(0.05, lambda: paused.__setitem__(0, True)).start()
    start = time.monotonic()
    assert lock.wait_if_due(0.05, lambda: True) is False       # the pause ended the wait
    assert time.monotonic() - start < 0.25 and timeouts == []
    time.sleep(0.5)                                            # longer than the timeout
    paused[0] = False
    threading.Timer(0.1, lock.command_arrived).start()
    assert lock.wait_if_due(0.05, lambda: True) is True        # the same answer, awaited
    assert lock.commands == 1 and timeouts == []


def test_a_reset_forgets_the_silence():
    lock, timeouts = make(timeout=0.1)
    lock.expect_answer(commands_before=lock.commands, needed_at=0.0)
    lock.wait_if_due(0.0, lambda: True)
    assert len(timeouts) == 1 and lock.silent_at == lock.commands
    lock.forget()                                              # reset_simulation
    lock.expect_answer(commands_before=lock.commands, needed_at=0.05)
    threading.Timer(0.05, lock.command_arrived).start()
    start = time.monotonic()
    lock.wait_if_due(0.05, lambda: True)                       # waited for, not skipped
    assert lock.commands == 1 and time.monotonic() - start >= 0.04 and len(timeouts) == 1


def test_a_loop_whose_tick_lies_after_the_update_is_stepped_past_without_a_timeout():
    """A behaviour switched on just after its loop ticked answers only at its next tick,
    after the drive's update: even the wake-up /clock brings no answer. Lockstep steps on
    after a quarter of its timeout (the command reaches the wheels one update later, as in Gazebo),
    reports no silence, and waits for the next scan's answer as usual."""
    woken, timeouts = [], []
    lock = Lockstep(True, 1.0, on_timeout=lambda: timeouts.append(True),
                    is_shutdown=lambda: False, before_wait=lambda: woken.append(True))
    lock.expect_answer(commands_before=lock.commands, needed_at=0.045)
    start = time.monotonic()
    assert lock.wait_if_due(0.045, lambda: True) is True
    waited = time.monotonic() - start
    assert woken == [True] and timeouts == []
    assert 0.25 * 0.9 < waited < 0.9                            # not the 1 s timeout
    lock.command_arrived()                                      # its tick came: it answers
    lock.expect_answer(commands_before=lock.commands, needed_at=0.095)
    threading.Timer(0.05, lock.command_arrived).start()
    lock.wait_if_due(0.095, lambda: True)
    assert lock.commands == 2 and timeouts == [] and lock.stats.step_ons == 1


def test_true_silence_is_reported_once_after_the_timeout_in_all():
    """Every controller switched off: scans step on after a quarter of `timeout` each until no command
    has come for `timeout`; then one report, and no more waiting."""
    lock, timeouts = make(timeout=0.6)
    start, scan = time.monotonic(), 0
    while not timeouts and scan < 20:
        lock.expect_answer(commands_before=lock.commands, needed_at=0.05 * scan)
        lock.wait_if_due(0.05 * scan, lambda: True)
        scan += 1
    silent_after = time.monotonic() - start
    assert len(timeouts) == 1 and 0.55 < silent_after < 1.2 and scan >= 3
    lock.expect_answer(commands_before=lock.commands, needed_at=1.0)
    start = time.monotonic()
    lock.wait_if_due(1.0, lambda: True)                         # silent: no wait any more
    assert time.monotonic() - start < 0.05 and len(timeouts) == 1


def test_a_longer_timeout_waits_longer_before_stepping_on():
    """The batch runner's lockstep_timeout of 30 s: a controller slowed down for 0.5 s by a
    loaded machine is still waited for (a step-on would make a run's metrics depend on the
    load)."""
    lock, timeouts = make(timeout=30.0)
    lock.expect_answer(commands_before=lock.commands, needed_at=0.05)
    threading.Timer(0.5, lock.command_arrived).start()
    assert lock.wait_if_due(0.05, lambda: True) is True
    assert lock.commands == 1 and lock.stats.step_ons == 0 and timeouts == []
