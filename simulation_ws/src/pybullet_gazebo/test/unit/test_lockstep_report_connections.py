"""The report publisher's connections: one whose simulator has gone is dropped before a report
is sent, so that report waits for the next simulator instead of going into a dead socket
(rospy would keep that connection until a write to it failed, and the first write after the
peer closed does not fail). Real sockets; the publisher around them is a stand-in for rospy's,
with what rospy_hooks uses of it."""
import socket

from pybullet_gazebo.ros.lockstep import rospy_hooks


class Connection:
    def __init__(self, sock):
        self.socket, self.closed = sock, False

    def close(self):
        self.closed = True
        self.socket.close()


class Publisher:
    def __init__(self, connections):
        self.impl = self
        self.connections = list(connections)

    def remove_connection(self, connection):
        self.connections.remove(connection)

    def get_num_connections(self):
        return len(self.connections)


def test_a_connection_whose_simulator_has_gone_is_dropped_and_no_report_is_due(monkeypatch):
    ours, simulators = socket.socketpair()
    ours.sendall(b"report")                 # written before the simulator went: no failure
    connection = Connection(ours)
    monkeypatch.setattr(rospy_hooks, "_publisher", Publisher([connection]))
    assert rospy_hooks._reporting()        # the simulator listens
    simulators.close()
    assert not rospy_hooks._reporting()    # gone: nothing is sent until the next connects
    assert connection.closed and rospy_hooks._publisher.connections == []


def test_a_live_connection_is_kept_whatever_is_waiting_to_be_read(monkeypatch):
    ours, simulators = socket.socketpair()
    connection = Connection(ours)
    monkeypatch.setattr(rospy_hooks, "_publisher", Publisher([connection]))
    simulators.sendall(b"x")               # unexpected bytes from a live peer are not an end
    assert rospy_hooks._reporting() and rospy_hooks._reporting()
    assert not connection.closed
    ours.close()
    simulators.close()


def test_no_publisher_no_report(monkeypatch):
    monkeypatch.setattr(rospy_hooks, "_publisher", None)
    assert not rospy_hooks._reporting()


def test_a_connection_asked_for_its_port_before_it_connects_is_named_by_its_port_once_it_has():
    """rospy lists a subscriber's connection before it connects; lockstep may look at it
    then (the simulator asks for its connections at every wait). Its port, 0 then, must not
    stick: the controller's reports name the connection by its real port, and a command on
    a connection named 0 would never be waited for."""
    connection = Connection(None)
    assert rospy_hooks._local_port(connection) == 0
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    client = socket.create_connection(listener.getsockname())
    server, _ = listener.accept()
    try:
        connection.socket = client
        assert rospy_hooks._local_port(connection) == client.getsockname()[1]
        served = Connection(server)
        assert rospy_hooks._peer_port(served) == client.getsockname()[1]
    finally:
        for sock in (client, server, listener):
            sock.close()
