"""The tutorial's obstacle_avoidance.py driven by a loop of its own, as learners often rewrite
it: the scan callback only keeps the latest scan; a rospy.Rate loop (~rate [Hz], default 20)
hands it to the tutorial's clbk_laser, whose take_action publishes /cmd_vel and logs the
case. Same node name (reading_laser), topics, rules and log lines as the tutorial's program;
only what makes it act differs. The benchmark measures lockstep with it beside the tutorial's
own program (a loop program against a scan-answering one).

    python -m m2wr_tools.bench.loop_avoidance [_rate:=20] [_timer:=true]

With `_timer:=true` a rospy.Timer at the same rate acts instead of the loop.
"""
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

from .. import tutorial_scripts, usage


def main(argv=None):
    usage.parser("python -m m2wr_tools.bench.loop_avoidance", __doc__, examples=[
        "python -m m2wr_tools.bench.loop_avoidance              # a rospy.Rate(20) loop",
        "python -m m2wr_tools.bench.loop_avoidance _timer:=true _rate:=50"],
        exit_statuses="Exit status: 0 when ROS shuts the node down.").parse_known_args(argv)
    tutorial = tutorial_scripts.load("obstacle_avoidance.py")
    rospy.init_node("reading_laser")
    hz = rospy.get_param("~rate", 20.0)
    tutorial.pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
    latest = []
    rospy.Subscriber("/m2wr/laser/scan", LaserScan, lambda msg: latest[:1].clear()
                     or latest.append(msg))
    if rospy.get_param("~timer", False):
        rospy.Timer(rospy.Duration(1.0 / hz),
                    lambda _event: latest and tutorial.clbk_laser(latest[-1]))
        rospy.spin()
        return
    rate = rospy.Rate(hz)
    try:
        while not rospy.is_shutdown():
            if latest:
                tutorial.clbk_laser(latest[-1])
            rate.sleep()
    except rospy.ROSInterruptException:
        pass


if __name__ == "__main__":
    main()
