"""In lockstep the simulator's main thread reads the messages it waits for itself: the
controllers' commands and their lockstep reports.

Why: rospy reads each subscribed connection in a thread of its own, and a message it reads
then reaches the main thread through two hand-offs: the reader waits for the GIL, which the
main thread holds while it steps physics (Bullet's calls do not release it), so a report sent
while physics ran is read only once the main thread waits; the reader then wakes the main
thread through a condition. Measured on the demo: a report sent 0.2 ms before the main
thread began to wait for it was taken in 0.3 ms after the controller sent it, and the wait
was about a quarter of the main thread's time per scan (figures: docs/performance.md). Read
by the thread that waits for it, a report that has arrived is taken in at once.

How: rospy still makes each connection (its handshake, in its own thread, as always). Then,
for a topic of the inbox, the connection's thread hands the connection over and sleeps;
the main thread reads it whenever it looks for news (`poll`): in every wait for the
controllers, between two physics steps while it looks whether they are done, and once per
turn of its loop. A connection that ends (the publisher went away, a read failed) is given
back to its thread, whose rospy receive loop then ends it, or reconnects, as rospy does.
Messages are read, dropped by queue_size and handed to the subscriber's callbacks by
rospy's own code, in the same order; only the thread differs.
"""
import os
import select
import socket
import threading

_INBOX = None                # the process's inbox, once installed


class _Held:
    """A connection handed over by its thread."""
    __slots__ = ("transport", "callback", "fd", "given_back", "buffered")

    def __init__(self, transport, callback, fd):
        self.transport = transport
        self.callback = callback
        self.fd = fd
        # what rospy read with the connection header may hold the first message already
        self.buffered = transport.read_buff.tell() > 0
        self.given_back = threading.Event()
        self.given_back._cond._lockstep_untracked = True     # (a park, not work handed on)


