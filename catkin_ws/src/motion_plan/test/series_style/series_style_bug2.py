#!/usr/bin/env python3
"""Test fixture: bug 2 (episode 10) written the way the series and its learners write it, from
the facts in the project's reference notes (not the series' code): global variables, the
start put with /gazebo/set_model_state (model m2wr, only pose.position x/y set: the quaternion
is all zeros, as the series sends it), then go to point and wall following alternated through
their switch services. It publishes no cmd_vel of its own.

Bug 2: go to point until the front region sees an obstacle nearer than d_obstacle_; then
follow the wall (on the right) until the robot is back on the start-goal line, nearer the goal
than where it met the obstacle; then go to point again. Within 0.3 m of the goal it logs
"goal reached", sets ~goal_reached true and leaves go to point on (its done state holds the
robot with a zero Twist).

Topics: /odom (nav_msgs/Odometry), /m2wr/laser/scan (sensor_msgs/LaserScan) in.
Services called: /gazebo/set_model_state, /go_to_point_switch, /wall_follower_switch.
Parameters (global, as the series): initial_x, initial_y, des_pos_x, des_pos_y [m].
"""
import math

import rospy
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import SetModelState
from geometry_msgs.msg import Point
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_srvs.srv import SetBool
from tf import transformations

srv_client_go_to_point_ = None
srv_client_wall_follower_ = None
yaw_ = 0.0
position_ = Point()
initial_position_ = Point()
initial_position_.x = rospy.get_param("initial_x")
initial_position_.y = rospy.get_param("initial_y")
initial_position_.z = 0
desired_position_ = Point()
desired_position_.x = rospy.get_param("des_pos_x")
desired_position_.y = rospy.get_param("des_pos_y")
desired_position_.z = 0
regions_ = None
state_desc_ = ['Go to point', 'wall following', 'goal reached']
state_ = 0                  # 0 go to point, 1 wall following, 2 goal reached
hit_distance_ = 0.0         # [m] to the goal where wall following began

d_obstacle_ = 1.0           # [m] front nearer than this: an obstacle (the wall follower's d)
d_min_valid_ = 0.15         # [m] readings under this are the laser's minimum, not a wall
line_precision_ = 0.1       # [m] "on the line"
closer_by_ = 0.2            # [m] leave the wall only this much nearer the goal than the hit
goal_precision_ = 0.3       # [m]


def clbk_odom(msg):
    global position_, yaw_
    position_ = msg.pose.pose.position
    quaternion = (msg.pose.pose.orientation.x, msg.pose.pose.orientation.y,
                  msg.pose.pose.orientation.z, msg.pose.pose.orientation.w)
    euler = transformations.euler_from_quaternion(quaternion)
    yaw_ = euler[2]


def clbk_laser(msg):
    global regions_
    regions_ = {
        'right': min(min(msg.ranges[0:143]), 10),
        'fright': min(min(msg.ranges[144:287]), 10),
        'front': min(min(msg.ranges[288:431]), 10),
        'fleft': min(min(msg.ranges[432:575]), 10),
        'left': min(min(msg.ranges[576:713]), 10),
    }


def change_state(state):
    global state_, hit_distance_
    state_ = state
    rospy.loginfo("bug2: state %d, %s (at %.2f, %.2f)", state, state_desc_[state],
                  position_.x, position_.y)
    if state_ == 0:
        srv_client_wall_follower_(False)
        srv_client_go_to_point_(True)
    if state_ == 1:
        hit_distance_ = distance_to_goal()
        srv_client_go_to_point_(False)
        srv_client_wall_follower_(True)
    if state_ == 2:
        srv_client_wall_follower_(False)
        srv_client_go_to_point_(True)       # its done state publishes the zero Twist


def distance_to_goal():
    return math.sqrt(pow(desired_position_.y - position_.y, 2) +
                     pow(desired_position_.x - position_.x, 2))


def distance_to_line(p0):
    """[m] from p0 to the line through the initial and the desired position."""
    p1 = initial_position_
    p2 = desired_position_
    up_eq = math.fabs((p2.y - p1.y) * p0.x - (p2.x - p1.x) * p0.y + (p2.x * p1.y) - (p2.y * p1.x))
    lo_eq = math.sqrt(pow(p2.y - p1.y, 2) + pow(p2.x - p1.x, 2))
    return up_eq / lo_eq


def main():
    global srv_client_go_to_point_, srv_client_wall_follower_

    rospy.init_node("bug2")

    rospy.Subscriber("/m2wr/laser/scan", LaserScan, clbk_laser)
    rospy.Subscriber("/odom", Odometry, clbk_odom)

    rospy.wait_for_service("/go_to_point_switch")
    rospy.wait_for_service("/wall_follower_switch")
    rospy.wait_for_service("/gazebo/set_model_state")

    srv_client_go_to_point_ = rospy.ServiceProxy("/go_to_point_switch", SetBool)
    srv_client_wall_follower_ = rospy.ServiceProxy("/wall_follower_switch", SetBool)
    srv_client_set_model_state = rospy.ServiceProxy("/gazebo/set_model_state", SetModelState)

    # put the robot at the start: only the position is set, as the series does
    model_state = ModelState()
    model_state.model_name = "m2wr"
    model_state.pose.position.x = initial_position_.x
    model_state.pose.position.y = initial_position_.y
    resp = srv_client_set_model_state(model_state)
    rospy.loginfo("bug2: set_model_state (%.2f, %.2f): %s %s", initial_position_.x,
                  initial_position_.y, resp.success, resp.status_message)

    rate_hz = 20
    rate = rospy.Rate(rate_hz)
    while regions_ is None and not rospy.is_shutdown():
        rate.sleep()                        # the first scan

    rospy.loginfo("bug2: from (%.2f, %.2f) to (%.2f, %.2f)", initial_position_.x,
                  initial_position_.y, desired_position_.x, desired_position_.y)
    change_state(0)

    while not rospy.is_shutdown():
        distance_position_to_line = distance_to_line(position_)

        if state_ == 0:
            if distance_to_goal() < goal_precision_:
                rospy.loginfo("goal reached: (%.2f, %.2f)", position_.x, position_.y)
                rospy.set_param("~goal_reached", True)
                change_state(2)
            elif d_min_valid_ < regions_['front'] < d_obstacle_:
                change_state(1)

        elif state_ == 1:
            if distance_to_goal() < goal_precision_:
                rospy.loginfo("goal reached: (%.2f, %.2f)", position_.x, position_.y)
                rospy.set_param("~goal_reached", True)
                change_state(2)
            elif distance_position_to_line < line_precision_ and \
                    distance_to_goal() < hit_distance_ - closer_by_:
                change_state(0)

        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
