#!/usr/bin/env python3
"""Drives m2wr with a trained policy: laser in, cmd_vel out, like episode 5's
obstacle_avoidance.py but with the rules learned (scripts/train.sh, package m2wr_gym).

    rosrun motion_plan learned_avoidance.py _policy:=FILE.npz

Topics in:  /m2wr/laser/scan (sensor_msgs/LaserScan)
Topics out: /cmd_vel (geometry_msgs/Twist); a zero Twist on shutdown
Parameters:
  ~policy   path of the policy .npz (default: m2wr_gym's shipped policies/avoid_world02.npz)
The observation is computed by m2wr_gym.observation, the code the environment uses, and the
policy runs with numpy only (no torch). It decides once per control_period [s of sim time]
stored in the file (0.1 s: the environment's 10 Hz), by the scans' stamps, and answers every
scan with the current command, so a simulator in lockstep goes on at each scan.
"""
import os
import sys

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

from m2wr_gym import observation
from m2wr_gym.policy import PolicyFileError, load

_SLACK = 1e-6        # [s]


def default_policy():
    import rospkg
    return os.path.join(rospkg.RosPack().get_path("m2wr_gym"), "policies", "avoid_world02.npz")


class LearnedAvoidance:
    def __init__(self, policy):
        self.policy = policy
        self.command = (0.0, 0.0)
        self.next_decision = None         # [s] sim time of the next decision
        self.last_stamp = None
        self.pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        self.sub = rospy.Subscriber("/m2wr/laser/scan", LaserScan, self.on_scan, queue_size=1)

    def on_scan(self, msg):
        stamp = msg.header.stamp.to_sec()
        restarted = self.last_stamp is not None and stamp < self.last_stamp   # sim reset
        self.last_stamp = stamp
        if self.next_decision is None or restarted or stamp >= self.next_decision - _SLACK:
            try:
                features = observation.laser_features(self.policy.observation, msg.ranges,
                                                      msg.range_max, self.policy.downsample)
                self.command = self.policy.command(features)
            except ValueError as err:
                rospy.logerr_throttle(5.0, "learned_avoidance: %s; stopping the robot" % err)
                self.command = (0.0, 0.0)
            self.next_decision = stamp + self.policy.control_period
        self.publish(*self.command)

    def publish(self, linear_x, angular_z):
        msg = Twist()
        msg.linear.x = linear_x
        msg.angular.z = angular_z
        self.pub.publish(msg)

    def stop(self):
        self.sub.unregister()
        self.publish(0.0, 0.0)


def check(policy):
    """PolicyFileError when the policy cannot drive from m2wr's scan alone."""
    expected = observation.size(policy.observation, policy.downsample)
    if policy.input_size != expected:
        raise PolicyFileError("policy file %s takes %d inputs, but observation '%s' of m2wr's "
                              "scan gives %d (a goal-task policy also needs the goal; this node "
                              "runs avoid policies)" % (policy.source, policy.input_size,
                                                        policy.observation, expected))


def main():
    rospy.init_node("learned_avoidance")
    path = rospy.get_param("~policy", "") or default_policy()
    try:
        policy = load(path)
        check(policy)
    except PolicyFileError as err:
        rospy.logfatal("%s", err)
        return 1
    node = LearnedAvoidance(policy)
    rospy.on_shutdown(node.stop)
    rospy.loginfo("learned_avoidance: policy %s (%s, %d inputs, %d actions, every %.2f s)",
                  path, policy.observation, policy.input_size, len(policy.actions),
                  policy.control_period)
    rospy.spin()
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (KeyboardInterrupt, rospy.ROSInterruptException):
        sys.exit(0)
