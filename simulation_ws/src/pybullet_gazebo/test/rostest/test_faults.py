#!/usr/bin/env python3
"""rostest: faults mid-run in world02 with m2wr at (0, 8) and the tutorial's controller
(motion_plan's obstacle_avoidance.py, started and killed by this test).

1. The controller killed with SIGKILL: the simulation goes on (/clock, /odom); a controller
   started again drives the robot (from (0, 8) it sees nothing ahead: 0.6 m/s forward).
2. reset_simulation with the controller running: m2wr is back at its spawn pose (0, 8, 0.5),
   sim time restarts at 0, and the same controller process goes on driving it.
Over the whole run /clock goes backwards exactly once: at the reset.
"""
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospkg
import rospy
import rostest
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reliability import ClockWatch, OdomWatch, state   # noqa: E402
from pybullet_gazebo.ros.testing import (service, wait_for_message, wait_until,  # noqa: E402
                                         wait_until_sim_time)

# The tutorial's controller, in catkin_ws (which overlays this workspace). catkin's run_tests
# for simulation_ws sees only this workspace's packages, so the script is found by its place
# in the repository when rospack cannot find motion_plan.
REPOSITORY = os.path.abspath(os.path.join(os.path.dirname(__file__), *[".."] * 5))
CONTROLLER_SCRIPT = os.path.join(REPOSITORY, "catkin_ws", "src", "motion_plan", "scripts",
                                 "obstacle_avoidance.py")


def controller_command():
    try:
        rospkg.RosPack().get_path("motion_plan")
        return ["rosrun", "motion_plan", "obstacle_avoidance.py"]
    except rospkg.ResourceNotFound:
        if not os.path.isfile(CONTROLLER_SCRIPT):
            raise AssertionError("the tutorial's controller is neither a package motion_plan "
                                 "(source scripts/env.sh) nor at %s" % CONTROLLER_SCRIPT)
        return [sys.executable, CONTROLLER_SCRIPT]
START = (0.0, 8.0, 0.5)          # [m] spawn.launch y:=8 (z 0.5: dropped onto its wheels)


class CommandWatch:
    """Wall times of the /cmd_vel messages received, by publishing node."""

    def __init__(self):
        self._lock = threading.Lock()
        self.received = []                 # (wall time [s], caller id)
        self.last = None                   # (linear.x, angular.z) of the latest
        self._sub = rospy.Subscriber("/cmd_vel", Twist, self._on_command, queue_size=100)

    def _on_command(self, msg):
        with self._lock:
            self.received.append((time.monotonic(), msg._connection_header["callerid"]))
            self.last = (msg.linear.x, msg.angular.z)

    def count_after(self, wall_time):
        with self._lock:
            return sum(1 for t, _ in self.received if t > wall_time)

    def wait_after(self, wall_time, timeout=30.0):
        wait_until(lambda: self.count_after(wall_time), timeout,
                   "a /cmd_vel from the controller (is it running?)", interval=0.05)


def simulator_connections(topic="/cmd_vel"):
    """The simulator's connections on `topic`, from its own bus information."""
    try:
        master = rosgraph.Master("/test_faults")
        uri = master.lookupNode("/gazebo")
        code, _, bus = xmlrpc.client.ServerProxy(uri).getBusInfo("/test_faults")
        return [c[1:6] for c in bus if len(c) >= 6 and c[4] == topic] if code == 1 else bus
    except Exception as error:          # noqa: BLE001 (evidence for a failure message)
        return "not available (%s)" % error


