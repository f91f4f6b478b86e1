"""Lockstep and real-time pacing without ROS: when the loop waits for the controllers, and for
how long."""
import threading
import time

from pybullet_gazebo.ros.lockstep.gate import Lockstep
from pybullet_gazebo.ros.pacing import RealTimePacer


class FakeWatch:
    """An IdleWatch stand-in: busy until `idle_at` (monotonic) or for ever (None)."""

    def __init__(self, idle_at=0.0):
        self.idle_at = idle_at
        self.sent = 0
        self.followed = []          # what each wait was told the look before it found

    def note_sent(self):
        self.sent += 1

    def busy(self, new_round=True):
        if self.idle_at is not None and time.monotonic() >= self.idle_at:
            return None
        return (4242, 4243)

    def wait(self, deadline, interrupted=lambda: False, busy=None):
        self.followed.append(busy)
        while self.busy() is not None:
            if time.monotonic() >= deadline or interrupted():
                return self.busy()
            time.sleep(0.001)
        return None


def make(watch, enabled=True, timeout=0.5, paused=lambda: False):
    """A Lockstep whose one controller sends no reports: it is watched (the fallback)."""
    told = []
    lock = Lockstep(enabled, timeout, None, watch, is_shutdown=lambda: False, is_paused=paused,
                    describe=lambda busy: "pid %d" % busy[0], on_timeout=told.append)
    lock.wait_for(reporting=(), watched={"/no_reports"})
    return lock, told


def test_nothing_sent_nothing_waited_for():
    lock, told = make(FakeWatch(idle_at=None))
    start = time.monotonic()
    assert lock.settle() and time.monotonic() - start < 0.05
    assert lock.stats.settles == 0 and told == []


def test_waits_until_the_controllers_are_idle():
    watch = FakeWatch(idle_at=time.monotonic() + 0.2)
    lock, told = make(watch, timeout=5.0)
    lock.sending()
    assert watch.sent == 1 and lock.unsettled
    start = time.monotonic()
    assert lock.settle()
    assert time.monotonic() - start >= 0.19 and not lock.unsettled
    assert (lock.stats.settles, lock.stats.waits, lock.stats.timeouts) == (1, 1, 0)
    assert told == []
    assert watch.followed == [(4242, 4243)]     # the wait starts from the look that found it


def test_idle_at_once_is_a_settle_without_a_wait():
    lock, _ = make(FakeWatch(idle_at=0.0))
    lock.sending()
    assert lock.settle()
    assert (lock.stats.settles, lock.stats.waits) == (1, 0)


def test_steps_on_after_the_timeout_naming_who_was_busy_once():
    lock, told = make(FakeWatch(idle_at=None), timeout=0.1)
    for _ in range(3):
        lock.sending()
        assert lock.settle()
    assert told == ["pid 4242"]
    assert lock.stats.timeouts == 3 and lock.stats.stepped_past == {"pid 4242": 3}
    assert "3 time-outs (still at work: pid 4242 3 x)" in lock.stats.summary()


def test_a_pause_ends_the_wait_without_a_verdict():
    paused = []
    lock, told = make(FakeWatch(idle_at=None), timeout=5.0, paused=lambda: bool(paused))
    lock.sending()
    threading.Timer(0.1, paused.append, args=(True,)).start()
    start = time.monotonic()
    assert not lock.settle()
    assert time.monotonic() - start < 2.0
    assert lock.unsettled and told == [] and lock.stats.timeouts == 0


def test_disabled_or_forgotten_lockstep_never_waits():
    watch = FakeWatch(idle_at=None)
    lock, told = make(watch, enabled=False, timeout=5.0)
    lock.sending()
    assert watch.sent == 0 and lock.settle()
    lock, told = make(FakeWatch(idle_at=None), timeout=5.0)
    lock.sending()
    lock.forget()                                      # a reset
    start = time.monotonic()
    assert lock.settle() and time.monotonic() - start < 0.1 and told == []


class Board:
    """A lockstep/board.py stand-in: busy until `done_at` (monotonic)."""

    def __init__(self, done_at):
        self.done_at = done_at
        self.version = 0
        self.silent = set()

    def pending_calls(self, nodes):
        return False

    def busy(self, nodes):
        self.version += 1                 # as if a report came at every look
        return None if time.monotonic() >= self.done_at else ("/ctl", "no report yet")

    def wait(self, nodes, deadline, interrupted=lambda: False):
        while self.busy(nodes) is not None:
            if time.monotonic() >= deadline or interrupted():
                return self.busy(nodes)
            time.sleep(0.001)
        return None


def test_settled_now_never_waits_and_settles_once_the_reports_say_done():
    board = Board(done_at=time.monotonic() + 0.2)
    lock = Lockstep(True, 5.0, board, None, is_shutdown=lambda: False)
    lock.wait_for(reporting={"/ctl"}, watched=())
    assert lock.settled_now()                                   # nothing sent
    lock.sending()
    start = time.monotonic()
    assert not lock.settled_now() and time.monotonic() - start < 0.05
    assert lock.unsettled and lock.stats.settles == 0
    time.sleep(0.25)
    assert lock.settled_now() and not lock.unsettled
    assert (lock.stats.settles, lock.stats.waits, lock.stats.wall_waiting) == (1, 0, 0.0)
    assert lock.settle() and lock.stats.settles == 1          # nothing left to wait for


def test_a_controller_watched_in_proc_is_settled_only_by_a_wait():
    lock, told = make(FakeWatch(idle_at=0.0), timeout=5.0)
    lock.sending()
    assert not lock.settled_now()                 # two looks: only settle() takes them
    assert lock.settle() and told == []


def test_a_timeout_on_a_report_names_why_and_skips_the_node_until_it_reports():
    board = Board(done_at=float("inf"))
    told = []
    lock = Lockstep(True, 0.05, board, None, is_shutdown=lambda: False,
                    on_timeout=told.append)
    lock.wait_for(reporting={"/ctl"}, watched=())
    lock.sending()
    assert lock.settle()
    assert told == ["node /ctl (no report yet)"] and board.silent == {"/ctl"}
    assert "by handshake (exact): /ctl" in lock.stats.summary()


def test_the_summary_counts_ticks_handed_on_while_stepping():
    lock, _ = make(FakeWatch())
    assert "ticks" not in lock.stats.summary()
    lock.stats.ticks, lock.stats.ticks_while_stepping = 20, 17
    assert "17 of 20 /clock ticks to a loop node handed on while physics ran" in \
        lock.stats.summary()


def test_pacer_holds_the_real_time_factor():
    pacer = RealTimePacer(real_time_factor=2.0, sim_time=0.0)
    start = time.monotonic()
    pacer.pace(0.4)                                    # 0.4 s of sim at 2x: 0.2 s of wall
    assert 0.18 < time.monotonic() - start < 0.6
    unlimited = RealTimePacer(0.0)
    start = time.monotonic()
    unlimited.pace(100.0)
    assert time.monotonic() - start < 0.05
