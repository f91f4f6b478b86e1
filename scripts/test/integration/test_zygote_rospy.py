"""A rospy program forked from the batch runner's zygote, on a real master: the zygote says
when it enters rospy.spin() (its subscriptions are made by then), and SIGINT ends it the way
rospy ends it: its shutdown hooks run, the code after spin() runs, exit status 0. (How soon:
the batch benchmark's stop stage; timed tests are not this suite's way.)"""
import os
import signal

import pytest

from m2wr_tools.running import processes, zygote
from pybullet_gazebo.ros.testing import wait_until

PROGRAM = """#!/usr/bin/env python3
import rospy
from std_msgs.msg import String
rospy.init_node("warm_test")
rospy.on_shutdown(lambda: print("shutdown hook ran", flush=True))
rospy.Subscriber("/chatter", String, lambda msg: None)
print("spinning", flush=True)
rospy.spin()
print("after spin", flush=True)
"""


@pytest.fixture
def master(tmp_path):
    port = processes.free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port,
               ROS_HOSTNAME="localhost", ROS_LOG_DIR=str(tmp_path / "ros"))
    child = processes.Child("master", ["rosmaster", "--core", "-p", str(port)], env,
                            str(tmp_path / "master.log"))
    wait_until(lambda: processes.port_in_use(port), 20.0, "rosmaster on port %d" % port,
               interval=0.1)
    yield env
    processes.stop([child], sigint_timeout=5.0)


def test_a_warm_rospy_program_says_when_it_spins_and_stops_at_once_on_sigint(master, tmp_path):
    script = tmp_path / "program.py"
    script.write_text(PROGRAM)
    script.chmod(0o755)
    z = zygote.Zygote(master, str(tmp_path / "zygote.log"))
    try:
        log = str(tmp_path / "program.log")
        child = z.start("controller", [str(script)], master, log)
        assert child.spinning(timeout=30.0), processes.log_tail(log)
        assert "spinning" in processes.log_tail(log)
        child.signal_group(signal.SIGINT)
        assert child.wait(10.0) == 0
        text = processes.log_tail(log)
        assert "shutdown hook ran" in text and "after spin" in text, text
        assert not child.spinning()
    finally:
        z.close()


def test_a_warm_program_takes_its_own_remappings_name_and_namespace(master, tmp_path):
    """rospy reads them as it is imported (in the zygote): `rosrun PKG SCRIPT __name:=...
    chatter:=...` and ROS_NAMESPACE must still reach the program, as in a fresh interpreter."""
    script = tmp_path / "program.py"
    script.write_text(PROGRAM.replace('rospy.Subscriber("/chatter"', 'rospy.Subscriber("chatter"'))
    script.chmod(0o755)
    z = zygote.Zygote(master, str(tmp_path / "zygote.log"))
    try:
        log = str(tmp_path / "program.log")
        env = dict(master, ROS_NAMESPACE="/team")
        child = z.start("controller", [str(script), "__name:=renamed", "chatter:=heard"], env,
                        log)
        assert child.spinning(timeout=30.0), processes.log_tail(log)
        import xmlrpc.client
        with xmlrpc.client.ServerProxy(master["ROS_MASTER_URI"]) as proxy:
            state = proxy.getSystemState("/t")[2]
        assert ["/team/heard", ["/team/renamed"]] in state[1], state
        child.signal_group(signal.SIGINT)
        assert child.wait(10.0) == 0
    finally:
        z.close()
