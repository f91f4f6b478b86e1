"""A publisher that writes in the caller's thread, for the messages the loop sends every
few steps (/clock, the laser scan).

rospy's queued publisher (queue_size=N) hands each message to a writer thread per
subscriber and then calls time.sleep(0) to let that thread run: in the lockstep loop the
simulator's main thread then spends much of its wall time in that one line, the GIL going
back and forth after every publish. rospy's synchronous mode (queue_size=None) writes the
serialized message straight into each subscriber's socket, and the loop runs faster for it.

What synchronous writing costs: `sendall` waits when a subscriber's socket buffer is full,
so a subscriber that reads slower than the simulator publishes (or a stopped process)
would set the loop's pace, or stop it. So before each message every subscriber's socket is
asked (select, no wait) whether it can take more; a subscriber whose buffer is full misses
this message, as a full queue of queue_size=1 would drop it, and the others get it. The
kernel's buffers on localhost hold hundreds of scans, so a subscriber that keeps up never
misses one.

`publish(msg, share)`: `share(connection)` picks the subscribers that get this message
(clock_topic.py sends every /clock tick to controllers, fewer to displays). Whatever the
subset, the message is serialized once and the same bytes written to each socket.

Every subscriber's socket gets TCP_NODELAY, whatever the subscriber asked for: with Nagle's
algorithm a message written while the last one is not yet acknowledged waits in the kernel
for that ACK, which a receiver that sends nothing back delays; in lockstep the simulator then
waits for a message its controller has not got.
"""
import select
import socket
import warnings

import rospy
from rospy.msg import serialize_message


class DirectPublisher:
    def __init__(self, topic, data_class, latch=False):
        with warnings.catch_warnings():     # rospy warns when queue_size is None: on purpose
            warnings.simplefilter("ignore", SyntaxWarning)
            self.publisher = rospy.Publisher(topic, data_class, queue_size=None, latch=latch)
        self.skipped = 0                    # messages not sent to a subscriber that lagged
        self._no_delay = set()              # ids of the connections given TCP_NODELAY

    def get_num_connections(self):
        return self.publisher.get_num_connections()

    def subscriber_nodes(self):
        """The names of the nodes subscribed now."""
        impl = self.publisher.impl
        return {c.endpoint_id for c in list(impl.connections)} if impl is not None else set()

    def publish(self, msg, share=None):
        """Writes `msg` to every subscriber that can take it now, or, with `share`, to those
        of them for which share(connection) is true (rospy's TCPROS connection; its
        endpoint_id is the subscriber's node name)."""
        impl = self.publisher.impl
        if impl is None:
            return
        connections = list(impl.connections)
        if not connections:
            impl.publish(msg)             # keeps rospy's latch and sequence number
            return
        if len(self._no_delay) != len(connections):
            self._set_no_delay(connections)
        everyone = len(connections)
        if share is not None:
            connections = [c for c in connections if share(c)]
        sockets = [getattr(c, "socket", None) for c in connections]
        try:
            _, writable, _ = select.select([], [s for s in sockets if s is not None], [], 0)
        except (OSError, ValueError):     # a socket closed meanwhile: rospy will drop it
            writable = []
        if len(writable) == everyone:
            self.publisher.publish(msg)
            return
        ready = set(writable)
        chosen = [c for c, sock in zip(connections, sockets) if sock in ready]
        self.skipped += len(connections) - len(chosen)
        self._write(impl, msg, chosen)

    def _set_no_delay(self, connections):
        present = set()
        for connection in connections:
            present.add(id(connection))
            if id(connection) not in self._no_delay:
                try:
                    connection.socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                except (AttributeError, OSError):
                    pass                  # closing: rospy drops it
        self._no_delay = present

    @staticmethod
    def _write(impl, msg, connections):
        """What rospy's publish does for all its connections, for some of them: serialize
        once (next sequence number, latch kept), write, close the connections that failed."""
        failed = []
        impl.acquire()
        try:
            if impl.closed:
                return
            if impl.is_latch:
                impl.latch = msg
            if not connections:
                return
            buff = impl.buff
            impl.seq += 1
            serialize_message(buff, impl.seq, msg)
            data = buff.getvalue()
            buff.seek(0)
            buff.truncate(0)
            impl.message_data_sent += len(data)
            for connection in connections:
                try:
                    connection.write_data(data)
                except Exception:         # as rospy's publish: that connection is dropped
                    failed.append(connection)
        finally:
            impl.release()
        for connection in failed:
            connection.close()            # rospy drops it from the topic's connections

    def unregister(self):
        self.publisher.unregister()
