#!/usr/bin/env python3
"""Measuring helper for the series-style fixtures: watches /odom, /cmd_vel, the scan and
/gazebo/contacts and prints one line of results, then exits.

The clock starts at the first non-zero /cmd_vel. With a goal, it stops when /odom comes within
~tolerance of it (then waits ~settle s more for the end pose) or after ~timeout s of sim time;
without a goal it runs ~timeout s. Printed: time to goal [s sim], end pose, nearest approach,
distance driven, total turn [rad, + = left], the nearest scan reading, min/max of the scan's
right quarter (index 0:180, the wall follower's side), and the touches /gazebo/contacts
reported (-1 when nothing publishes it: launch the world with contacts:=true) with the
sim time spent touching.

Parameters: ~goal_x, ~goal_y [m] (optional), ~tolerance [m] (0.3), ~timeout [s sim] (120),
~settle [s sim] (2), ~trace [path] (optional: a CSV of t, x, y, yaw at 20 Hz).
"""
import math

import rospy
from gazebo_msgs.msg import ContactsState
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from tf import transformations

state = {"start": None, "pose": None, "yaw": None, "turn": 0.0, "driven": 0.0,
         "nearest": math.inf, "scan_min": math.inf, "right_min": math.inf, "right_max": 0.0,
         "contacts": -1, "touching": set(), "touch_since": None, "touch_time": 0.0,
         "reached": None, "rows": []}


def on_cmd(msg):
    if state["start"] is None and (msg.linear.x or msg.angular.z):
        state["start"] = rospy.get_time()


def on_odom(msg):
    p = msg.pose.pose.position
    q = msg.pose.pose.orientation
    yaw = transformations.euler_from_quaternion([q.x, q.y, q.z, q.w])[2]
    if state["start"] is not None and state["pose"] is not None:
        state["driven"] += math.hypot(p.x - state["pose"][0], p.y - state["pose"][1])
        state["turn"] += math.atan2(math.sin(yaw - state["yaw"]), math.cos(yaw - state["yaw"]))
        state["rows"].append((msg.header.stamp.to_sec(), p.x, p.y, yaw))
    state["pose"], state["yaw"] = (p.x, p.y), yaw


def on_scan(msg):
    if state["start"] is None:
        return
    valid = [r for r in msg.ranges if r == r and r > msg.range_min]
    right = [r for r in msg.ranges[0:180] if r == r and r > msg.range_min]
    if valid:
        state["scan_min"] = min(state["scan_min"], min(valid))
    if right:
        state["right_min"] = min(state["right_min"], min(right))
        state["right_max"] = max(state["right_max"], min(right))


def on_contacts(msg):
    """Latched, published when the set of touching pairs changes: count each pair's onset."""
    state["contacts"] = max(state["contacts"], 0)
    now = msg.header.stamp.to_sec()
    if state["touch_since"] is not None:
        state["touch_time"] += now - state["touch_since"]
    state["touch_since"] = now if msg.states else None
    pairs = {(c.collision1_name, c.collision2_name) for c in msg.states}
    for robot, model in sorted(pairs - state["touching"]):
        rospy.logwarn("probe: sim %.2f %s touches %s", now, robot, model)
        state["contacts"] += 1
    if state["touching"] and not pairs:
        rospy.loginfo("probe: sim %.2f touching nothing again", now)
    state["touching"] = pairs


def main():
    rospy.init_node("goal_probe", anonymous=True)
    goal = None
    if rospy.has_param("~goal_x"):
        goal = (float(rospy.get_param("~goal_x")), float(rospy.get_param("~goal_y")))
    tolerance = float(rospy.get_param("~tolerance", 0.3))
    timeout = float(rospy.get_param("~timeout", 120.0))
    settle = float(rospy.get_param("~settle", 2.0))
    trace = rospy.get_param("~trace", "")
    rospy.Subscriber("/cmd_vel", Twist, on_cmd)
    rospy.Subscriber("/odom", Odometry, on_odom)
    rospy.Subscriber("/m2wr/laser/scan", LaserScan, on_scan)
    contacts = rospy.Subscriber("/gazebo/contacts", ContactsState, on_contacts)
    rospy.loginfo("probe: waiting for the first non-zero /cmd_vel")
    rate = rospy.Rate(20)
    end = None
    while not rospy.is_shutdown():
        rate.sleep()
        if state["start"] is None or state["pose"] is None:
            continue
        now = rospy.get_time()
        if goal is not None:
            d = math.hypot(goal[0] - state["pose"][0], goal[1] - state["pose"][1])
            state["nearest"] = min(state["nearest"], d)
            if state["reached"] is None and d < tolerance:
                state["reached"] = now - state["start"]
                end = now + settle
        if end is None and now - state["start"] >= timeout:
            end = now
        if end is not None and now >= end:
            break
    if state["contacts"] < 0 and contacts.get_num_connections() > 0:
        state["contacts"] = 0               # published (latched) only when touches change
    if state["touch_since"] is not None:
        state["touch_time"] += rospy.get_time() - state["touch_since"]
    x, y = state["pose"]
    result = "probe: "
    if goal is not None:
        result += "goal (%.2f, %.2f) %s, nearest %.3f m, " % (
            goal[0], goal[1], "reached in %.2f s" % state["reached"] if state["reached"]
            is not None else "NOT reached in %.0f s" % timeout, state["nearest"])
    result += ("end (%.3f, %.3f) yaw %.1f deg after %.2f s, driven %.2f m, turned %.2f rad, "
               "scan min %.3f m, right min %.3f max %.3f m, contacts %d (%.2f s touching)" % (
                   x, y, math.degrees(state["yaw"]), rospy.get_time() - state["start"],
                   state["driven"], state["turn"], state["scan_min"], state["right_min"],
                   state["right_max"], state["contacts"], state["touch_time"]))
    rospy.loginfo(result)
    print(result, flush=True)
    if trace:
        with open(trace, "w") as f:
            f.write("t,x,y,yaw\n")
            f.writelines("%.3f,%.4f,%.4f,%.4f\n" % row for row in state["rows"])


if __name__ == "__main__":
    main()
