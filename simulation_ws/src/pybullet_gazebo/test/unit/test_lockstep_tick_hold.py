"""The controller's side of the word on its /clock ticks (lockstep/tick_hold.py): a tick is
set only once the readings sent before it are taken in; ticks the simulator left free, ticks
of another publisher or connection, and ticks of a process no simulator told HOLD pass at
once; word for ticks dropped unread is passed over; a tick whose word never comes is set
after HOLD_CAP and counted."""
import threading
import time

from pybullet_gazebo.ros.lockstep import tick_hold
from pybullet_gazebo.ros.lockstep.tick_hold import HOLD, TICK, TickHold

SIM, SCAN, CLOCK_PORT, SCAN_PORT = "/gazebo", "/m2wr/laser/scan", 41000, 41002


class Connection:
    done = False


class Counts:
    def __init__(self):
        self.taken = {}

    def __call__(self):
        return dict(self.taken)


def held(free=0):
    counts, connection = Counts(), Connection()
    hold = TickHold(counts)
    hold.heard(HOLD, CLOCK_PORT, free, {}, SIM, connection)
    return hold, counts, connection


def word(hold, number, scans, connection):
    hold.heard(TICK, CLOCK_PORT, number, {(SCAN, SCAN_PORT): scans}, SIM, connection)


def wait_in_thread(hold, number, publisher=SIM, port=CLOCK_PORT):
    done = threading.Event()
    thread = threading.Thread(target=lambda: (hold.wait_for_word(number, publisher, port,
                                                                 time.monotonic), done.set()))
    thread.start()
    return done, thread


def test_a_tick_is_set_only_once_the_scan_sent_before_it_is_taken_in():
    hold, counts, connection = held()
    word(hold, 1, 1, connection)
    done, thread = wait_in_thread(hold, 1)
    assert not done.wait(0.2)                    # the scan is still in its callback
    counts.taken[(SCAN, SIM, SCAN_PORT)] = 1
    hold.taken_changed()
    assert done.wait(2.0)
    thread.join()
    assert hold.late == 0


def test_a_tick_waits_for_its_word_that_comes_after_it():
    hold, counts, connection = held()
    counts.taken[(SCAN, SIM, SCAN_PORT)] = 3
    done, thread = wait_in_thread(hold, 1)
    assert not done.wait(0.2)
    word(hold, 1, 3, connection)
    assert done.wait(2.0)
    thread.join()


def test_ticks_left_free_other_publishers_and_processes_never_told_pass_at_once():
    free = TickHold(Counts())
    free.wait_for_word(1, SIM, CLOCK_PORT, time.monotonic)            # never told HOLD
    hold, _, connection = held(free=4)
    word(hold, 5, 99, connection)
    start = time.monotonic()
    hold.wait_for_word(4, SIM, CLOCK_PORT, time.monotonic)            # sent before HOLD
    hold.wait_for_word(5, "/other_clock", CLOCK_PORT, time.monotonic)
    hold.wait_for_word(5, SIM, CLOCK_PORT + 1, time.monotonic)        # another connection
    connection.done = True                                            # the simulator left
    hold.wait_for_word(5, SIM, CLOCK_PORT, time.monotonic)
    assert time.monotonic() - start < 0.5 and hold.late == 0


def test_word_of_dropped_ticks_is_passed_over_and_the_last_word_of_a_tick_counts():
    hold, counts, connection = held()
    word(hold, 1, 1, connection)                 # tick 1 dropped unread (queue_size 1)
    word(hold, 2, 5, connection)                 # tick 2's first write found the socket full
    word(hold, 2, 2, connection)
    counts.taken[(SCAN, SIM, SCAN_PORT)] = 2
    start = time.monotonic()
    hold.wait_for_word(2, SIM, CLOCK_PORT, time.monotonic)
    assert time.monotonic() - start < 0.5 and hold.late == 0


def test_a_tick_whose_word_never_comes_is_set_after_the_cap_and_counted(monkeypatch):
    monkeypatch.setattr(tick_hold, "HOLD_CAP", 0.2)
    hold, _, _ = held()
    start = time.monotonic()
    hold.wait_for_word(1, SIM, CLOCK_PORT, time.monotonic)
    assert 0.15 < time.monotonic() - start < 1.5
    assert hold.late == 1


def test_a_new_hold_forgets_the_words_of_the_last():
    hold, counts, connection = held()
    word(hold, 1, 7, connection)
    other = Connection()
    hold.heard(HOLD, CLOCK_PORT, 0, {}, SIM, other)    # the simulator's next connection
    word(hold, 1, 0, connection)                       # (the old one's word: not taken)
    word(hold, 1, 1, other)
    counts.taken[(SCAN, SIM, SCAN_PORT)] = 1
    start = time.monotonic()
    hold.wait_for_word(1, SIM, CLOCK_PORT, time.monotonic)
    assert time.monotonic() - start < 0.5 and hold.late == 0
