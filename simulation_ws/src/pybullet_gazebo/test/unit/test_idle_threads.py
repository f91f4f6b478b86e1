"""Lockstep's barrier on real processes (no ROS): a child that works on what it is sent is
waited for until it is done; a busy loop is found and not waited for; beside one, a thread
waiting for the GIL is still waited for."""
import ctypes
import select
import subprocess
import sys
import textwrap
import threading
import time

import pytest

from pybullet_gazebo.ros.lockstep.idle_threads import IdleWatch

# Reads a line from stdin, burns `work` s of CPU, answers "done <line>" on stdout.
WORKER = """
import sys, time
work = float(sys.argv[1])
print("ready", flush=True)
for line in sys.stdin:
    end = time.thread_time() + work
    while time.thread_time() < end:
        pass
    print("done " + line.strip(), flush=True)
"""

# The same beside a thread that spins for ever without sleeping (as the series' go_to_point
# does while switched off): the reader needs the GIL the spinner holds.
WORKER_BESIDE_SPINNER = """
import sys, threading
def spin():
    while True:
        pass
threading.Thread(target=spin, daemon=True).start()
print("ready", flush=True)
for line in sys.stdin:
    print("done " + line.strip(), flush=True)
"""

# Spins until a line comes on stdin, then sleeps reading stdin. It spins until told, not for
# a set time: on a loaded machine it may get too little CPU in a set time to be taken for a
# busy loop before it stops.
SPIN_THEN_SLEEP = """
import select, sys
print("ready", flush=True)
while not select.select([sys.stdin], [], [], 0)[0]:
    pass
sys.stdin.readline()
print("asleep", flush=True)
sys.stdin.readline()
"""


@pytest.fixture
def child():
    children = []

    def start(code, *args):
        process = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)] + list(args),
                                   stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        children.append(process)
        assert process.stdout.readline().strip() == "ready"     # Python has started
        return process

    yield start
    for process in children:
        process.kill()
        process.wait()
        process.stdin.close()
        process.stdout.close()


def answered(process):
    """The lines the child has written so far, without waiting."""
    lines = []
    while select.select([process.stdout], [], [], 0)[0]:
        line = process.stdout.readline()
        if not line:
            break
        lines.append(line.strip())
    return lines


def settle(watch, timeout=5.0):
    """What lockstep's settle does: a first look, then the wait, which follows what the
    first look found."""
    busy = watch.busy()
    if busy is None:
        return None
    return watch.wait(time.monotonic() + timeout, busy=busy)


def test_a_sleeping_process_is_idle(child):
    worker = child(WORKER, "0.01")
    watch = IdleWatch()
    watch.watch([worker.pid])
    assert settle(watch) is None                   # once it sleeps in its read, it is idle
    assert watch.busy() is None and watch.spinners() == {}


def test_waits_until_the_child_is_done_with_each_message(child):
    worker = child(WORKER, "0.02")                 # 20 ms of CPU per message
    watch = IdleWatch()
    watch.watch([worker.pid])
    for n in range(20):
        watch.note_sent()
        worker.stdin.write("%d\n" % n)
        worker.stdin.flush()
        assert settle(watch) is None
        assert answered(worker) == ["done %d" % n]  # its answer is out when the wait ends


def test_a_busy_loop_is_found_and_not_waited_for(child):
    spinner = child(SPIN_THEN_SLEEP)
    watch = IdleWatch()
    watch.watch([spinner.pid])
    start = time.monotonic()
    assert settle(watch, timeout=5.0) is None
    assert time.monotonic() - start < 1.0
    assert list(watch.spinners()) == [spinner.pid]


def test_a_busy_loop_that_went_to_sleep_is_waited_for_again(child):
    spinner = child(SPIN_THEN_SLEEP)
    watch = IdleWatch()
    watch.watch([spinner.pid])
    assert settle(watch) is None and list(watch.spinners()) == [spinner.pid]
    spinner.stdin.write("sleep\n")
    spinner.stdin.flush()
    assert spinner.stdout.readline().strip() == "asleep"
    time.sleep(0.05)
    assert watch.busy() is None and watch.spinners() == {}


