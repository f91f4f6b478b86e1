"""A session's ROS graph on the loopback address ROS_HOSTNAME names: the master and every node
listen there only, so a master of a graph on another address (scripts/test.sh runs its
streams side by side, each on its own) cannot reach them, whatever port it calls. Without
that, a master calling a killed node's old address (a publisherUpdate) reaches the node of
another graph that the kernel gave the same port, and that node connects to the wrong graph's
publishers (real masters and rospy nodes)."""
import signal
import socket
import sys
import textwrap
import time
from urllib.parse import urlparse

import pytest

from m2wr_tools.running.session import Session, loopback_host
from pybullet_gazebo.ros.testing import wait_until

PROGRAM = textwrap.dedent("""
    import rospy
    from std_msgs.msg import String
    rospy.init_node("address_probe")
    rospy.Subscriber("/odom_like", String, lambda _msg: None)
    rospy.spin()
""")


# a node of either role on /odom_like, at a given XML-RPC port (0: any); a listener prints the
# messages it heard after `seconds`
CROSS_TALK_NODE = textwrap.dedent("""
    import sys, time
    import rospy
    from std_msgs.msg import String
    role, name, port, seconds = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    rospy.init_node(name, xmlrpc_port=port)
    heard = set()
    if role == "listen":
        rospy.Subscriber("/odom_like", String, lambda msg: heard.add(msg.data))
    else:
        publisher = rospy.Publisher("/odom_like", String, queue_size=10)
    end = time.monotonic() + seconds
    while time.monotonic() < end and not rospy.is_shutdown():
        if role == "talk":
            publisher.publish(String(data=sys.argv[5]))
        time.sleep(0.1)
    print("heard", sorted(heard), flush=True)
""")


def listening(host, port):
    with socket.socket() as sock:
        sock.settimeout(1.0)
        return sock.connect_ex((host, port)) == 0


@pytest.mark.parametrize("named, used", [("127.0.0.5", "127.0.0.5"), ("localhost", "localhost"),
                                         ("my-laptop", "localhost"), ("0.0.0.0", "localhost"),
                                         ("", "localhost")])
def test_only_a_loopback_address_is_taken_from_ros_hostname(monkeypatch, named, used):
    monkeypatch.setenv("ROS_HOSTNAME", named)
    assert loopback_host() == used


def test_the_master_and_its_nodes_listen_on_the_sessions_address_only(tmp_path, monkeypatch):
    monkeypatch.setenv("ROS_HOSTNAME", "127.0.0.5")
    session = Session(str(tmp_path / "logs"), name="address_test")
    try:
        uri = session.start_master()
        master = urlparse(uri)
        assert master.hostname == "127.0.0.5"
        assert listening("127.0.0.5", master.port) and not listening("127.0.0.1", master.port)
        script = tmp_path / "address_probe.py"
        script.write_text(PROGRAM)
        session.start_controller([sys.executable, str(script)], log_name="address_probe")
        wait_until(lambda: session.node_uri("/address_probe") is not None, 30,
                   "the probe node's registration", interval=0.1)
        node = urlparse(session.node_uri("/address_probe"))
        assert node.hostname == "127.0.0.5"
        assert listening("127.0.0.5", node.port) and not listening("127.0.0.1", node.port)
    finally:
        session.stop()


@pytest.mark.parametrize("address_b, cross_talk", [("localhost", True), ("127.0.0.6", False)])
def test_a_killed_nodes_port_taken_by_another_graph_hears_nothing_of_the_first(
        tmp_path, monkeypatch, address_b, cross_talk):
    """Graph A's listener is killed (SIGKILL: no unregistering); a listener of graph B is given
    its port; a talker then starts in graph A, whose master tells the listeners it knows. On
    one address graph B's listener hears graph A (the control: the hazard is real); on
    addresses of their own it hears its own graph only."""
    script = tmp_path / "cross_talk_node.py"
    script.write_text(CROSS_TALK_NODE)
    monkeypatch.setenv("LOCKSTEP_HANDSHAKE", "off")
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    graph_a = Session(str(tmp_path / "a"), name="graph_a")
    monkeypatch.setenv("ROS_HOSTNAME", address_b)
    graph_b = Session(str(tmp_path / "b"), name="graph_b")
    try:
        graph_b.start_master()
        monkeypatch.setenv("ROS_HOSTNAME", "localhost")
        graph_a.start_master()
        with socket.socket() as probe:          # a port free on every loopback address
            probe.bind(("0.0.0.0", 0))
            port = probe.getsockname()[1]

        def node(session, name, *args):           # a child of the session, stopped with it
            return session._start(name, [sys.executable, str(script), *map(str, args)])
        dead = node(graph_a, "dead", "listen", "dead_listener", port, 60)
        wait_until(lambda: graph_a.node_uri("/dead_listener") is not None, 30,
                   "graph A's listener", interval=0.1)
        time.sleep(0.5)                          # (its subscription registered with it)
        dead.signal_group(signal.SIGKILL)
        dead.wait(10)
        listener = node(graph_b, "listener", "listen", "listener", port, 6)
        node(graph_b, "talker_b", "talk", "talker_b", 0, 7, "from graph B")
        wait_until(lambda: graph_b.node_uri("/listener") is not None, 30,
                   "graph B's listener", interval=0.1)
        node(graph_a, "talker_a", "talk", "talker_a", 0, 4, "from graph A")
        listener.wait(30)
        heard = listener.log_tail(1)
        assert "from graph B" in heard, heard
        assert ("from graph A" in heard) == cross_talk, heard
    finally:
        try:
            graph_a.stop()
        finally:
            graph_b.stop()
