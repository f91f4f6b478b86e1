#!/usr/bin/env python3
"""Go to point, as episode 6 of the series describes it (our own code, written from that
description): turn in place towards the goal, then drive straight at it; stop within 0.3 m.
Built the way the series' programs are: parameters read before init_node, a switch service,
tf.transformations for the heading, and a loop at its own rate (not in answer to /odom).

Parameters (read before init_node, global names as in the series):
  des_pos_x, des_pos_y  [m]  the goal (0, 0)
  turn_sign             +1: a positive angular.z turns the robot left (REP 103; the simulator
                        run with legacy_mode:=true, or Gazebo Kinetic); -1: the twin for the
                        simulator's default (Gazebo Noetic), under which a positive angular.z
                        turns m2wr clockwise
Unlike the series' program it also stops driving forward when the laser's front fifth sees
something nearer than 0.45 m: a bug controller that switches it off when it meets an
obstacle does so by a service call, which a simulator running many times faster than real
time does not wait for; without the stop the robot would drive on into the wall meanwhile.
Topics: /odom (nav_msgs/Odometry) and /m2wr/laser/scan (sensor_msgs/LaserScan) in; /cmd_vel (geometry_msgs/Twist) out at 20 Hz sim, only
while active. Service: /go_to_point_switch (std_srvs/SetBool): data true starts (reading
des_pos_x/des_pos_y again, so a new goal can be given without a restart), false stops (and
publishes one zero Twist: the drive holds the last command, as Gazebo's does).
Logs `goal reached` once within 0.3 m of the goal.
"""
import math
import threading

import rospy
from geometry_msgs.msg import Point, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_srvs.srv import SetBool, SetBoolResponse
from tf import transformations

TURN_SPEED = 0.7            # [rad/s] turning in place
DRIVE_SPEED = 0.6           # [m/s]
HEADING_TOLERANCE = math.radians(2.0)   # [rad] turn until the heading error is under this
HEADING_DRIFT = math.radians(15.0)      # [rad] driving: turn in place again beyond this
GOAL_TOLERANCE = 0.3        # [m]
SAFETY_STOP = 0.45          # [m] nothing drives forward with the front nearer than this
RATE = 20.0                 # [Hz] of ROS time

FIX_HEADING, DRIVE, DONE = "fix heading", "drive", "done"


def heading_error(position, yaw, goal):
    """[rad] in (-pi, pi]: how far the robot must turn left to face the goal."""
    wanted = math.atan2(goal.y - position.y, goal.x - position.x)
    return math.atan2(math.sin(wanted - yaw), math.cos(wanted - yaw))


class GoToPoint:
    def __init__(self, goal, turn_sign):
        self.goal = goal
        self.turn_sign = turn_sign
        self.active = False
        self.switching = threading.Lock()    # a command never goes out after the stop
        self.state = FIX_HEADING
        self.position = None
        self.yaw = 0.0
        self.front = float("inf")           # [m] nearest range of the scan's middle fifth
        self.cmd_vel = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        rospy.Subscriber("/odom", Odometry, self.on_odom, queue_size=1)
        rospy.Subscriber("/m2wr/laser/scan", LaserScan, self.on_scan, queue_size=1)
        rospy.Service("/go_to_point_switch", SetBool, self.on_switch)

    def on_switch(self, request):
        with self.switching:
            return self.switch(request)

    def switch(self, request):
        self.active = request.data
        if self.active:
            self.state = FIX_HEADING
            # the goal may have changed since the start (the series reads it once)
            self.goal = Point(rospy.get_param("des_pos_x", self.goal.x),
                              rospy.get_param("des_pos_y", self.goal.y), 0.0)
        else:
            self.cmd_vel.publish(Twist())    # stop: the drive would hold the last command
        rospy.loginfo("go to point %s", ("on: goal (%.2f, %.2f)" % (self.goal.x, self.goal.y))
                      if self.active else "off")
        return SetBoolResponse(True, "done")

    def on_odom(self, msg):
        self.position = msg.pose.pose.position
        q = msg.pose.pose.orientation
        self.yaw = transformations.euler_from_quaternion([q.x, q.y, q.z, q.w])[2]

    def on_scan(self, msg):
        fifth = len(msg.ranges) // 5
        middle = [r for r in msg.ranges[2 * fifth:3 * fifth] if r == r]
        self.front = min(middle) if middle else float("inf")

    def command(self):
        """The Twist for now (REP 103 signs before turn_sign) and the next state."""
        twist = Twist()
        if self.position is None or self.state == DONE:
            return twist
        distance = math.hypot(self.goal.x - self.position.x, self.goal.y - self.position.y)
        error = heading_error(self.position, self.yaw, self.goal)
        if distance < GOAL_TOLERANCE:
            self.state = DONE
            rospy.loginfo("goal reached: (%.2f, %.2f), %.2f m from (%.2f, %.2f)", self.position.x,
                          self.position.y, distance, self.goal.x, self.goal.y)
            return twist
        if self.state == FIX_HEADING:
            if abs(error) < HEADING_TOLERANCE:
                self.state = DRIVE
            else:
                # full speed, slowing down over the last 20 degrees so as not to overshoot
                speed = min(TURN_SPEED, max(0.15, 2.0 * abs(error)))
                twist.angular.z = math.copysign(speed, error)
                return twist
        if abs(error) > HEADING_DRIFT:
            self.state = FIX_HEADING
            return twist
        twist.linear.x = DRIVE_SPEED if self.front > SAFETY_STOP else 0.0
        twist.angular.z = max(-0.3, min(0.3, 1.5 * error))       # small steering while driving
        return twist

    def spin(self):
        rate = rospy.Rate(RATE)
        while not rospy.is_shutdown():
            with self.switching:
                if self.active:
                    twist = self.command()
                    twist.angular.z *= self.turn_sign
                    self.cmd_vel.publish(twist)
            rate.sleep()


def main():
    goal = Point(rospy.get_param("des_pos_x", 0.0), rospy.get_param("des_pos_y", 0.0), 0.0)
    turn_sign = 1.0 if float(rospy.get_param("turn_sign", 1.0)) >= 0 else -1.0
    rospy.init_node("go_to_point")
    rospy.loginfo("go to point: goal (%.2f, %.2f), positive angular.z %s", goal.x, goal.y,
                  "turns left (REP 103)" if turn_sign > 0 else "sent negated (Gazebo Noetic m2wr)")
    try:
        GoToPoint(goal, turn_sign).spin()
    except rospy.ROSInterruptException:
        pass


if __name__ == "__main__":
    main()
