#!/usr/bin/env python3
"""rostest: SIGINT (Ctrl-C) and SIGTERM end the simulator at once and without a traceback,
every time, while it steps as fast as it can. Each run starts gazebo_world on world02 in a
namespace of its own (on this test's master), waits until it publishes, signals its whole
process group (as a terminal's Ctrl-C does) at a varying moment, and reads its output.
The same is done with the GUI on, in a real window: on the user's display when DISPLAY is
set, else on an Xvfb server this test starts and stops (setup.sh installs Debian's xvfb)."""
import os
import random
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import rosgraph
import rospkg
import rostest

from pybullet_gazebo.ros.testing import VirtualDisplay, wait_until

RUNS_SIGINT = 5
RUNS_SIGTERM = 2
EXIT_WITHIN = 10.0          # [s] wall from the signal to the process's exit


class CleanShutdownTest(unittest.TestCase):
    def setUp(self):
        self.master = rosgraph.Master("/test_clean_shutdown")
        self.worlds = os.path.join(rospkg.RosPack().get_path("my_worlds"), "worlds")
        self.rng = random.Random(7)

    def run_and_signal(self, run, signum, gui, env=None):
        namespace = "/shutdown_%d_%d" % (os.getpid(), run)
        output = tempfile.TemporaryFile(mode="w+")
        node = subprocess.Popen(
            ["rosrun", "pybullet_gazebo", "gazebo_world", "world02", "--worlds-dir", self.worlds,
             "__ns:=" + namespace, "_real_time_factor:=0", "_gui:=%s" % str(gui).lower()],
            stdout=output, stderr=subprocess.STDOUT, start_new_session=True, env=env)
        try:
            topic = namespace + "/gazebo/model_states"

            def up():
                self.assertIsNone(node.poll(), "the simulator ended while starting")
                return topic in [t for t, _ in self.master.getPublishedTopics("/")]
            wait_until(up, 40, "the simulator to publish %s" % topic, interval=0.1)
            time.sleep(self.rng.uniform(0.2, 1.5))          # mid-run, at a varying step
            os.killpg(node.pid, signum)
            node.wait(EXIT_WITHIN)
        finally:
            if node.poll() is None:
                os.killpg(node.pid, signal.SIGKILL)
                node.wait()
        output.seek(0)
        text = output.read()
        self.assertNotIn("Traceback", text, text)
        self.assertNotIn("pybullet.error", text, text)
        return text

    def test_sigint_and_sigterm_leave_no_traceback_headless(self):
        for run in range(RUNS_SIGINT):
            self.run_and_signal(run, signal.SIGINT, gui=False)
        for run in range(RUNS_SIGTERM):
            self.run_and_signal(100 + run, signal.SIGTERM, gui=False)

    @unittest.skipUnless(os.environ.get("DISPLAY") or shutil.which("Xvfb"),
                         "no display and no Xvfb (apt-get install xvfb)")
    def test_sigint_leaves_no_traceback_with_the_gui(self):
        virtual = None if os.environ.get("DISPLAY") else VirtualDisplay()
        env = dict(os.environ, DISPLAY=virtual.display) if virtual else None
        try:
            for run in range(3):
                text = self.run_and_signal(200 + run, signal.SIGINT, gui=True, env=env)
                self.assertNotIn("running headless", text, "the GUI did not open:\n" + text)
        finally:
            if virtual is not None:
                virtual.stop()


if __name__ == "__main__":
    rostest.rosrun("pybullet_gazebo", "clean_shutdown", CleanShutdownTest)
