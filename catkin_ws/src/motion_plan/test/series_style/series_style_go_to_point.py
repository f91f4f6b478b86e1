#!/usr/bin/env python3
"""Test fixture: go to point (episode 6) written the way the series and its learners write it,
from the facts in the project's reference notes (not the series' code): global variables, the
goal read from des_pos_x/des_pos_y BEFORE init_node, a switch service, tf.transformations for
the heading, its own rospy.Rate loop, and bang-bang control with no slow-down anywhere.

States: fix yaw (turn in place at +-0.7 rad/s, sign by the heading error, until the error is
under 2 deg), go straight (0.6 m/s, angular 0; back to fix yaw when the error exceeds 2 deg),
done (within 0.3 m: a zero Twist, "goal reached").

Topics: /odom (nav_msgs/Odometry) in; /cmd_vel (geometry_msgs/Twist) out, only while active.
Service: go_to_point_switch (std_srvs/SetBool), inactive at start.
Parameters:
  des_pos_x, des_pos_y  [m]   the goal, read once, before init_node (as the series does)
  ~rate                 [Hz]  the loop's rate (20)
  ~active                     start switched on (false: as the series, wait for the switch;
                              true: for a batch runner that does not call switch services)
  ~turn_sign                  +1: angular.z as written (REP 103, positive = left; the
                              simulator with legacy_mode:=true); -1: negated, for the
                              simulator's default (Gazebo Noetic's diff drive)
"""
import math

import rospy
from geometry_msgs.msg import Point, Twist
from nav_msgs.msg import Odometry
from std_srvs.srv import SetBool, SetBoolResponse
from tf import transformations

active_ = False
position_ = Point()
yaw_ = 0.0
state_ = 0                  # 0 fix yaw, 1 go straight, 2 done
state_names_ = ["fix yaw", "go straight", "done"]
desired_position_ = Point()
desired_position_.x = rospy.get_param("des_pos_x")     # before init_node: global names
desired_position_.y = rospy.get_param("des_pos_y")
desired_position_.z = 0
yaw_precision_ = math.pi / 90   # [rad] 2 deg
dist_precision_ = 0.3           # [m]
turn_sign_ = 1.0

pub_ = None


def go_to_point_switch(req):
    global active_
    active_ = req.data
    rospy.loginfo("go_to_point: %s", "active" if active_ else "inactive")
    return SetBoolResponse(success=True, message="Done!")


def clbk_odom(msg):
    global position_, yaw_
    position_ = msg.pose.pose.position
    quaternion = (msg.pose.pose.orientation.x, msg.pose.pose.orientation.y,
                  msg.pose.pose.orientation.z, msg.pose.pose.orientation.w)
    euler = transformations.euler_from_quaternion(quaternion)
    yaw_ = euler[2]


def change_state(state):
    global state_
    state_ = state
    rospy.loginfo("go_to_point: state %d, %s (at %.2f, %.2f)", state, state_names_[state],
                  position_.x, position_.y)


def normalize_angle(angle):
    if math.fabs(angle) > math.pi:
        angle = angle - (2 * math.pi * angle) / math.fabs(angle)
    return angle


def fix_yaw(des_pos):
    desired_yaw = math.atan2(des_pos.y - position_.y, des_pos.x - position_.x)
    err_yaw = normalize_angle(desired_yaw - yaw_)
    twist_msg = Twist()
    if math.fabs(err_yaw) > yaw_precision_:
        twist_msg.angular.z = 0.7 if err_yaw > 0 else -0.7
    twist_msg.angular.z *= turn_sign_
    pub_.publish(twist_msg)
    if math.fabs(err_yaw) <= yaw_precision_:
        change_state(1)


def go_straight_ahead(des_pos):
    desired_yaw = math.atan2(des_pos.y - position_.y, des_pos.x - position_.x)
    err_yaw = normalize_angle(desired_yaw - yaw_)
    err_pos = math.sqrt(pow(des_pos.y - position_.y, 2) + pow(des_pos.x - position_.x, 2))
    if err_pos > dist_precision_:
        twist_msg = Twist()
        twist_msg.linear.x = 0.6
        pub_.publish(twist_msg)
    else:
        change_state(2)
        return
    if math.fabs(err_yaw) > yaw_precision_:
        change_state(0)


def done():
    twist_msg = Twist()
    pub_.publish(twist_msg)


def main():
    global pub_, turn_sign_, active_
    rospy.init_node("go_to_point")
    turn_sign_ = -1.0 if float(rospy.get_param("~turn_sign", 1)) < 0 else 1.0
    rate_hz = float(rospy.get_param("~rate", 20))
    active_ = bool(rospy.get_param("~active", False))    # the series' starts switched off
    pub_ = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
    rospy.Subscriber("/odom", Odometry, clbk_odom)
    rospy.Service("go_to_point_switch", SetBool, go_to_point_switch)
    rospy.loginfo("go_to_point: goal (%.2f, %.2f), rate %.0f Hz, turn_sign %+.0f",
                  desired_position_.x, desired_position_.y, rate_hz, turn_sign_)

    rate = rospy.Rate(rate_hz)
    reported = False
    while not rospy.is_shutdown():
        if active_:
            if state_ == 0:
                fix_yaw(desired_position_)
            elif state_ == 1:
                go_straight_ahead(desired_position_)
            elif state_ == 2:
                if not reported:
                    rospy.loginfo("goal reached: (%.2f, %.2f)", position_.x, position_.y)
                    reported = True
                done()
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
