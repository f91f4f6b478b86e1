"""`roslaunch PKG FILE ARGS` started warm (m2wr_tools.running.warm_launch), on a real master:
the launch file is read as roslaunch reads it (arguments, parameters, a group's namespace, a
node's name and private parameters, <env>, remappings, args: rospy, imported in the zygote,
takes the node's own), its Python nodes are forks of the
launcher (no interpreter of theirs started), output="screen" is in the run's log and the
others' in the ROS log folder, a required node that ends stops the rest, and SIGINT to the
group ends every node the way rospy ends it."""
import contextlib
import os
import signal
import xmlrpc.client

import pytest

from m2wr_tools.running import processes, zygote
from pybullet_gazebo.ros.testing import wait_until

TALKER = """#!/usr/bin/env python3
import os, sys, rospy
from std_msgs.msg import String
rospy.init_node("named_in_its_code")   # the launch file names it
print("talker %s rate %s greeting %s who %s args %s" % (
    rospy.get_name(), rospy.get_param("~rate"), rospy.get_param("/greeting"),
    os.environ.get("WHO"), " ".join(sys.argv[1:3])), flush=True)
pub = rospy.Publisher("chatter", String, queue_size=1)
rate = rospy.Rate(20)
while not rospy.is_shutdown():
    pub.publish("hi")
    rate.sleep()
print("talker ends", flush=True)
"""

# (its line comes after its call to the master: rospy hangs for good when SIGINT comes while
# a thread of the node is in a master call, as its shutdown calls the master through the same
# locked proxy; roslaunch and warm_launch end such a node with SIGTERM after 15 s)
QUITTER = """#!/usr/bin/env python3
import time, rospy
rospy.init_node("named_in_its_code")
after = rospy.get_param("~after", None)
print("quitter in the log folder", flush=True)
if after is None:
    rospy.spin()
else:
    time.sleep(after)
"""

LAUNCH = """<launch>
  <arg name="greeting" default="hello"/>
  <arg name="quit" default="false"/>
  <param name="greeting" value="$(arg greeting)"/>
  <group ns="robot">
    <node pkg="wl_test" type="talker.py" name="talker" output="screen" args="--flag one">
      <param name="rate" value="20"/>
      <env name="WHO" value="the launch file"/>
      <remap from="chatter" to="/said"/>
    </node>
  </group>
  <node pkg="wl_test" type="quitter.py" name="quitter" required="$(arg quit)">
    <param name="after" value="1.0" if="$(arg quit)"/>
  </node>
</launch>
"""


@pytest.fixture
def launch_env(tmp_path):
    package = tmp_path / "pkgs" / "wl_test"
    (package / "launch").mkdir(parents=True)
    (package / "package.xml").write_text(
        '<package format="2"><name>wl_test</name><version>0.0.0</version><description>t'
        '</description><maintainer email="t@t.t">t</maintainer><license>MIT</license>'
        '</package>')
    for name, text in (("talker.py", TALKER), ("quitter.py", QUITTER)):
        (package / name).write_text(text)
        (package / name).chmod(0o755)
    (package / "launch" / "two.launch").write_text(LAUNCH)
    port = processes.free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port,
               ROS_HOSTNAME="localhost", ROS_LOG_DIR=str(tmp_path / "ros"),
               ROS_HOME=str(tmp_path / "home"),
               ROS_PACKAGE_PATH="%s:%s" % (tmp_path / "pkgs", os.environ["ROS_PACKAGE_PATH"]))
    master = processes.Child("master", ["rosmaster", "--core", "-p", str(port)], env,
                             str(tmp_path / "master.log"))
    wait_until(lambda: processes.port_in_use(port), 20.0, "rosmaster on port %d" % port,
               interval=0.1)
    warm = zygote.Zygote(env, str(tmp_path / "zygote.log"))
    yield warm, env, tmp_path
    warm.close()
    processes.stop([master], sigint_timeout=5.0)


def _publishers(env, topic):
    with xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"]) as master:
        _, _, (publishers, _, _) = master.getSystemState("/test")
    return [nodes for name, nodes in publishers if name == topic]


@contextlib.contextmanager
def _launched(launch_env, *argv):
    """(the launcher, its log) running `roslaunch ARGV` warm; every process of its group
    ends with the test."""
    warm, env, tmp_path = launch_env
    log = str(tmp_path / "run.log")
    child = warm.start("controller", ["roslaunch", *argv], env, log, launch=True)
    try:
        yield child, log
    finally:
        if child.running():
            child.signal_group(signal.SIGKILL)
        child.close()


def _read(path, mode="r"):
    with open(path, mode) as source:
        return source.read()


def test_a_launch_file_runs_warm_as_roslaunch_would_run_it(launch_env):
    _, env, tmp_path = launch_env
    with _launched(launch_env, "wl_test", "two.launch", "greeting:=hey") as (child, log):
        wait_until(lambda: _publishers(env, "/said") == [["/robot/talker"]], 30.0,
                   "/robot/talker publishing /said (%s)" % processes.log_tail(log))
        wait_until(lambda: "talker /robot/talker" in processes.log_tail(log), 10.0,
                   "the talker's first line")
        text = processes.log_tail(log)
        assert "talker /robot/talker rate 20 greeting hey who the launch file args --flag one" \
            in text, text
        assert "quitter in the log folder" not in text      # output="log"
        pids = [int(line.rsplit("[", 1)[1].rstrip("]")) for line in text.splitlines()
                if line.startswith("process[")]
        assert len(pids) == 2, text
        launcher_cmdline = _read("/proc/%d/cmdline" % child.pid, "rb")
        for pid in pids:
            # a fork of the launcher, which is a fork of the zygote: no interpreter started
            assert _read("/proc/%d/cmdline" % pid, "rb") == launcher_cmdline
            assert os.getpgid(pid) == child.pid
        wait_until(lambda: any("quitter in the log folder" in _read(os.path.join(d, f))
                               for d, _, files in os.walk(tmp_path / "ros") for f in files
                               if f == "quitter-stdout.log"), 10.0, "quitter's output file")
        child.signal_group(signal.SIGINT)
        assert child.wait(10.0) == 0, processes.log_tail(log)
        text = processes.log_tail(log, 40)
        assert "talker ends" in text
        assert "[robot/talker] process has finished cleanly" in text, text
        assert not any(processes.alive(pid) for pid in pids)


def test_a_required_node_that_ends_stops_the_launch(launch_env):
    with _launched(launch_env, "wl_test", "two.launch", "quit:=true") as (child, log):
        assert child.wait(30.0) == 0, processes.log_tail(log, 40)
        text = processes.log_tail(log, 40)
        assert "[quitter] required node has ended: stopping the others" in text, text
        assert "talker ends" in text, text


def test_a_launch_file_that_cannot_be_read_ends_the_launch_with_roslaunch_s_reason(launch_env):
    with _launched(launch_env, "wl_test", "missing.launch") as (child, log):
        assert child.wait(30.0) == 1
        text = processes.log_tail(log)
        assert "RLException" in text and "missing.launch" in text, text
