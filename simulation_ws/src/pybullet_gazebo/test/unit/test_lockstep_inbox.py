"""Lockstep's inbox (ros/lockstep/inbox.py) on rospy's own connection classes, without a
master: a connection's thread hands its connection over, and the thread that polls reads the
messages and runs the callbacks, in order, whole; a connection that ends goes back to its
thread."""
import io
import socket
import threading
import time

import pytest
from rospy.impl.tcpros_base import TCPROSTransport
from rospy.impl.tcpros_pubsub import TCPROSSub
from rospy.msg import serialize_message
from std_msgs.msg import String

from pybullet_gazebo.ros.lockstep.inbox import Inbox

TOPIC = "/chatter"


def wire(text, seq=0):
    """A String message as it travels on a TCPROS connection (length first)."""
    buffer = io.BytesIO()
    serialize_message(buffer, seq, String(text))
    return buffer.getvalue()


class Connection:
    """A subscriber's connection as rospy makes it, its publisher's end a socket pair's
    other end, and the thread that would run rospy's receive loop holding it in the inbox."""

    def __init__(self, inbox, topic=TOPIC, already_read=b""):
        self.ours, self.theirs = socket.socketpair()
        self.transport = TCPROSTransport(TCPROSSub(topic, String, queue_size=None), topic)
        self.transport.socket = self.ours
        self.transport.header = {"callerid": "/talker"}
        self.transport.read_buff.write(already_read)
        self.got = []                          # (thread ident, [texts], callerid)
        self.thread = threading.Thread(target=inbox.hold, args=(self.transport, self.callback))
        self.thread.start()
        deadline = time.monotonic() + 5.0
        while self.thread.native_id not in inbox.parked:
            assert time.monotonic() < deadline, "the connection's thread never handed it over"
            time.sleep(0.001)

    def callback(self, msgs, transport):
        self.got.append((threading.get_ident(), [m.data for m in msgs],
                         msgs[0]._connection_header["callerid"]))

    def texts(self):
        return [text for _, texts, _ in self.got for text in texts]

    def close(self):
        for sock in (self.ours, self.theirs):
            sock.close()
        self.thread.join(5.0)


@pytest.fixture
def inbox():
    made = Inbox([TOPIC])
    connections = []

    def connect(**kwds):
        connection = Connection(made, **kwds)
        connections.append(connection)
        return connection
    made.connect = connect
    yield made
    made.close()
    for connection in connections:
        connection.close()
        assert not connection.thread.is_alive()


def poll_until(inbox, connection, count):
    deadline = time.monotonic() + 5.0
    while len(connection.texts()) < count and time.monotonic() < deadline:
        inbox.poll(0.1)
    return connection.texts()


def test_the_polling_thread_reads_the_messages_and_runs_the_callbacks_in_order(inbox):
    connection = inbox.connect()
    connection.theirs.sendall(b"".join(wire("m%d" % n, n) for n in range(3)))
    assert poll_until(inbox, connection, 3) == ["m0", "m1", "m2"]
    assert {ident for ident, _, _ in connection.got} == {threading.get_ident()}
    assert {callerid for _, _, callerid in connection.got} == {"/talker"}
    assert connection.thread.is_alive()          # its own thread still leaves it alone


def test_a_message_arriving_in_pieces_is_handed_on_whole(inbox):
    connection = inbox.connect()
    data = wire("a longer message " * 20)
    connection.theirs.sendall(data[:7])
    inbox.poll(0.2)
    assert connection.texts() == []
    connection.theirs.sendall(data[7:])
    assert poll_until(inbox, connection, 1) == ["a longer message " * 20]


def test_a_message_read_with_the_connection_header_is_not_left_behind(inbox):
    connection = inbox.connect(already_read=wire("first"))
    assert poll_until(inbox, connection, 1) == ["first"]


def test_a_connection_whose_publisher_closed_goes_back_to_its_thread(inbox):
    connection = inbox.connect()
    connection.theirs.sendall(wire("last words"))
    connection.theirs.close()
    assert poll_until(inbox, connection, 1) == ["last words"]
    inbox.poll(0.2)
    connection.thread.join(5.0)
    assert not connection.thread.is_alive() and not inbox.parked


def test_another_topic_is_not_held():
    inbox = Inbox([TOPIC])
    try:
        other = TCPROSTransport(TCPROSSub("/other", String, queue_size=None), "/other")
        other.socket = object()
        assert not inbox.wants(other)
        ours = TCPROSTransport(TCPROSSub(TOPIC, String, queue_size=None), TOPIC)
        ours.socket = object()
        assert inbox.wants(ours)
    finally:
        inbox.close()


def test_only_the_thread_that_made_it_reads(inbox):
    connection = inbox.connect()
    connection.theirs.sendall(wire("for the main thread"))
    time.sleep(0.05)
    elsewhere = threading.Thread(target=inbox.poll)
    elsewhere.start()
    elsewhere.join()
    assert connection.texts() == []
    assert poll_until(inbox, connection, 1) == ["for the main thread"]


def test_a_wake_ends_a_waiting_poll(inbox):
    waker = threading.Timer(0.05, inbox.wake)
    waker.start()
    start = time.monotonic()
    assert inbox.poll(30.0) is True                 # woken, not timed out
    assert time.monotonic() - start < 10.0
    waker.join()


def test_close_gives_every_connection_back():
    inbox = Inbox([TOPIC])
    connection = Connection(inbox)
    inbox.close()
    connection.thread.join(5.0)
    assert not connection.thread.is_alive()
    connection.close()