class FaultsTest(unittest.TestCase):
    controller = None
    controller_log = os.path.join(tempfile.gettempdir(), "test_faults_controller_%d.log"
                                  % os.getpid())

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_faults")
        cls.controller_command = controller_command()
        cls.clock = ClockWatch()
        cls.odom = OdomWatch()
        cls.commands = CommandWatch()
        cls.reset_world = service("/gazebo/reset_world", Empty, timeout=30)
        cls.reset_simulation = service("/gazebo/reset_simulation", Empty)
        wait_for_message("/m2wr/laser/scan", LaserScan, timeout=30)
        wait_until_sim_time(rospy.get_time() + 1.0)          # dropped from z 0.5, settled

    @classmethod
    def tearDownClass(cls):
        cls.kill_controller()
        if os.path.exists(cls.controller_log):
            os.remove(cls.controller_log)

    @classmethod
    def start_controller(cls):
        started = time.monotonic()
        with open(cls.controller_log, "ab") as log:
            cls.controller = subprocess.Popen(cls.controller_command, stdout=log,
                                              stderr=subprocess.STDOUT, start_new_session=True)
        return started

    @classmethod
    def kill_controller(cls):
        if cls.controller is not None and cls.controller.poll() is None:
            os.killpg(cls.controller.pid, signal.SIGKILL)
            cls.controller.wait(timeout=10)

    def assert_drives_forward(self, seconds=1.5, at_least=0.3):
        """The robot's x grows by at_least [m] within `seconds` [s] of sim time."""
        before = state()
        wait_until_sim_time(before[0] + seconds)
        after = state()
        self.assertGreater(after[1] - before[1], at_least, self.evidence(before, after))

    def evidence(self, before, after):
        """What a failure to drive needs to be understood from CI's log alone."""
        alive = self.controller is not None and self.controller.poll() is None
        try:
            with open(self.controller_log, "rb") as log:
                tail = [line[:160] for line in
                        log.read().decode("utf-8", "replace").splitlines()[-4:]]
        except OSError:
            tail = []
        return ("(t, x, y, z, yaw) %s -> %s; %d /cmd_vel heard, the latest %s; the "
                "simulator's /cmd_vel connections %s; controller %s; its output ends: %s"
                % (before, after, len(self.commands.received), self.commands.last,
                   simulator_connections(), "running" if alive else "ended",
                   " | ".join(tail) or "(none)"))

    def test_1_controller_killed_and_restarted(self):
        started = self.start_controller()
        self.commands.wait_after(started)
        self.assert_drives_forward()

        self.kill_controller()
        killed = time.monotonic()
        self.assertEqual(self.controller.returncode, -signal.SIGKILL)
        t_kill = state()[0]
        wait_until_sim_time(t_kill + 1.0, timeout=20)         # the simulation goes on
        self.assertGreater(len(self.odom.since(t_kill)), 10)
        self.assertEqual(self.commands.count_after(killed + 0.5), 0)   # nobody commands now

        self.reset_world()                                    # stop it, back at the start
        t0, x0 = state()[:2]
        wait_until_sim_time(t0 + 1.0)
        self.assertLess(abs(state()[1] - x0), 0.01)          # at rest without a controller

        restarted = self.start_controller()
        self.commands.wait_after(restarted)
        self.assert_drives_forward()                          # the new controller drives

    def test_2_reset_simulation_mid_run_with_the_controller_running(self):
        if self.controller is None or self.controller.poll() is not None:
            self.start_controller()
            self.commands.wait_after(time.monotonic() - 0.1)
        wait_until_sim_time(rospy.get_time() + 1.0)
        before = state()
        self.assertGreater(before[0], 2.0)
        self.assertGreater(before[1], 0.3, self.evidence(before, before))   # it drove away

        self.reset_simulation()
        t, x, y, z, yaw = state()
        self.assertLess(t, 0.3)                               # sim time restarted at 0
        self.assertAlmostEqual(x, START[0], delta=0.02)
        self.assertAlmostEqual(y, START[1], delta=0.02)
        self.assertGreater(z, 0.2)                            # still dropping from 0.5
        self.assertAlmostEqual(yaw, 0.0, delta=0.02)

        reset_at = time.monotonic()
        self.commands.wait_after(reset_at)                    # the controller goes on
        wait_until_sim_time(1.0)                              # landed
        self.assert_drives_forward()
        self.assertIsNone(self.controller.poll())             # and is still alive

        jumps = self.clock.backward_jumps()
        self.assertEqual(len(jumps), 1, jumps)                # only the reset went back
        self.assertLess(jumps[0][1], 0.1)


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "faults", FaultsTest)
