"""The controller's side of the ticks sent with word of what they follow
(lockstep/tick_hold.py): a tick sets the time only once the readings sent before it are taken
in, and the /clock ticks sent before the HOLD; a tick whose counts never come is set after
HOLD_CAP and counted."""
import threading
import time

from pybullet_gazebo.ros.lockstep import tick_hold
from pybullet_gazebo.ros.lockstep.tick_hold import TickHold

SIM, SCAN, CLOCK_PORT, SCAN_PORT = "/gazebo", "/m2wr/laser/scan", 41000, 41002


class Counts:
    def __init__(self):
        self.taken = {}

    def __call__(self):
        return dict(self.taken)


def wait_in_thread(hold, counts):
    done = threading.Event()
    thread = threading.Thread(target=lambda: (hold.wait(SIM, counts, time.monotonic),
                                              done.set()))
    thread.start()
    return done, thread


def test_a_tick_waits_until_the_scan_sent_before_it_is_taken_in():
    counts = Counts()
    hold = TickHold(counts)
    hold.heard_hold(SIM, CLOCK_PORT, 0)
    done, thread = wait_in_thread(hold, {(SCAN, SCAN_PORT): 1})
    assert not done.wait(0.2)                    # the scan is still in its callback
    counts.taken[(SCAN, SIM, SCAN_PORT)] = 1
    hold.taken_changed()
    assert done.wait(2.0)
    thread.join()
    assert hold.late == 0


def test_the_first_tick_waits_for_the_clock_ticks_sent_before_the_hold():
    counts = Counts()
    hold = TickHold(counts)
    hold.heard_hold(SIM, CLOCK_PORT, 3)
    counts.taken[("/clock", SIM, CLOCK_PORT)] = 2
    done, thread = wait_in_thread(hold, {})
    assert not done.wait(0.2)                    # a /clock tick still on its way
    counts.taken[("/clock", SIM, CLOCK_PORT)] = 3
    hold.taken_changed()
    assert done.wait(2.0)
    thread.join()


def test_counts_already_reached_and_another_simulators_tick_pass_at_once():
    counts = Counts()
    counts.taken[(SCAN, SIM, SCAN_PORT)] = 5
    hold = TickHold(counts)
    hold.heard_hold(SIM, CLOCK_PORT, 0)
    start = time.monotonic()
    hold.wait(SIM, {(SCAN, SCAN_PORT): 5}, time.monotonic)
    hold.wait("/other_simulator", {}, time.monotonic)
    assert time.monotonic() - start < 0.5 and hold.late == 0


def test_a_tick_whose_counts_never_come_is_set_after_the_cap_and_counted(monkeypatch):
    monkeypatch.setattr(tick_hold, "HOLD_CAP", 0.2)
    hold = TickHold(Counts())
    start = time.monotonic()
    hold.wait(SIM, {(SCAN, SCAN_PORT): 1}, time.monotonic)
    assert 0.15 < time.monotonic() - start < 1.5
    assert hold.late == 1



def test_a_tick_does_not_wait_for_messages_behind_a_callback_asleep_in_sim_time():
    """What comes on a parked connection is read only once a tick wakes its thread: a tick
    that waited for it would be held to HOLD_CAP, and set late."""
    hold = TickHold(lambda: {}, lambda: {(SCAN, SIM, SCAN_PORT)})
    hold.heard_hold(SIM, clock_port=CLOCK_PORT, clock_count=0)
    started = time.monotonic()
    hold.wait(SIM, {(SCAN, SCAN_PORT): 2}, time.monotonic)
    assert hold.late == 0 and time.monotonic() - started < 0.5 * tick_hold.HOLD_CAP
