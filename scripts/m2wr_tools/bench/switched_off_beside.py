"""The tutorial's obstacle_avoidance.py beside a behaviour that is switched off, as bug 0-2
run the series' go to point: a second node reads /odom, offers go_to_point_switch
(std_srvs/SetBool) and, while off, goes round `while not rospy.is_shutdown(): if not active:
continue` without sleeping. Nobody switches it on. The benchmark measures lockstep with this
pair against obstacle_avoidance.py alone: a busy loop must not slow the loop down.

    python -m m2wr_tools.bench.switched_off_beside            # both: the behaviour as a child
    python -m m2wr_tools.bench.switched_off_beside --behaviour # the switched-off node alone

The child gets SIGTERM when this process ends, however it ends (PR_SET_PDEATHSIG), and is
waited for here on a normal exit.
"""
import ctypes
import signal
import subprocess
import sys

from .. import usage

PR_SET_PDEATHSIG = 1


def behaviour():
    import rospy
    from nav_msgs.msg import Odometry
    from std_srvs.srv import SetBool, SetBoolResponse

    state = {"active": False, "odometry": None}

    def switch(request):
        state["active"] = request.data
        return SetBoolResponse(success=True, message="Done!")

    rospy.init_node("go_to_point")
    rospy.Subscriber("/odom", Odometry, lambda msg: state.__setitem__("odometry", msg))
    rospy.Service("go_to_point_switch", SetBool, switch)
    rate = rospy.Rate(20)
    while not rospy.is_shutdown():
        if not state["active"]:
            continue                    # the series' switched-off branch: no sleep
        rate.sleep()


def _die_with_parent():
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


def main(argv=None):
    parser = usage.parser("python -m m2wr_tools.bench.switched_off_beside", __doc__, examples=[
        "python -m m2wr_tools.bench.switched_off_beside              # both nodes"],
        exit_statuses="Exit status: 0 when ROS shuts the nodes down.")
    parser.add_argument("--behaviour", action="store_true",
                        help="run only the switched-off go_to_point node (the child)")
    args, _ros_args = parser.parse_known_args(argv)
    if args.behaviour:
        try:
            behaviour()
        except KeyboardInterrupt:
            pass
        return
    child = subprocess.Popen([sys.executable, "-m", "m2wr_tools.bench.switched_off_beside",
                              "--behaviour"], stdin=subprocess.DEVNULL,
                             preexec_fn=_die_with_parent)
    try:
        from .. import tutorial_scripts
        tutorial_scripts.load("obstacle_avoidance.py").main()
    except KeyboardInterrupt:
        pass
    finally:
        child.terminate()
        try:
            child.wait(10)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()


if __name__ == "__main__":
    main()
