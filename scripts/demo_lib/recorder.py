"""What the demo (and the benchmark) hear during a run, as a rospy node in their own process.

Topics in:
  /clock (rosgraph_msgs/Clock)               latest sim time [s]; `reached` fires at a target
  /odom (nav_msgs/Odometry)                  the robot's true pose: trajectory (t, x, y, z, q)
  /m2wr/laser/scan (sensor_msgs/LaserScan)   the latest scan; a count
  /cmd_vel (geometry_msgs/Twist)             a count (the controller's answers), if asked
  /rosout (rosgraph_msgs/Log)                obstacle_avoidance.py's case lines (node
                                             /reading_laser): (stamp, text)
  /gazebo/contacts (gazebo_msgs/ContactsState)  each set of (robot, model) pairs in contact

The node does not use sim time itself (it is started before /use_sim_time is set); every
time it records is a message's own sim stamp or /clock's value.
"""
import threading

import rospy
from gazebo_msgs.msg import ContactsState
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock, Log
from sensor_msgs.msg import LaserScan

from . import summary

CONTROLLER_NODE = "/reading_laser"


class Recorder:
    """Collects a run's data. Construct with subscribe=False to feed callbacks by hand."""

    def __init__(self, subscribe=True, scan_topic="/m2wr/laser/scan", odom_topic="/odom",
                 count_commands=False, record_odom=True, record_rosout=True):
        self.sim_time = None               # [s] latest /clock
        self.poses = []                    # (t, x, y, z, qx, qy, qz, qw)
        self.last_scan = None              # sensor_msgs/LaserScan
        self.scans = 0
        self.commands = 0
        self.cases = []                    # (t, text) of the controller's case lines
        self.contacts = []                 # (t, [(robot, model), ...])
        self._target = None
        self.reached = threading.Event()
        self._subscribers = []
        if subscribe:
            sub = self._subscribers.append
            sub(rospy.Subscriber("/clock", Clock, self.on_clock, queue_size=1))
            sub(rospy.Subscriber(scan_topic, LaserScan, self.on_scan, queue_size=1))
            if record_odom:
                sub(rospy.Subscriber(odom_topic, Odometry, self.on_odom, queue_size=1000))
            if record_rosout:
                sub(rospy.Subscriber("/rosout", Log, self.on_log, queue_size=1000))
            sub(rospy.Subscriber("/gazebo/contacts", ContactsState, self.on_contacts,
                                 queue_size=100))
            if count_commands:
                sub(rospy.Subscriber("/cmd_vel", Twist, self.on_command, queue_size=1000))

    def unregister(self):
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers = []

    def fire_at(self, sim_time):
        """`reached` is set once /clock reaches sim_time [s]."""
        self.reached.clear()
        self._target = sim_time
        if self.sim_time is not None and self.sim_time >= sim_time:
            self.reached.set()

    # --- callbacks ----------------------------------------------------------------------
    def on_clock(self, msg):
        self.sim_time = msg.clock.to_sec()
        if self._target is not None and self.sim_time >= self._target:
            self.reached.set()

    def on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        self.poses.append((msg.header.stamp.to_sec(), p.x, p.y, p.z, q.x, q.y, q.z, q.w))

    def on_scan(self, msg):
        self.last_scan = msg
        self.scans += 1

    def on_command(self, _msg):
        self.commands += 1

    def on_log(self, msg):
        if msg.name == CONTROLLER_NODE and summary.is_case(msg.msg):
            self.cases.append((msg.header.stamp.to_sec(), msg.msg.strip()))

    def on_contacts(self, msg):
        pairs = [(s.collision1_name, s.collision2_name) for s in msg.states]
        self.contacts.append((msg.header.stamp.to_sec(), pairs))

    # --- views --------------------------------------------------------------------------
    def current_case(self):
        return self.cases[-1][1] if self.cases else ""
