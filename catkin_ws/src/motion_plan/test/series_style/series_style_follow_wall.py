#!/usr/bin/env python3
"""Test fixture: wall following (episode 7) written the way the series and its learners write
it, from the facts in the project's reference notes (not the series' code): global variables,
episode 5's five regions, a switch service, its own rospy.Rate loop, bang-bang commands.

Keeps the wall on the robot's RIGHT, with one distance d (1.0 m):
  find the wall   forward 0.2 m/s turning right (-0.3 rad/s)   nothing near ahead or right
  turn left       in place, +0.3 rad/s                          something near in front
  follow the wall forward 0.5 m/s, angular 0                    front clear, the wall front-right

Topics: /m2wr/laser/scan (sensor_msgs/LaserScan) in; /cmd_vel (geometry_msgs/Twist) out,
only while active. Service: wall_follower_switch (std_srvs/SetBool), inactive at start.
Parameters:
  ~rate       [Hz]  the loop's rate (20)
  ~d          [m]   the one distance of the rules (1.0). In the open, find the wall drives a
                    circle (0.2 m/s at -0.3 rad/s: radius 0.67 m as commanded, 0.5 m on this
                    project's m2wr, whose wheels sit at +-0.15 m under wheelSeparation 0.4)
                    and finds a wall only if one comes within d of the front or front-right:
                    from (0, 8), yaw 0, in world02 it circles for ever with d 1.0
  ~turn_sign        +1: angular.z as written (REP 103, positive = left; the simulator with
                    legacy_mode:=true); -1: negated, for the simulator's default
"""
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan
from std_srvs.srv import SetBool, SetBoolResponse

active_ = False
pub_ = None
regions_ = {
    'right': 0,
    'fright': 0,
    'front': 0,
    'fleft': 0,
    'left': 0,
}
state_ = 0                  # 0 find the wall, 1 turn left, 2 follow the wall
state_dict_ = {
    0: 'find the wall',
    1: 'turn left',
    2: 'follow the wall',
}
d_ = 1.0                    # [m]
turn_sign_ = 1.0


def wall_follower_switch(req):
    global active_
    active_ = req.data
    rospy.loginfo("follow_wall: %s", "active" if active_ else "inactive")
    return SetBoolResponse(success=True, message="Done!")


def clbk_laser(msg):
    global regions_
    regions_ = {
        'right': min(min(msg.ranges[0:143]), 10),
        'fright': min(min(msg.ranges[144:287]), 10),
        'front': min(min(msg.ranges[288:431]), 10),
        'fleft': min(min(msg.ranges[432:575]), 10),
        'left': min(min(msg.ranges[576:713]), 10),
    }
    take_action()


def change_state(state):
    global state_
    if state != state_:
        rospy.loginfo("follow_wall: state %d, %s", state, state_dict_[state])
        state_ = state


def take_action():
    regions = regions_
    d = d_
    if regions['front'] > d and regions['fleft'] > d and regions['fright'] > d:
        change_state(0)     # nothing near
    elif regions['front'] < d and regions['fleft'] > d and regions['fright'] > d:
        change_state(1)     # front
    elif regions['front'] > d and regions['fleft'] > d and regions['fright'] < d:
        change_state(2)     # fright: the wall on the right
    elif regions['front'] > d and regions['fleft'] < d and regions['fright'] > d:
        change_state(0)     # fleft only: look for a wall on the right
    elif regions['front'] < d and regions['fleft'] > d and regions['fright'] < d:
        change_state(1)     # front and fright
    elif regions['front'] < d and regions['fleft'] < d and regions['fright'] > d:
        change_state(1)     # front and fleft
    elif regions['front'] < d and regions['fleft'] < d and regions['fright'] < d:
        change_state(1)     # front and fleft and fright
    elif regions['front'] > d and regions['fleft'] < d and regions['fright'] < d:
        change_state(2)     # fleft and fright: a corridor, the wall still on the right
    else:
        rospy.loginfo("follow_wall: unknown case %s", regions)


def find_wall():
    msg = Twist()
    msg.linear.x = 0.2
    msg.angular.z = -0.3
    return msg


def turn_left():
    msg = Twist()
    msg.angular.z = 0.3
    return msg


def follow_the_wall():
    msg = Twist()
    msg.linear.x = 0.5
    return msg


def main():
    global pub_, turn_sign_, d_
    rospy.init_node("follow_wall")
    turn_sign_ = -1.0 if float(rospy.get_param("~turn_sign", 1)) < 0 else 1.0
    rate_hz = float(rospy.get_param("~rate", 20))
    d_ = float(rospy.get_param("~d", d_))
    pub_ = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
    rospy.Subscriber("/m2wr/laser/scan", LaserScan, clbk_laser)
    rospy.Service("wall_follower_switch", SetBool, wall_follower_switch)
    rospy.loginfo("follow_wall: d %.2f m, rate %.0f Hz, turn_sign %+.0f", d_, rate_hz, turn_sign_)

    rate = rospy.Rate(rate_hz)
    while not rospy.is_shutdown():
        if active_:
            if state_ == 0:
                msg = find_wall()
            elif state_ == 1:
                msg = turn_left()
            elif state_ == 2:
                msg = follow_the_wall()
            else:
                rospy.logerr("follow_wall: unknown state %s", state_)
                msg = Twist()
            msg.angular.z *= turn_sign_
            pub_.publish(msg)
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
