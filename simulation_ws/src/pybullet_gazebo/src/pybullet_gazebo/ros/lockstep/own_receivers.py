"""The simulator's own side of lockstep's barrier: whether its threads that read from other
nodes are still at work on something they were sent (see idle_threads.py).

A controller that is idle has written its command (or a service request, such as bug2's
set_model_state) to the simulator; the bytes are then in a socket of the simulator's, or a
rospy thread of the simulator is reading or handling them. Those threads are rospy's topic
receivers (one per subscribed connection), service connection handlers, and the TCPROS
server that accepts new connections. Each is idle only when it sleeps inside a socket wait
(recv, poll, accept ...): asleep anywhere else it may be waiting for the GIL or for the
world's lock with a message in hand. Like the controllers' threads, they get a second look
(`moved`, see idle_threads.py): a reader that answered a service call and went back to its
socket between the two has handed work on.

The threads are found by what rospy runs in them (`threading.Thread._target`); the list is
made again whenever the set of threads changes (the batch runner's next controller: its
reader thread replaces the last one's, and their number stays the same).
"""
import os
import threading

from rospy.impl.tcpros_base import TCPServer
from rospy.impl.tcpros_pubsub import robust_connect_subscriber
from rospy.impl.tcpros_service import ServiceImpl

from pybullet_gazebo.ros.lockstep.idle_threads import SOCKET_WAITS, in_socket_wait, state_of

def _is_reader(thread):
    target = getattr(thread, "_target", None)
    if target is robust_connect_subscriber:
        return True
    owner = getattr(target, "__self__", None)
    return isinstance(owner, (ServiceImpl, TCPServer))


class OwnReceivers:
    def __init__(self, held=frozenset):
        """`held()`: native ids of reader threads whose connection the main thread reads
        (inbox.py): they sleep until it is given back, and are not readers meanwhile."""
        self.held = held
        self._threads = ()
        self._files = {}            # reader tid -> (fds of its stat, syscall and schedstat)
        self._runs = {}             # reader tid -> its schedstat at the last look

    def tids(self):
        """The native ids of the reader threads now."""
        threads = threading.enumerate()
        if len(threads) != len(self._threads) or \
                any(a is not b for a, b in zip(threads, self._threads)):
            self._threads = tuple(threads)
            self._open([t.native_id for t in threads if t.native_id and _is_reader(t)])
        return list(self._files)

    def _open(self, tids):
        """Keeps the readers' /proc files open (re-read with pread: 4 us a thread against
        18 us for open, read and close)."""
        for tid in [t for t in self._files if t not in tids]:
            for fd in self._files.pop(tid):
                os.close(fd)
        for tid in tids:
            if tid not in self._files:
                base = "/proc/self/task/%d/" % tid
                try:
                    stat = os.open(base + "stat", os.O_RDONLY)
                except OSError:
                    continue                              # the thread ended meanwhile
                try:
                    syscall = os.open(base + "syscall", os.O_RDONLY)
                except OSError:
                    os.close(stat)
                    continue
                try:
                    self._files[tid] = (stat, syscall, os.open(base + "schedstat", os.O_RDONLY))
                except OSError:
                    os.close(stat)
                    os.close(syscall)

    def busy(self):
        """True while a reader thread is not asleep in a socket wait."""
        self.tids()
        runs = self._runs
        runs.clear()
        held = self.held()
        for tid, (stat_fd, syscall_fd, sched_fd) in self._files.items():
            if tid in held:
                continue
            try:
                runs[tid] = os.pread(sched_fd, 128, 0)          # before its state
                if state_of(os.pread(stat_fd, 512, 0)) != ord("S"):
                    return True
                syscall = os.pread(syscall_fd, 256, 0)
            except (OSError, ValueError, IndexError):
                continue                                  # the thread ended meanwhile
            if SOCKET_WAITS and not in_socket_wait(syscall):
                return True
        return False

    def moved(self):
        """After busy() found all readers idle: True if one has run since or is running."""
        held = self.held()
        for tid, (stat_fd, _, sched_fd) in self._files.items():
            if tid in held:
                continue
            try:
                if state_of(os.pread(stat_fd, 512, 0)) != ord("S") or \
                        os.pread(sched_fd, 128, 0) != self._runs.get(tid):
                    return True
            except (OSError, ValueError, IndexError):
                continue                                  # the thread ended meanwhile
        return False
