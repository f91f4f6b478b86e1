"""What the demo hears during a run, as a rospy node in its own process.

Topics in:
  /odom (nav_msgs/Odometry)                  the robot's true pose: trajectory (t, x, y, z, q);
                                             its stamps are also the demo's sim clock [s]
  /tf (tf2_msgs/TFMessage)                   instead of /odom with poses_from_tf=BASE_FRAME:
                                             the odom -> BASE_FRAME transform (the batch runner:
                                             /tf's publisher drops nothing under load)
  /m2wr/laser/scan (sensor_msgs/LaserScan)   only over the run's last `scan_window` seconds
                                             of sim time: the last scan, and a count; never
                                             with scan_window=None (the batch runner)
  /rosout (rosgraph_msgs/Log)                obstacle_avoidance.py's case lines (node
                                             /reading_laser): (stamp, text); not with
                                             cases_from_rosout=False (the batch runner
                                             reads them from the controller's log file)
  /gazebo/contacts (gazebo_msgs/ContactsState)  each set of (robot, model) pairs in contact

The loop being measured pays for every connection its publishers serve, so the demo keeps
to what it needs: no /clock (odometry stamps tell the sim time), the case lines from
rosout's aggregate (published by the rosout node, not by the controller), and scans only
at the end. The node itself does not use sim time; every time it records is a message's
own sim stamp.
"""
import threading

import rospy
from gazebo_msgs.msg import ContactsState
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

from ..analysis import summary
from ..names import (CONTACTS_TOPIC, CONTROLLER_NODE, ODOM_TOPIC, ROSOUT_TOPIC, SCAN_TOPIC,
                    TF_TOPIC)


class Recorder:
    """Collects a run's data. Construct with subscribe=False to feed callbacks by hand."""

    def __init__(self, subscribe=True, scan_window=3.0, poses_from_tf=None,
                 cases_from_rosout=True):
        self.sim_time = None               # [s] latest odometry stamp
        self.poses = []                    # (t, x, y, z, qx, qy, qz, qw)
        self.last_scan = None              # sensor_msgs/LaserScan
        self.scans = 0
        self.cases = []                    # (t, text) of the controller's case lines
        self.contacts = []                 # (t, [(robot, model), ...])
        self.contact_messages = 0          # heard since the subscription (restart keeps it)
        self.scan_window = scan_window     # [s] of sim time before the target, or None
        self._subscribe = subscribe
        self._target = None
        self._scan_sub = None
        self.reached = threading.Event()
        self._subscribers = []
        self._base_frame = poses_from_tf
        if subscribe:
            sub = self._subscribers.append
            if poses_from_tf:
                sub(rospy.Subscriber(TF_TOPIC, TFMessage, self.on_tf, queue_size=1000))
            else:
                sub(rospy.Subscriber(ODOM_TOPIC, Odometry, self.on_odom, queue_size=1000))
            if cases_from_rosout:
                sub(rospy.Subscriber(ROSOUT_TOPIC, Log, self.on_log, queue_size=1000))
            sub(rospy.Subscriber(CONTACTS_TOPIC, ContactsState, self.on_contacts,
                                 queue_size=100))

    def restart(self):
        """Forgets everything heard so far (a new run after a reset), keeping the
        subscriptions, whose connections are up already; the scans stop until fire_at's
        window again."""
        if self._scan_sub is not None:
            self._scan_sub.unregister()
            self._scan_sub = None
        self._target = None
        self.reached.clear()
        self.sim_time, self.last_scan, self.scans = None, None, 0
        self.poses, self.cases, self.contacts = [], [], []

    def unregister(self):
        for subscriber in self._subscribers + ([self._scan_sub] if self._scan_sub else []):
            subscriber.unregister()
        self._subscribers, self._scan_sub = [], None

    def fire_at(self, sim_time):
        """`reached` is set once the sim time reaches sim_time [s]; scans are heard from
        scan_window seconds before it."""
        self.reached.clear()
        self._target = sim_time
        self._tick()

    def _tick(self):
        if self._target is None or self.sim_time is None:
            return
        if self.scan_window is not None and self._scan_sub is None and self._subscribe \
                and self.sim_time >= self._target - self.scan_window:
            self._scan_sub = rospy.Subscriber(SCAN_TOPIC, LaserScan, self.on_scan, queue_size=1)
        if self.sim_time >= self._target:
            self.reached.set()

    # --- callbacks ----------------------------------------------------------------------
    def on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        t = msg.header.stamp.to_sec()
        self.poses.append((t, p.x, p.y, p.z, q.x, q.y, q.z, q.w))
        self.sim_time = t if self.sim_time is None else max(self.sim_time, t)
        self._tick()

    def on_tf(self, msg):
        """The odom -> base transform the simulator sends with each odometry message (the
        same pose; /tf's publisher queues 100 where /odom's keeps only the latest)."""
        for transform in msg.transforms:
            if transform.child_frame_id != self._base_frame:
                continue
            p, q = transform.transform.translation, transform.transform.rotation
            t = transform.header.stamp.to_sec()
            self.poses.append((t, p.x, p.y, p.z, q.x, q.y, q.z, q.w))
            self.sim_time = t if self.sim_time is None else max(self.sim_time, t)
            self._tick()

    def on_scan(self, msg):
        self.last_scan = msg
        self.scans += 1

    def on_log(self, msg):
        if msg.name == CONTROLLER_NODE and summary.is_case(msg.msg):
            self.cases.append((msg.header.stamp.to_sec(), msg.msg.strip()))

    def on_contacts(self, msg):
        pairs = [(s.collision1_name, s.collision2_name) for s in msg.states]
        self.contacts.append((msg.header.stamp.to_sec(), pairs))
        self.contact_messages += 1

    # --- views --------------------------------------------------------------------------
    def current_case(self):
        return self.cases[-1][1] if self.cases else ""
