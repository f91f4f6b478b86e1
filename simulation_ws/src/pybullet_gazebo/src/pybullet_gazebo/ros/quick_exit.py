"""A rospy node that ends without rospy's half-second wait.

rospy's shutdown wakes its registration thread (RegManager) before it raises the shutdown
flag, so the thread looks, sees no shutdown yet, and waits 0.5 s more on its condition, which
signal_shutdown then joins: every rospy node takes up to 0.5 s longer to exit than it needs.
The simulator and the tools start and stop many nodes (every run of the batch runner, the
grader and the tests), so every node of the project's environment wakes that thread once more
after the flag is up (lockstep/autoload.py installs this as rospy is imported; the world node
and the batch runner's warm interpreters install it themselves).
"""
import rospy.core
from rospy.impl.registration import RegManager


def install():
    """Every RegManager made from now on (rospy.init_node makes the node's one) is woken by
    a shutdown hook, which runs once the flag is up. Call before rospy.init_node; a second
    call changes nothing."""
    if getattr(RegManager, "_wakes_at_shutdown", False):
        return
    original_init = RegManager.__init__

    def init(self, handler):
        original_init(self, handler)

        def wake(_reason):
            with self.cond:          # (read at shutdown: the condition the thread waits on)
                self.cond.notify_all()
        rospy.core.add_shutdown_hook(wake)
    RegManager.__init__ = init
    RegManager._wakes_at_shutdown = True
