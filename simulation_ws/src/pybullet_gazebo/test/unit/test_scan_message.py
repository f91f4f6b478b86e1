"""The scan message the simulator publishes (conversions.ScanMessage) is a
sensor_msgs/LaserScan on the wire: the same bytes genpy writes for the same values, read
back as the ranges the engine measured, +inf (no return) and NaN included."""
import io
from types import SimpleNamespace

import numpy as np
import rospy
from sensor_msgs.msg import LaserScan

from pybullet_gazebo.ros.conversions import ScanMessage, scan_to_msg


def engine_scan(ranges):
    return SimpleNamespace(angle_min=-1.5707963, angle_max=1.5707963,
                           angle_increment=np.pi / 719, time_increment=0.0, scan_time=0.0,
                           range_min=0.1, range_max=10.0, ranges=ranges)


def genpy_bytes(scan, stamp, frame_id, intensities=()):
    msg = LaserScan()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.angle_min, msg.angle_max = scan.angle_min, scan.angle_max
    msg.angle_increment, msg.time_increment = scan.angle_increment, scan.time_increment
    msg.scan_time, msg.range_min, msg.range_max = scan.scan_time, scan.range_min, scan.range_max
    msg.ranges = scan.ranges.tolist()
    msg.intensities = list(intensities)
    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


def our_bytes(msg):
    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


def test_same_type_and_md5sum_as_laserscan():
    assert ScanMessage._type == LaserScan._type == "sensor_msgs/LaserScan"
    assert ScanMessage._md5sum == LaserScan._md5sum


def test_same_bytes_as_genpy_and_read_back_unchanged():
    ranges = np.linspace(0.12, 9.9, 720).astype(np.float32)
    ranges[10], ranges[20] = np.inf, np.nan
    scan, stamp = engine_scan(ranges), rospy.Time(12, 345000000)
    msg = scan_to_msg(scan, stamp, "sensor_laser")
    data = our_bytes(msg)
    assert data == genpy_bytes(scan, stamp, "sensor_laser")
    back = LaserScan()
    back.deserialize(data)
    assert back.header.stamp == stamp and back.header.frame_id == "sensor_laser"
    np.testing.assert_array_equal(np.array(back.ranges, np.float32), ranges)
    assert len(back.intensities) == 0
    # serializing leaves the message as it was (the loop may publish it again)
    assert msg.ranges is ranges and our_bytes(msg) == data


def test_intensities_and_another_frame():
    ranges = np.full(5, 2.5, np.float32)
    scan, stamp = engine_scan(ranges), rospy.Time(1, 0)
    msg = scan_to_msg(scan, stamp, frame_id="m2wr/sensor_laser")
    msg.intensities = [0.0, 1.0, 2.0, 3.0, 4.0]
    assert our_bytes(msg) == genpy_bytes(scan, stamp, "m2wr/sensor_laser",
                                         intensities=[0.0, 1.0, 2.0, 3.0, 4.0])