class Inbox:
    def __init__(self, topics=(), warn=lambda text: None):
        """`topics`: resolved names of the subscribed topics the main thread reads (more
        with add()); `warn(text)`: told of a callback that raised."""
        self.topics = set(topics)
        self.warn = warn
        self.parked = set()          # native ids of the threads whose connection is held
        self._held = {}              # fd -> _Held
        self._lock = threading.Lock()
        self._poller = select.epoll()
        self._wake_read, self._wake_write = os.pipe2(os.O_NONBLOCK | os.O_CLOEXEC)
        self._poller.register(self._wake_read, select.EPOLLIN)
        self._reader = threading.get_ident()     # the thread that reads: the one making it
        self._buffered = False       # a held connection came with a message read already
        self._closed = False

    def add(self, topic):
        """From now on the main thread reads `topic` (a resolved name) too: call before
        subscribing to it."""
        self.topics.add(topic)

    # --- rospy's connection threads --------------------------------------------------------
    def wants(self, transport):
        protocol = getattr(transport, "protocol", None)
        return not self._closed and transport.socket is not None and \
            getattr(protocol, "resolved_name", None) in self.topics and \
            type(protocol).__name__ == "TCPROSSub"

    def hold(self, transport, callback):
        """Called in the connection's thread instead of rospy's receive loop: hands the
        connection to the main thread and sleeps until it is given back (it ended, or the
        inbox closed). `callback(msgs, transport)` is the subscriber's receive callback."""
        held = _Held(transport, callback, transport.socket.fileno())
        tid = threading.get_native_id()
        with self._lock:
            if self._closed:
                return
            self._held[held.fd] = held
            self._buffered = self._buffered or held.buffered
            self.parked.add(tid)
            try:
                self._poller.register(held.fd, select.EPOLLIN | select.EPOLLRDHUP)
            except FileExistsError:     # its number was a closed connection's, still listed
                self._poller.modify(held.fd, select.EPOLLIN | select.EPOLLRDHUP)
        self.wake()
        try:
            # rospy may close the connection from another thread (a second connection to
            # the same publisher): look now and then, so that the thread ends with it
            while not held.given_back.wait(0.5):
                if transport.done or transport.socket is None:
                    self._give_back(held)
        finally:
            self.parked.discard(tid)

    # --- the main thread -------------------------------------------------------------------
    def poll(self, timeout=0.0):
        """Reads every held connection that has something, and hands the messages to their
        callbacks; waits up to `timeout` [s] for something to come (a message, or wake()).
        True when anything came. Only the thread that made the inbox reads; for any other
        it does nothing."""
        if threading.get_ident() != self._reader:
            return False
        try:
            events = self._poller.poll(timeout)
        except (OSError, ValueError):          # closed meanwhile (shutdown)
            return False
        for fd, _ in events:
            if fd == self._wake_read:
                try:
                    while os.read(self._wake_read, 512):
                        pass
                except (BlockingIOError, OSError):
                    pass
                continue
            held = self._held.get(fd)
            if held is not None:
                self._read(held)
        if self._buffered:
            self._buffered = False
            for held in [h for h in list(self._held.values()) if h.buffered]:
                held.buffered = False
                self._read(held)
                events = True
        return bool(events)

    def wake(self):
        """Ends a poll that waits now (something came by another way: a report from a
        connection not held yet, a service answer); free when called by the polling thread."""
        if self._reader != threading.get_ident():
            try:
                os.write(self._wake_write, b"x")
            except (BlockingIOError, OSError):
                pass                              # a wake-up is pending already

    def close(self):
        """Gives every connection back to its thread (at shutdown: rospy's receive loop
        then ends them)."""
        with self._lock:
            self._closed = True
            held = list(self._held.values())
        for h in held:
            self._give_back(h)
        self._poller.close()
        os.close(self._wake_read)
        os.close(self._wake_write)

    def _read(self, held):
        transport = held.transport
        sock = transport.socket
        if transport.done or sock is None or sock.fileno() != held.fd:
            self._give_back(held)
            return
        protocol = transport.protocol
        buffer = transport.read_buff
        try:
            while True:
                try:
                    data = sock.recv(protocol.buff_size, socket.MSG_DONTWAIT)
                except BlockingIOError:
                    break
                if not data:                      # the publisher closed: rospy ends it
                    self._give_back(held)
                    break
                buffer.write(data)
                transport.stat_bytes += len(data)
                if len(data) < protocol.buff_size:
                    break
            msgs = []
            if buffer.tell() >= 4:
                protocol.read_messages(buffer, msgs, sock)
        except Exception:         # noqa: BLE001 (rospy's receive loop handles it, as always)
            self._give_back(held)
            return
        if msgs:
            transport.stat_num_msg += len(msgs)
            for msg in msgs:
                msg._connection_header = transport.header
            try:
                held.callback(msgs, transport)
            except Exception as error:    # noqa: BLE001 (the simulator keeps running)
                self.warn("a callback of %s failed: %r" % (transport.protocol.resolved_name,
                                                            error))

    def _give_back(self, held):
        with self._lock:
            if self._held.get(held.fd) is held:
                del self._held[held.fd]
                try:
                    self._poller.unregister(held.fd)
                except (OSError, ValueError):
                    pass                          # closed already: epoll dropped it
        held.given_back.set()


def install(inbox):
    """Makes rospy's subscriber connections of `inbox.topics` in this process hand
    themselves to `inbox` once connected. Once per process."""
    global _INBOX
    from rospy.impl import tcpros_base
    if _INBOX is None:
        receive_loop = tcpros_base.TCPROSTransport.receive_loop

        def receive_loop_or_hold(self, msgs_callback):
            inbox = _INBOX
            if inbox is not None and inbox.wants(self):
                inbox.hold(self, msgs_callback)
            return receive_loop(self, msgs_callback)
        tcpros_base.TCPROSTransport.receive_loop = receive_loop_or_hold
    _INBOX = inbox
    return inbox
