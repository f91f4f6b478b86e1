#!/usr/bin/env python3
"""rostest: `roslaunch my_worlds launch_world.launch` ends by itself, within a few seconds, when
its simulator (node /gazebo, required="true") is killed with SIGKILL, and takes the master it
started with it. The launch runs on a private master (its own port), so this test's master
and anything else on the machine are not involved."""
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import rosgraph
import rosgraph.network
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reliability import node_pid   # noqa: E402
from pybullet_gazebo.ros.testing import wait_until   # noqa: E402

EXIT_WITHIN = 5.0          # [s] wall from the kill to roslaunch's exit


def free_port(address):
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind((address, 0))
        return probe.getsockname()[1]


class SimulatorKilledTest(unittest.TestCase):
    def test_launch_ends_when_the_simulator_is_killed(self):
        # where roslaunch's master will listen: ROS_HOSTNAME's address (scripts/test.sh gives
        # the rostests a loopback address of their own), as rospy and rosmaster read it
        port = free_port(rosgraph.network.get_bind_address())
        master_uri = "http://%s:%d/" % (rosgraph.network.get_host_name(), port)
        env = dict(os.environ, ROS_MASTER_URI=master_uri)
        output = tempfile.TemporaryFile(mode="w+")
        launch = subprocess.Popen(["roslaunch", "-p", str(port), "my_worlds",
                                   "launch_world.launch", "gui:=false"],
                                  env=env, stdout=output, stderr=subprocess.STDOUT,
                                  start_new_session=True)
        master = rosgraph.Master("/test_simulator_killed", master_uri=master_uri)
        try:
            def clock_published():
                try:
                    return "/clock" in [t for t, _ in master.getPublishedTopics("/")]
                except (OSError, rosgraph.MasterException):
                    return False
            wait_until(clock_published, 40, "the simulator to publish /clock", interval=0.1)
            pid = node_pid("/gazebo", master_uri)
            with open("/proc/%d/cmdline" % pid) as source:
                self.assertIn("gazebo_world", source.read())

            os.kill(pid, signal.SIGKILL)
            killed = time.monotonic()
            try:
                launch.wait(timeout=EXIT_WITHIN)
            except subprocess.TimeoutExpired:
                pass
            took = time.monotonic() - killed
            output.seek(0)
            log = output.read()
            self.assertIsNotNone(launch.poll(), "roslaunch still runs %.0f s after its "
                                 "simulator was killed:\n%s" % (took, log[-2000:]))
            self.assertIn("REQUIRED process [gazebo-", log)
            self.assertFalse(master.is_online())                 # its master went too
        finally:
            self.stop(launch, master)
            output.close()

    @staticmethod
    def stop(launch, master):
        """Ends what this test started when the launch did not end by itself: roslaunch with
        SIGINT (it then stops its nodes and master), by force if it has to."""
        if launch.poll() is None:
            os.killpg(launch.pid, signal.SIGINT)
            try:
                launch.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(launch.pid, signal.SIGKILL)
                launch.wait()
        try:
            os.kill(master.getPid(), signal.SIGKILL)       # a master roslaunch left behind
        except (OSError, rosgraph.MasterException):
            pass


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "simulator_killed", SimulatorKilledTest)
