"""The simulator's own side of lockstep's barrier: whether its threads that read from other
nodes are still at work on something they were sent (see idle_threads.py).

A controller that is idle has written its command (or a service request, such as bug2's
set_model_state) to the simulator; the bytes are then in a socket of the simulator's, or a
rospy thread of the simulator is reading or handling them. Those threads are rospy's topic
receivers (one per subscribed connection), service connection handlers, and the TCPROS
server that accepts new connections. Each is idle only when it sleeps inside a socket wait
(recv, poll, accept ...): asleep anywhere else it may be waiting for the GIL or for the
world's lock with a message in hand.

The threads are found by what rospy runs in them (`threading.Thread._target`); the list is
made again whenever the set of threads changes (the batch runner's next controller: its
reader thread replaces the last one's, and their number stays the same).
"""
import os
import threading

from rospy.impl.tcpros_base import TCPServer
from rospy.impl.tcpros_pubsub import robust_connect_subscriber
from rospy.impl.tcpros_service import ServiceImpl

from pybullet_gazebo.ros.idle_threads import SOCKET_WAITS, in_socket_wait, state_of

def _is_reader(thread):
    target = getattr(thread, "_target", None)
    if target is robust_connect_subscriber:
        return True
    owner = getattr(target, "__self__", None)
    return isinstance(owner, (ServiceImpl, TCPServer))


class OwnReceivers:
    def __init__(self):
        self._threads = ()
        self._files = {}            # reader tid -> (fd of its stat, fd of its syscall)

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
                    self._files[tid] = (stat, os.open(base + "syscall", os.O_RDONLY))
                except OSError:
                    os.close(stat)

    def busy(self):
        """True while a reader thread is not asleep in a socket wait."""
        self.tids()
        for stat_fd, syscall_fd in self._files.values():
            try:
                if state_of(os.pread(stat_fd, 512, 0)) != ord("S"):
                    return True
                syscall = os.pread(syscall_fd, 256, 0)
            except (OSError, ValueError, IndexError):
                continue                                  # the thread ended meanwhile
            if SOCKET_WAITS and not in_socket_wait(syscall):
                return True
        return False
