#!/usr/bin/env python3
"""Bug 2, as episodes 8-10 of the series describe it (our own code, written from that
description): go straight for the goal; at an obstacle, follow its wall (on the right) until
back on the start-goal line (the m-line) nearer to the goal than where the obstacle was
met; then go for the goal again. It alternates the go-to-point and wall-following nodes
through their switch services, as the series' bug programs do, and first puts the robot at
the start with a position-only /gazebo/set_model_state (orientation left all zeros).

Parameters (read before init_node, global names as in the series):
  initial_x, initial_y  [m]  the start (0, 8)
  des_pos_x, des_pos_y  [m]  the goal (0, -4)
Uses: /odom (nav_msgs/Odometry), /m2wr/laser/scan (sensor_msgs/LaserScan),
/go_to_point_switch and /wall_follower_switch (std_srvs/SetBool), /gazebo/set_model_state.
Logs each change of state and `goal reached` within 0.3 m; then both behaviours are off.
Sets ~placed_at (the sim time [s] the robot was put at the start) or ~not_placed (the
simulator's answer) after its set_model_state, for tests that must not miss it on /rosout.
"""
import math

import rospy
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import SetModelState
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_srvs.srv import SetBool
from tf import transformations

OBSTACLE = 0.7              # [m] the front region nearer than this: follow the wall
ON_LINE = 0.15              # [m] from the m-line counts as on it
PROGRESS = 0.5              # [m] leave the wall only this much nearer the goal than the hit
MIN_FOLLOW = 3.0            # [s] of ROS time following a wall before leaving it
GOAL_TOLERANCE = 0.3        # [m]
RATE = 20.0                 # [Hz]

GO, WALL, DONE = "go to point", "wall following", "done"


class Bug2:
    def __init__(self, start, goal):
        self.start, self.goal = start, goal
        self.position, self.yaw, self.front = None, 0.0, 10.0
        rospy.Subscriber("/odom", Odometry, self.on_odom, queue_size=1)
        rospy.Subscriber("/m2wr/laser/scan", LaserScan, self.on_scan, queue_size=1)
        for name in ("/go_to_point_switch", "/wall_follower_switch", "/gazebo/set_model_state"):
            rospy.wait_for_service(name)
        self.go_to_point = rospy.ServiceProxy("/go_to_point_switch", SetBool)
        self.wall_follower = rospy.ServiceProxy("/wall_follower_switch", SetBool)
        self.set_model_state = rospy.ServiceProxy("/gazebo/set_model_state", SetModelState)
        self.state, self.hit_distance, self.hit_time = None, None, None

    def on_odom(self, msg):
        p = msg.pose.pose.position
        q = msg.pose.pose.orientation
        self.position = (p.x, p.y)
        self.yaw = transformations.euler_from_quaternion([q.x, q.y, q.z, q.w])[2]

    def on_scan(self, msg):
        fifth = len(msg.ranges) // 5
        self.front = min([r for r in msg.ranges[2 * fifth:3 * fifth] if math.isfinite(r)] + [10.0])

    def place_robot(self):
        state = ModelState()
        state.model_name = "m2wr"
        state.pose.position.x, state.pose.position.y = self.start
        answer = self.set_model_state(state)
        if answer.success:
            rospy.set_param("~placed_at", rospy.get_time())     # [s] sim time, for tests
            rospy.loginfo("robot placed at (%.2f, %.2f)", *self.start)
        else:
            rospy.set_param("~not_placed", answer.status_message)
            rospy.logwarn("robot not placed at (%.2f, %.2f): %s", self.start[0], self.start[1],
                          answer.status_message)

    def switch(self, state):
        if state == self.state:
            return
        rospy.loginfo("state: %s", state)
        self.state = state
        self.go_to_point(state == GO)
        self.wall_follower(state == WALL)

    def distance_to_goal(self):
        return math.hypot(self.goal[0] - self.position[0], self.goal[1] - self.position[1])

    def distance_to_m_line(self):
        (x0, y0), (x1, y1), (x, y) = self.start, self.goal, self.position
        return abs((x1 - x0) * (y0 - y) - (x0 - x) * (y1 - y0)) / math.hypot(x1 - x0, y1 - y0)

    def step(self):
        if self.distance_to_goal() < GOAL_TOLERANCE:
            rospy.loginfo("goal reached: (%.2f, %.2f), %.2f m from (%.2f, %.2f)",
                          self.position[0], self.position[1], self.distance_to_goal(), *self.goal)
            self.switch(DONE)
        elif self.state == GO and self.front < OBSTACLE:
            self.hit_distance, self.hit_time = self.distance_to_goal(), rospy.get_time()
            self.switch(WALL)
        elif self.state == WALL and rospy.get_time() - self.hit_time > MIN_FOLLOW \
                and self.distance_to_m_line() < ON_LINE \
                and self.distance_to_goal() < self.hit_distance - PROGRESS:
            self.switch(GO)

    def spin(self):
        rate = rospy.Rate(RATE)
        while self.position is None and not rospy.is_shutdown():
            rate.sleep()                 # the robot is there once its /odom comes
        self.place_robot()
        rospy.sleep(0.5)                 # let /odom report the new pose
        self.switch(GO)
        while not rospy.is_shutdown() and self.state != DONE:
            self.step()
            rate.sleep()


def main():
    start = (rospy.get_param("initial_x", 0.0), rospy.get_param("initial_y", 8.0))
    goal = (rospy.get_param("des_pos_x", 0.0), rospy.get_param("des_pos_y", -4.0))
    rospy.init_node("bug2")
    try:
        Bug2(start, goal).spin()
    except rospy.ROSInterruptException:
        pass


if __name__ == "__main__":
    main()
