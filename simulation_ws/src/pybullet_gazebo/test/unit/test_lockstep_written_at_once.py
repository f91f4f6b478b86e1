"""A controller's queued publish while a simulator listens in lockstep (rospy_hooks.py): the
message is written by the publishing thread, so it is out when publish() returns; a
subscriber that does not keep up, /rosout, or a process no simulator listens to, keep rospy's
queue and its thread. On rospy's own transport classes over a socket pair, without a master."""
import socket
import threading

import pytest
from rospy.impl.tcpros_base import TCPROSTransport
from rospy.impl.tcpros_pubsub import QueuedConnection, TCPROSPub
from geometry_msgs.msg import Twist

from pybullet_gazebo.ros.lockstep import rospy_hooks


@pytest.fixture
def listening():
    """The hooks installed, and a simulator taken to listen. (The tracker's own look, which
    would find none, is kept out meanwhile: rospy threads left by other tests in this
    process may ask it; it says "not reporting", so that no poller of theirs is held.)"""
    tracker = rospy_hooks.TRACKER or rospy_hooks.install(report=False)
    before = tracker.reporting, rospy_hooks._listening
    tracker.reporting = lambda: False
    rospy_hooks._listening = True
    yield tracker
    tracker.reporting, rospy_hooks._listening = before


class RecordingSocket:
    """A socket that notes which thread writes to it."""

    def __init__(self, sock):
        self.sock = sock
        self.writers = []

    def sendall(self, data):
        self.writers.append(threading.get_ident())
        return self.sock.sendall(data)

    def __getattr__(self, name):
        return getattr(self.sock, name)


def tcp_pair():
    """A TCP connection on localhost with small buffers (Linux grows large ones as they fill,
    so that a socket filled once has room again later)."""
    with socket.socket() as server:
        server.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        client = socket.socket()
        client.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
        client.connect(server.getsockname())
        accepted, _ = server.accept()
    return client, accepted


@pytest.fixture
def queued():
    """connect(topic) -> (a QueuedConnection as rospy makes it for queue_size=1, its socket,
    the subscriber's end of it)."""
    made = []

    def connect(topic="/cmd_vel"):
        ours, theirs = tcp_pair()
        transport = TCPROSTransport(TCPROSPub(topic, Twist), topic)
        transport.socket = RecordingSocket(ours)
        made.append((transport, theirs))
        return QueuedConnection(transport, 1), transport.socket, theirs
    yield connect
    for transport, theirs in made:
        transport.close()                  # ends the queue's thread
        theirs.close()


def arrived(sock):
    try:
        return sock.recv(65536, socket.MSG_DONTWAIT)
    except BlockingIOError:
        return b""


def received(sock, expected):
    sock.settimeout(5.0)
    data = b""
    while len(data) < len(expected):
        data += sock.recv(65536)
    return data


def test_written_by_the_publishing_thread_while_a_simulator_listens(listening, queued):
    connection, ours, subscriber = queued()
    connection.write_data(b"command")
    assert arrived(subscriber) == b"command"            # out when the write returned
    assert ours.writers == [threading.get_ident()]
    assert not listening.pending_writes()


def test_a_full_socket_leaves_the_message_to_the_queue_without_blocking(listening, queued):
    connection, ours, subscriber = queued()
    ours.setblocking(False)
    for size in (65536, 4096, 256, 1):              # full to the last byte
        try:
            while True:
                ours.send(b"x" * size)
        except BlockingIOError:
            pass
    ours.setblocking(True)
    writer = threading.Thread(target=connection.write_data, args=(b"command",))
    writer.start()
    writer.join(5.0)
    assert not writer.is_alive()                    # queued, not stuck in a write
    subscriber.settimeout(5.0)
    while not ours.writers:                         # the queue's thread writes it once
        subscriber.recv(1 << 20)                    # there is room
    assert ours.writers[0] not in (writer.ident, threading.get_ident())


@pytest.mark.parametrize("topic, simulator", [("/rosout", True), ("/cmd_vel", False)])
def test_rosout_and_a_process_without_simulator_keep_the_queue(listening, queued, topic,
                                                                simulator):
    import pybullet_gazebo.ros.lockstep.rospy_hooks as hooks
    hooks._listening = simulator
    connection, ours, subscriber = queued(topic)
    connection.write_data(b"message")
    assert received(subscriber, b"message") == b"message"
    assert ours.writers and ours.writers[0] != threading.get_ident()     # the queue's thread


def test_a_subscriber_gone_mid_write_ends_the_connection_without_hanging(listening, queued):
    """The subscriber's end closed (a `rostopic echo` stopped with Ctrl-C, a simulator killed):
    rospy's transport closes itself on the broken pipe and calls the queue's clean-up, which
    takes the queue's lock. The publishing thread, writing under that lock, must not wait for
    itself: the publish ends as rospy's does (TransportTerminated, which rospy's publish
    drops), and the program goes on."""
    from rospy.exceptions import TransportTerminated
    connection, ours, subscriber = queued()
    subscriber.close()
    ended = []

    def publish_until_it_fails():
        for _ in range(100):
            try:
                connection.write_data(b"command")
            except TransportTerminated as error:
                ended.append(error)
                return
            except OSError as error:            # (a reset before the pipe breaks)
                ended.append(error)
    writer = threading.Thread(target=publish_until_it_fails, daemon=True)
    writer.start()
    writer.join(5.0)
    assert not writer.is_alive(), "the publishing thread waits for its own lock"
    assert any(isinstance(e, TransportTerminated) for e in ended), ended
    assert connection._connection.done
