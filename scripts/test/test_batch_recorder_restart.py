"""m2wr_tools.running.recorder.Recorder.restart: the batch's one recorder per rig forgets a run's
data before the next run (callbacks fed by hand, no master)."""
import rospy
from gazebo_msgs.msg import ContactsState, ContactState
from nav_msgs.msg import Odometry

from m2wr_tools.running.recorder import Recorder


def odom_at(t, x=0.0):
    msg = Odometry()
    msg.header.stamp = rospy.Time.from_sec(t)
    msg.pose.pose.position.x = x
    msg.pose.pose.orientation.w = 1.0
    return msg


def test_a_restarted_recorder_keeps_nothing_of_the_run_before():
    r = Recorder(subscribe=False)
    r.fire_at(2.0)
    r.on_odom(odom_at(2.0, x=5.0))
    touching = ContactsState(states=[ContactState(collision1_name="m2wr::link_chassis",
                                                  collision2_name="wall::link")])
    touching.header.stamp = rospy.Time.from_sec(1.5)
    r.on_contacts(touching)
    assert r.reached.is_set() and r.poses and r.contacts
    r.restart()
    assert not r.reached.is_set() and r.sim_time is None
    assert r.poses == [] and r.contacts == [] and r.cases == [] and r.scans == 0
    r.fire_at(1.0)                      # the next run: sim time starts again from 0
    r.on_odom(odom_at(0.5, x=1.0))
    assert not r.reached.is_set() and r.poses[0][1] == 1.0
    r.on_odom(odom_at(1.0, x=1.1))
    assert r.reached.is_set()
