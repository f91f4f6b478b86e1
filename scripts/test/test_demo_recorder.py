"""m2wr_tools.running.recorder: what the demo keeps from each topic (callbacks fed by hand, no
master)."""
import rospy
from gazebo_msgs.msg import ContactsState, ContactState
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import LaserScan

from m2wr_tools.running.recorder import Recorder


def log(name, text, t):
    msg = Log(name=name, msg=text)
    msg.header.stamp = rospy.Time.from_sec(t)
    return msg


def test_only_the_controllers_case_lines_are_kept():
    r = Recorder(subscribe=False)
    r.on_log(log("/reading_laser", "case 1 - nothing", 1.0))
    r.on_log(log("/reading_laser", "{'right': 10}", 1.0))
    r.on_log(log("/gazebo", "case 2 - front", 1.05))
    r.on_log(log("/reading_laser", "case 2 - front", 1.05))
    assert r.cases == [(1.0, "case 1 - nothing"), (1.05, "case 2 - front")]
    assert r.current_case() == "case 2 - front"


def odom_at(t, x=0.0, y=0.0):
    msg = Odometry()
    msg.header.stamp = rospy.Time.from_sec(t)
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.w = 1.0
    return msg


def test_odometry_stamps_fire_the_target_once_reached():
    r = Recorder(subscribe=False)
    r.fire_at(2.0)
    r.on_odom(odom_at(1.95))
    assert not r.reached.is_set() and r.sim_time == 1.95
    r.on_odom(odom_at(2.0))
    assert r.reached.is_set()
    r.on_odom(odom_at(1.0))                 # a late message never moves the clock back
    assert r.sim_time == 2.0
    r.fire_at(1.5)                          # already past: set at once
    assert r.reached.is_set()


def test_odometry_scans_and_contacts():
    r = Recorder(subscribe=False)
    r.on_odom(odom_at(0.05, 1.0, 8.0))
    assert r.poses == [(0.05, 1.0, 8.0, 0.0, 0.0, 0.0, 0.0, 1.0)]
    first, second = LaserScan(), LaserScan()
    r.on_scan(first)
    r.on_scan(second)
    assert r.scans == 2 and r.last_scan is second
    contacts = ContactsState(states=[ContactState(collision1_name="m2wr", collision2_name="wall")])
    contacts.header.stamp = rospy.Time.from_sec(3.0)
    r.on_contacts(contacts)
    r.on_contacts(ContactsState())
    assert r.contacts == [(3.0, [("m2wr", "wall")]), (0.0, [])]
