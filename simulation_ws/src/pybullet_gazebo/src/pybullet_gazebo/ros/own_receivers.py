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

from pybullet_gazebo.ros.idle_threads import SOCKET_WAITS

def _is_reader(thread):
    target = getattr(thread, "_target", None)
    if target is robust_connect_subscriber:
        return True
    owner = getattr(target, "__self__", None)
    return isinstance(owner, (ServiceImpl, TCPServer))


class OwnReceivers:
    def __init__(self):
        self._threads = ()
        self._tids = []

    def tids(self):
        """The native ids of the reader threads now."""
        threads = threading.enumerate()
        if len(threads) != len(self._threads) or \
                any(a is not b for a, b in zip(threads, self._threads)):
            self._threads = tuple(threads)
            self._tids = [t.native_id for t in threads if t.native_id and _is_reader(t)]
        return self._tids

    def busy(self):
        """True while a reader thread is not asleep in a socket wait."""
        for tid in self.tids():
            base = "/proc/self/task/%d/" % tid
            try:
                with open(base + "stat", "rb") as f:
                    stat = f.read()
                if stat[stat.rindex(b")") + 2] != ord("S"):
                    return True
                with open(base + "syscall", "rb") as f:
                    call = f.read().split(None, 1)[0]
            except (OSError, ValueError, IndexError):
                continue                                  # the thread ended meanwhile
            if SOCKET_WAITS and (not call.lstrip(b"-").isdigit()
                                  or int(call) not in SOCKET_WAITS):
                return True
        return False
