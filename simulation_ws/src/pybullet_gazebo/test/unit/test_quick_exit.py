"""quick_exit: rospy's registration thread sees the shutdown flag as soon as it is raised.

rospy wakes that thread before it raises the flag, so the thread waits once more (0.5 s) and
signal_shutdown joins it. Here the thread's condition waits without end unless woken, so
rospy alone would leave it waiting and the fix is told apart by outcome, not by timing. Each
case runs in its own interpreter (rospy's shutdown is for the whole process), without the
autoload hook (LOCKSTEP_HANDSHAKE=off), which would install quick_exit itself. No ROS master:
the thread is rospy's own RegManager loop, started as init_node starts it.
"""
import os
import subprocess
import sys

import pytest

PRELUDE = r"""
import threading
import time
import rospy.core
from rospy.impl.registration import RegManager
from pybullet_gazebo.ros import quick_exit


class WaitsUntilWoken(threading.Condition):
    def wait(self, timeout=None):
        return super().wait(None)


class Handler:
    done = False

"""

CASE = PRELUDE + r"""

if WAKE:
    quick_exit.install()                    # before the node's RegManager is made
manager = RegManager(Handler())             # adds its wake-up as a pre-shutdown hook
manager.cond = WaitsUntilWoken()
thread = threading.Thread(target=manager.run, daemon=True)
thread.start()
while not manager.cond._waiters:            # until the thread waits on its condition
    time.sleep(0.001)
# in a node, the wake-up is followed by the unregistration calls to the master: the thread
# looks again before the flag is raised
rospy.core.add_preshutdown_hook(lambda _reason: time.sleep(0.2))
rospy.core._TIMEOUT_SHUTDOWN_JOIN = 2.0     # how long signal_shutdown joins the thread
rospy.core._add_shutdown_thread(thread)
rospy.core.signal_shutdown("test")
print("thread alive after shutdown:", thread.is_alive())
"""


@pytest.mark.parametrize("wake, alive", [(True, False), (False, True)])
def test_the_registration_thread_ends_with_the_shutdown_only_when_woken_after_the_flag(wake, alive):
    # without the autoload hook, which installs quick_exit in every process of the venv
    env = dict(os.environ, LOCKSTEP_HANDSHAKE="off")
    done = subprocess.run([sys.executable, "-c", "WAKE = %r\n" % wake + CASE], env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=60)
    assert done.returncode == 0, done.stdout
    assert "thread alive after shutdown: %s" % alive in done.stdout, done.stdout


SLEEPER = PRELUDE + r"""
import rospy
import rospy.rostime

if WAKE:
    quick_exit.install()
RegManager(Handler())                       # as init_node makes it: adds the shutdown hook
rospy.rostime._rostime_cond = WaitsUntilWoken()
rospy.rostime.set_rostime_initialized(True)
rospy.rostime._set_rostime(rospy.Time(1))   # /use_sim_time: the world paused at 1 s
ended = []


def loop():
    try:
        rospy.sleep(10.0)                   # a rospy.Rate loop's sleep, on sim time
    except rospy.exceptions.ROSInterruptException:
        ended.append(True)
thread = threading.Thread(target=loop, daemon=True)
thread.start()
while not rospy.rostime._rostime_cond._waiters:
    time.sleep(0.001)
rospy.core.signal_shutdown("test")
thread.join(2.0)
print("sleeper ended with the shutdown:", bool(ended))
"""


@pytest.mark.parametrize("wake, ended", [(True, True), (False, False)])
def test_a_sleep_on_sim_time_ends_with_the_shutdown_only_when_woken(wake, ended):
    """rospy's sim-time sleep looks at the shutdown flag between 0.5 s waits on its time
    condition; here that condition waits without end unless woken (outcome, not timing)."""
    env = dict(os.environ, LOCKSTEP_HANDSHAKE="off")
    done = subprocess.run([sys.executable, "-c", "WAKE = %r\n" % wake + SLEEPER], env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=60)
    assert done.returncode == 0, done.stdout
    assert "sleeper ended with the shutdown: %s" % ended in done.stdout, done.stdout
