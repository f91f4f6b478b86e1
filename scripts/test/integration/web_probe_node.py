"""A ROS node for test_web_view_browser.py, run as a process of its own: drives m2wr
(/cmd_vel, `linear` m/s and `angular` rad/s, argv[2:4]) and writes each /gazebo/model_states
message's m2wr pose with the sim time it arrived at (the latest /clock) as a JSON line to
argv[1]."""
import json
import sys

import rospy
from gazebo_msgs.msg import ModelStates
from geometry_msgs.msg import Twist


def main():
    out = open(sys.argv[1], "w", buffering=1)
    linear, angular = float(sys.argv[2]), float(sys.argv[3])
    rospy.init_node("web_probe")

    def on_states(msg):
        if "m2wr" in msg.name:
            p = msg.pose[msg.name.index("m2wr")].position
            out.write(json.dumps([rospy.get_time(), p.x, p.y]) + "\n")
    rospy.Subscriber("/gazebo/model_states", ModelStates, on_states, queue_size=10)
    command = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
    twist = Twist()
    twist.linear.x, twist.angular.z = linear, angular
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        command.publish(twist)
        rate.sleep()


if __name__ == "__main__":
    try:
        main()
    except (KeyboardInterrupt, rospy.ROSInterruptException):
        pass
