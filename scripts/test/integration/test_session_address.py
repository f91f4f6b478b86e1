"""A session's ROS graph on the loopback address ROS_HOSTNAME names: the master and every node
listen there only, so a master of a graph on another address (scripts/test.sh runs its
streams side by side, each on its own) cannot reach them, whatever port it calls. Without
that, a master calling a killed node's old address (a publisherUpdate, a shutdown) may reach
the node of another graph that the kernel gave the same port, and that node connects to the
wrong graph's publishers (a real master and a rospy node)."""
import socket
import sys
import textwrap
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
