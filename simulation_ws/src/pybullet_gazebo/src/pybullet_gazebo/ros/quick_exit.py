"""A rospy node that ends without rospy's half-second wait.

rospy's shutdown wakes its registration thread (RegManager) before it raises the shutdown
flag, so the thread looks, sees no shutdown yet, and waits 0.5 s more on its condition, which
signal_shutdown then joins: every rospy node takes up to 0.5 s longer to exit than it needs.
The simulator and the tools start and stop many nodes (every run of the batch runner, the
grader and the tests), so their own nodes wake that thread once more after the flag is up.
"""
import functools

import rospy
import rospy.client
import rospy.core
from rospy.impl.registration import RegManager

_woken = set()            # ids of the RegManagers whose condition is woken at shutdown


def wake_registration_thread_at_shutdown():
    """Call after rospy.init_node: at shutdown, once the flag is raised, the node's
    registration thread is woken to see it. Does nothing before init_node, nor twice."""
    for hook in list(rospy.core._preshutdown_hooks):
        manager = getattr(hook, "__self__", None)
        if isinstance(manager, RegManager) and id(manager) not in _woken:
            _woken.add(id(manager))
            rospy.core.add_shutdown_hook(lambda _reason, cond=manager.cond: _notify_all(cond))
            return


def install():
    """Every later rospy.init_node of this process does the above (lockstep/autoload.py
    calls this as rospy is imported, so a controller's exit is quick too)."""
    init_node = rospy.client.init_node

    @functools.wraps(init_node)
    def init_node_then_wake_at_shutdown(*args, **kwds):
        result = init_node(*args, **kwds)
        wake_registration_thread_at_shutdown()
        return result
    rospy.init_node = rospy.client.init_node = init_node_then_wake_at_shutdown


def _notify_all(cond):
    with cond:
        cond.notify_all()
