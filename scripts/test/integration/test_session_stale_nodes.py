"""A node the session stops is forgotten by the master, so a later node of the same name
cannot have the master shut down whatever process took the old node's port (a real master
and rospy nodes; stale_nodes.py tells the story)."""
import os
import sys
import textwrap
import xmlrpc.client

from m2wr_tools.running.session import Session
from pybullet_gazebo.ros.testing import wait_until

NODE = "/stale_probe"
# a rospy node that logs once (rospy then subscribes /rosout_disable_topics_generation, the
# subscription no node takes back) and spins until stopped
PROGRAM = textwrap.dedent("""
    import rospy
    rospy.init_node("stale_probe")
    rospy.loginfo("up")
    from std_msgs.msg import String
    rospy.Publisher("/stale_probe_topic", String, queue_size=1)
    rospy.spin()
""")


def lookup(session, node):
    with session.master() as master:
        code, _, uri = master.lookupNode("/test", node)
    return uri if code == 1 else None


def start_probe(session, tmp_path):
    script = tmp_path / "stale_probe.py"
    script.write_text(PROGRAM)
    session.start_controller([sys.executable, str(script)], log_name="stale_probe")
    wait_until(lambda: lookup(session, NODE) is not None and cached_param_subscribed(session),
               30, "the probe node's registration and its cached parameter", interval=0.1)
    return lookup(session, NODE)


def cached_param_subscribed(session):
    """rospy subscribes the parameter a moment after it registers; the master log says when."""
    log = os.path.join(session.log_dir, "ros", "master.log")
    if not os.path.exists(log):
        return False
    with open(log) as text:
        return "CACHEDPARAM [/rosout_disable_topics_generation] by %s" % NODE in text.read()


def test_a_stopped_node_is_forgotten_by_the_master(tmp_path):
    session = Session(str(tmp_path / "logs"), name="test_stale_nodes")
    try:
        session.start_master()
        uri = start_probe(session, tmp_path)
        assert uri is not None
        session.stop(["controller"])
        # rospy took back its topics as it shut down, but not its parameter subscription:
        # without the session's clean-up the master still lists the node at its old address
        assert lookup(session, NODE) is None
        # and a new node of that name registers without a shutdown sent anywhere
        assert start_probe(session, tmp_path) is not None
        session.stop(["controller"])
        assert lookup(session, NODE) is None
    finally:
        session.stop()
    assert session.master_uri is not None
    try:
        with xmlrpc.client.ServerProxy(session.master_uri) as master:
            master.getPid("/test")
        stopped = False
    except OSError:
        stopped = True
    assert stopped, "the master outlived the session"


def test_spawn_launchs_node_is_forgotten_once_m2wr_is_in(tmp_path):
    """spawn.launch's node ends by itself once m2wr is spawned, keeping rospy's parameter
    subscription: the next spawn (the batch runner relaunches the world for a new seed) would
    have the master shut down whatever took its port, the new simulator among others."""
    session = Session(str(tmp_path / "logs"), name="test_stale_nodes")
    try:
        session.start_master()
        session.launch_world("world02", paused=True)
        session.wait_for_simulator()
        session.spawn(0.0, 8.0, 0.0)
        log = os.path.join(session.log_dir, "ros", "master.log")
        with open(log) as text:
            assert "CACHEDPARAM [/rosout_disable_topics_generation] by /spawn_m2wr" in text.read()
        assert lookup(session, "/spawn_m2wr") is None
        assert lookup(session, "/gazebo") is not None        # the live one stays
    finally:
        session.stop()
