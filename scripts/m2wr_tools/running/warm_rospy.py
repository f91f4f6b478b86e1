"""rospy's idle waits, shortened in the zygote's children (m2wr_tools.running.zygote), and a signal
to the batch runner when the program has set up its node.

A controller's program stays the user's, unmodified, and so does what its node does; only
four of rospy's fixed sleeps, which cost the batch runner ~0.8 s of wall time a run and a
busy thread at exit, are shortened:

- rospy.init_node waits for its registration with the master in 0.1 s sleeps: here in
  REGISTRATION_POLL [s] sleeps (it takes ~10 ms on localhost).
- rospy.spin() checks for shutdown every 0.5 s: here it returns as soon as the node is shut
  down (a shutdown hook wakes it), e.g. ~0.1 s after SIGINT instead of up to 0.6 s.
- rospy.signal_shutdown joins the registration thread, which notices the shutdown only
  when its 0.5 s wait on new publishers times out: here the shutdown wakes it at once
  (pybullet_gazebo.ros.quick_exit, which every node of the project's environment gets).
  Meanwhile rospy's XML-RPC server thread, whose socket is closed, spins on it, using CPU
  that the next run needs: the shorter exit ends that early too.
- rospy.signal_shutdown ends with a 0.1 s sleep "until we get rid of all the extra threads"
  (rospy's comment), after its hooks have closed every connection: it lets daemon threads
  wind down before the interpreter's teardown, which a zygote child never does (it leaves
  with os._exit once the program has returned): skipped.

A child also takes its own command line's remappings and namespace (`take_command_line`):
rospy reads them as it is imported, in the zygote.

`on_spin` is called once, when the program first enters rospy.spin(): its node has made
every subscription and publisher of its main thread (the batch runner then only waits for
the simulator's connections, not for the program to look idle).
"""
import sys
import threading
import time

REGISTRATION_POLL = 0.005      # [s]


class _PollingClock:
    """`time` for rospy.impl.init: its sleeps (polls) last at most REGISTRATION_POLL."""

    def __getattr__(self, name):
        return getattr(time, name)

    @staticmethod
    def sleep(seconds):
        time.sleep(min(seconds, REGISTRATION_POLL))


def quicken(on_spin=lambda: None):
    """Applies the four changes above to this process's rospy (call before the program
    runs; rospy imported already)."""
    import rospy
    import rospy.client
    import rospy.core
    import rospy.impl.init
    import rospy.rostime

    rospy.impl.init.time = _PollingClock()

    original_wallsleep = rospy.rostime.wallsleep
    shutdown_code = rospy.core.signal_shutdown.__code__

    def wallsleep(duration):
        if sys._getframe(1).f_code is shutdown_code:
            return                              # signal_shutdown's closing pause
        return original_wallsleep(duration)
    rospy.rostime.wallsleep = wallsleep

    original_spin = rospy.client.spin
    spun = []

    def spin():
        if not spun:
            spun.append(True)
            on_spin()
        if not rospy.core.is_initialized():
            return original_spin()              # rospy's own error
        stopped = threading.Event()
        rospy.core.add_shutdown_hook(lambda _reason: stopped.set())
        try:
            while not rospy.core.is_shutdown():
                stopped.wait(0.5)
        except KeyboardInterrupt:
            rospy.core.signal_shutdown("keyboard interrupt")
    spin.__doc__ = original_spin.__doc__
    rospy.client.spin = rospy.spin = spin

    from pybullet_gazebo.ros import quick_exit
    quick_exit.install()


def take_command_line():
    """rospy reads the node's remappings (`from:=to`, `__name:=`, `__ns:=`, `_param:=`) from
    sys.argv, and its namespace (ROS_NAMESPACE or `__ns:=`), once, as it is imported: in the
    zygote, whose command line and environment are not the program's. A child takes its own
    here (sys.argv and os.environ set), before its program runs, as a fresh interpreter would
    have read them: a launch file's `<remap>`, its node's name and `ns`, or rosrun's
    `scan:=/other`."""
    import rosgraph.names
    import rospy.names
    rospy.names.reload_mappings(sys.argv)
    namespace = rosgraph.names.get_ros_namespace()
    rospy.names._caller_namespace = namespace
    rospy.names._caller_id = namespace + "unnamed"
