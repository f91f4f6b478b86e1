"""Engine data <-> ROS messages. Every message of one step carries the same stamp."""
import io
import math
import struct

import numpy as np
import rospy
from geometry_msgs.msg import Point, Pose as PoseMsg, Quaternion, TransformStamped, Twist, Vector3
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from pybullet_gazebo.engine.transforms import Pose


def stamp_of_world(world):
    """rospy.Time of the world's sim time, in integer nanoseconds so it never drifts, also
    across a change of the time step (see World.sim_time_ns)."""
    total = world.sim_time_ns()
    return rospy.Time(total // 1000000000, total % 1000000000)


def pose_to_msg(pose):
    return PoseMsg(Point(*pose.position), Quaternion(*pose.orientation))


def pose_from_msg(msg, zero_quaternion_is_identity=False):
    q = (msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w)
    if zero_quaternion_is_identity and all(v == 0.0 for v in q):
        q = (0.0, 0.0, 0.0, 1.0)
    return Pose((msg.position.x, msg.position.y, msg.position.z), q)


def twist_to_msg(linear, angular):
    return Twist(Vector3(*[float(v) for v in linear]), Vector3(*[float(v) for v in angular]))


def is_finite_twist(msg):
    values = (msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x, msg.angular.y, msg.angular.z)
    return all(math.isfinite(v) for v in values)


class ScanMessage(LaserScan):
    """A sensor_msgs/LaserScan (same type, md5sum and bytes on the wire) whose `ranges` may
    stay the engine's float32 array: written with one tobytes() instead of genpy's
    tolist() and struct.pack(*ranges), ~30 us of the loop's ~1 ms per scan."""
    __slots__ = ()

    def serialize(self, buff):
        ranges, intensities = self.ranges, self.intensities
        self.ranges, self.intensities = (), ()
        try:
            head = io.BytesIO()
            LaserScan.serialize(self, head)     # everything before the two arrays, then
        finally:                                # their lengths (0, 0): 8 bytes
            self.ranges, self.intensities = ranges, intensities
        buff.write(head.getvalue()[:-8])
        for values in (ranges, intensities):
            data = np.asarray(values, dtype="<f4")
            buff.write(struct.pack("<I", len(data)))
            buff.write(data.tobytes())


def scan_to_msg(scan, stamp, frame_id):
    """frame_id: the scan's frame as the ROS side resolved it."""
    msg = ScanMessage()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.angle_min = scan.angle_min
    msg.angle_max = scan.angle_max
    msg.angle_increment = scan.angle_increment
    msg.time_increment = scan.time_increment
    msg.scan_time = scan.scan_time
    msg.range_min = scan.range_min
    msg.range_max = scan.range_max
    msg.ranges = scan.ranges
    return msg


def odometry_to_msgs(odometry, drive, stamp, frames):
    """(nav_msgs/Odometry, TransformStamped odom -> base) as gazebo_ros_diff_drive sends.
    frames: (odometry frame, base frame) as the ROS side resolved them."""
    odometry_frame, base_frame = frames
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = odometry_frame
    msg.child_frame_id = base_frame
    msg.pose.pose = pose_to_msg(odometry.pose)
    msg.twist.twist = twist_to_msg(odometry.linear, odometry.angular)
    transform = TransformStamped()
    transform.header = msg.header
    transform.child_frame_id = base_frame
    transform.transform.translation = Vector3(*odometry.pose.position)
    transform.transform.rotation = Quaternion(*odometry.pose.orientation)
    return msg, transform
