#!/usr/bin/env python3
"""Wall following, as episode 7 of the series describes it (our own code, written from that
description): the scan's five regions as in episode 5, three states (find the wall, turn
left, follow the wall) keeping the wall on the robot's right. Unlike a bang-bang follower,
`follow the wall` steers to hold the wall at WALL_DISTANCE. Built the way the series'
programs are: a switch service, parameters read before init_node, its own loop rate.

Parameters (read before init_node):
  turn_sign   +1: a positive angular.z turns the robot left (REP 103; legacy_mode:=true);
              -1: the twin for the simulator's default (Gazebo Noetic's turning of m2wr)
  wall_follower_active  start active (false: wait for the switch), as a convenience for tests
Topics: /m2wr/laser/scan (sensor_msgs/LaserScan) in; /cmd_vel (geometry_msgs/Twist) out at
20 Hz sim while active. Service: /wall_follower_switch (std_srvs/SetBool); switched off, it
publishes one zero Twist (the drive holds the last command, as Gazebo's does).
Logs each change of state (`state: follow the wall`, ...).
"""
import math
import threading

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan
from std_srvs.srv import SetBool, SetBoolResponse

WALL_DISTANCE = 0.55        # [m] from the laser to the wall on the right, when following
SEES_WALL = 1.2             # [m] a region nearer than this holds a wall
BLOCKED = 0.7               # [m] the front nearer than this: turn left in place
FORWARD = 0.35              # [m/s] following
TURN = 0.6                  # [rad/s] turning left in place
RATE = 20.0                 # [Hz] of ROS time
WRAP_TIME = 7.0             # [s] arcing right round a wall's end before going straight on

FIND, TURN_LEFT, FOLLOW = "find the wall", "turn left", "follow the wall"


def regions(ranges):
    """Minimum range [m] (at most 10) of the five fifths of a scan, right to left."""
    fifth = len(ranges) // 5
    values = [r if math.isfinite(r) else 10.0 for r in ranges]
    return {name: min(min(values[i * fifth:(i + 1) * fifth]), 10.0)
            for i, name in enumerate(("right", "fright", "front", "fleft", "left"))}


def decide(region, lost_for):
    """(state, linear.x [m/s], angular.z [rad/s], REP 103 signs) for the five regions;
    lost_for [s]: how long ago the wall was last on the right (inf: never)."""
    if region["front"] < BLOCKED or region["fright"] < BLOCKED * 0.6:
        return TURN_LEFT, 0.0, TURN
    wall = min(region["right"], region["fright"] / 1.2)    # fright beams look ahead at the wall
    if wall < SEES_WALL:
        steer = max(-0.8, min(0.8, 2.0 * (WALL_DISTANCE - wall)))   # too near: left
        return FOLLOW, FORWARD, steer
    if lost_for < WRAP_TIME:                 # the wall ended: turn right round its end
        return FIND, 0.25, -0.5
    return FIND, 0.3, 0.0                    # no wall near: straight on until one comes


class WallFollower:
    def __init__(self, turn_sign, active):
        self.turn_sign = turn_sign
        self.active = active
        self.switching = threading.Lock()    # a command never goes out after the stop
        self.state = None
        self.region = None
        self.wall_seen_at = -float("inf")    # [s] ROS time the wall was last beside it
        self.cmd_vel = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        rospy.Subscriber("/m2wr/laser/scan", LaserScan, self.on_scan, queue_size=1)
        rospy.Service("/wall_follower_switch", SetBool, self.on_switch)

    def on_switch(self, request):
        with self.switching:
            return self.switch(request)

    def switch(self, request):
        self.active = request.data
        if not self.active:
            self.cmd_vel.publish(Twist())    # stop: the drive would hold the last command
        rospy.loginfo("wall follower %s", "on" if self.active else "off")
        return SetBoolResponse(True, "done")

    def on_scan(self, msg):
        self.region = regions(msg.ranges)

    def spin(self):
        rate = rospy.Rate(RATE)
        while not rospy.is_shutdown():
            with self.switching:
                self.tick()
            rate.sleep()

    def tick(self):
        """Publishes the command for the present regions, while active."""
        if not self.active or self.region is None:
            return
        now = rospy.get_time()
        state, linear, angular = decide(self.region, now - self.wall_seen_at)
        if state != FIND:
            self.wall_seen_at = now
        if state != self.state:
            rospy.loginfo("state: %s", state)
            self.state = state
        twist = Twist()
        twist.linear.x = linear
        twist.angular.z = angular * self.turn_sign
        self.cmd_vel.publish(twist)


def main():
    turn_sign = 1.0 if float(rospy.get_param("turn_sign", 1.0)) >= 0 else -1.0
    active = bool(rospy.get_param("wall_follower_active", False))
    rospy.init_node("wall_follower")
    try:
        WallFollower(turn_sign, active).spin()
    except rospy.ROSInterruptException:
        pass


if __name__ == "__main__":
    main()