def test_beside_a_busy_loop_a_thread_waiting_for_the_gil_is_waited_for(child):
    worker = child(WORKER_BESIDE_SPINNER)
    watch = IdleWatch()
    watch.watch([worker.pid])
    assert settle(watch) is None and list(watch.spinners()) == [worker.pid]
    for n in range(10):
        watch.note_sent()
        worker.stdin.write("%d\n" % n)
        worker.stdin.flush()
        assert settle(watch) is None
        assert answered(worker) == ["done %d" % n]


def test_a_process_that_ended_is_dropped(child):
    worker = child(WORKER, "0.01")
    watch = IdleWatch()
    watch.watch([worker.pid])
    worker.kill()
    worker.wait()
    assert watch.busy() is None and watch.pids == set()


# A relay: a reader thread takes each line from stdin and hands it to the main thread, which
# passes it through a pipe to a second process (RELAY_END) that works on it and answers. Work
# goes from thread to thread and process to process; no one is running at the hand-offs'
# edges for long, which a look reading thread after thread could fall between.
RELAY = """
import os, queue, subprocess, sys, threading
end = subprocess.Popen([sys.executable, "-c", sys.argv[1]], stdin=subprocess.PIPE,
                       stdout=sys.stdout, text=True)
print("ready %d" % end.pid, flush=True)
lines = queue.Queue()
threading.Thread(target=lambda: [lines.put(line) for line in sys.stdin], daemon=True).start()
while True:
    end.stdin.write(lines.get())
    end.stdin.flush()
"""
RELAY_END = """
import sys, time
print("end ready", flush=True)
for line in sys.stdin:
    end = time.thread_time() + 0.002
    while time.thread_time() < end:
        pass
    print("done " + line.strip(), flush=True)
"""


def test_work_handed_on_between_threads_and_processes_is_waited_for_to_the_end():
    relay = subprocess.Popen([sys.executable, "-c", textwrap.dedent(RELAY),
                              textwrap.dedent(RELAY_END)],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        first = relay.stdout.readline().split()
        assert first[0] == "ready"
        # both Pythons have started, as the other tests wait for their child's "ready": a
        # start-up still at work when the watch first looks could be taken for a busy loop
        assert relay.stdout.readline().strip() == "end ready"
        watch = IdleWatch()
        watch.watch([relay.pid, int(first[1])])
        assert settle(watch) is None
        for n in range(200):
            watch.note_sent()
            relay.stdin.write("%d\n" % n)
            relay.stdin.flush()
            assert settle(watch) is None
            assert answered(relay) == ["done %d" % n], "message %d" % n
    finally:
        relay.kill()
        relay.wait()
        relay.stdin.close()
        relay.stdout.close()


@pytest.mark.parametrize("columns, backlog", [(15, (13, 14)), (13, (11,)), (11, ())])
def test_the_kernel_backlog_columns_follow_the_kernel(columns, backlog):
    from pybullet_gazebo.ros.lockstep.idle_threads import _backlog_columns
    assert _backlog_columns(columns) == backlog


def _timer_slack():
    return ctypes.CDLL(None).prctl(30, 0, 0, 0, 0)          # PR_GET_TIMERSLACK [ns]


def test_a_wait_asks_for_precise_sleeps_in_its_own_thread_only(child):
    """A wait polls every 30 us: with Linux's default timer slack (50 us) each sleep would
    last ~80 us. The thread that waits gets 1 ns; other threads keep theirs."""
    worker = child(WORKER, "0.005")
    watch = IdleWatch()
    watch.watch([worker.pid])
    slack = {}

    def waiter():
        ctypes.CDLL(None).prctl(29, 50000, 0, 0, 0)         # Linux's default: 50 us
        slack["before"] = _timer_slack()
        watch.note_sent()
        worker.stdin.write("1\n")
        worker.stdin.flush()
        watch.wait(time.monotonic() + 5.0, busy=watch.busy())
        slack["after"] = _timer_slack()
    ours = _timer_slack()
    thread = threading.Thread(target=waiter)
    thread.start()
    thread.join()
    assert slack["before"] == 50000 and slack["after"] == 1
    assert _timer_slack() == ours                           # this thread's is unchanged
    assert answered(worker) == ["done 1"]
