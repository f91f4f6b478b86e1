"""A rospy node that ends without rospy's half-second wait.

rospy's shutdown wakes its registration thread (RegManager) before it raises the shutdown
flag, so the thread looks, sees no shutdown yet, and waits 0.5 s more on its condition, which
signal_shutdown then joins: every rospy node takes up to 0.5 s longer to exit than it needs.
Likewise a thread in rospy.sleep or rospy.Rate.sleep on sim time (/use_sim_time) waits on
rospy's time condition in 0.5 s waits and looks at the flag only between them: nothing
wakes it at shutdown, so a loop program ended while the world is paused (the batch
runner's and the grader's SIGINT at a run's end) exits up to 0.5 s late. The simulator and
the tools start and stop many nodes (every run of the batch runner, the grader and the
tests), so every node of the project's environment wakes that thread and the sim-time
sleepers once more after the flag is up (lockstep/autoload.py installs this as rospy is
imported; the world node and the batch runner's warm interpreters install it themselves).
"""
import rospy.core
import rospy.rostime
from rospy.impl.registration import RegManager


def install():
    """Every RegManager made from now on (rospy.init_node makes the node's one), and the
    threads sleeping on sim time, are woken by a shutdown hook, which runs once the flag is
    up. Call before rospy.init_node; a second call changes nothing."""
    if getattr(RegManager, "_wakes_at_shutdown", False):
        return
    original_init = RegManager.__init__

    def init(self, handler):
        original_init(self, handler)

        def wake(_reason):
            with self.cond:          # (read at shutdown: the condition the thread waits on)
                self.cond.notify_all()
            sleepers = rospy.rostime.get_rostime_cond()
            with sleepers:
                sleepers.notify_all()
        rospy.core.add_shutdown_hook(wake)
    RegManager.__init__ = init
    RegManager._wakes_at_shutdown = True
