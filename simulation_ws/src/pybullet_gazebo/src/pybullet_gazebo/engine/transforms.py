"""Rigid transforms in numpy, quaternions in pybullet's (x, y, z, w) order.

Gazebo's SDF poses are `x y z roll pitch yaw` with fixed-axis (extrinsic X, then Y, then Z)
angles, the same convention as URDF's `rpy` and pybullet's getQuaternionFromEuler.
"""
from dataclasses import dataclass
import math

import numpy as np


def quaternion_from_rpy(roll, pitch, yaw):
    """(x, y, z, w) of the rotation Rz(yaw) * Ry(pitch) * Rx(roll)."""
    cr, sr = math.cos(roll / 2.0), math.sin(roll / 2.0)
    cp, sp = math.cos(pitch / 2.0), math.sin(pitch / 2.0)
    cy, sy = math.cos(yaw / 2.0), math.sin(yaw / 2.0)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def rpy_from_quaternion(q):
    """(roll, pitch, yaw) [rad] of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch, yaw_from_quaternion(q)


def yaw_from_quaternion(q):
    """Yaw [rad] (heading about z) of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def wrap_angle(angle):
    """`angle` [rad] wrapped into (-pi, pi]."""
    return math.atan2(math.sin(angle), math.cos(angle))


def rotation_matrix(q):
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def cross(a, b):
    """Cross product of two 3-vectors, as a tuple (np.cross spends ~15 us on one pair)."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def rotate(q, v):
    """The 3-vector v rotated by the unit quaternion q (x, y, z, w), as a tuple of floats:
    v + 2 w (u x v) + 2 u x (u x v), u the vector part."""
    u, w = q[:3], q[3]
    t = cross(u, v)
    t = (2.0 * t[0], 2.0 * t[1], 2.0 * t[2])
    c = cross(u, t)
    return (float(v[0] + w * t[0] + c[0]), float(v[1] + w * t[1] + c[1]),
            float(v[2] + w * t[2] + c[2]))


def quaternion_multiply(a, b):
    """Hamilton product a * b of (x, y, z, w) quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


@dataclass(frozen=True)
class Pose:
    """A rigid transform: position [m] and orientation quaternion (x, y, z, w)."""
    position: tuple = (0.0, 0.0, 0.0)
    orientation: tuple = (0.0, 0.0, 0.0, 1.0)

    @staticmethod
    def from_xyz_rpy(x=0.0, y=0.0, z=0.0, roll=0.0, pitch=0.0, yaw=0.0):
        return Pose((float(x), float(y), float(z)), quaternion_from_rpy(roll, pitch, yaw))

    @staticmethod
    def parse_sdf(text):
        """Pose from SDF's `x y z roll pitch yaw` text (missing values are 0).

        Raises ValueError naming the text when it is not six numbers."""
        parts = (text or "").split()
        if len(parts) not in (0, 6):
            raise ValueError("pose '%s' must be six numbers: x y z roll pitch yaw" % text)
        try:
            values = [float(p) for p in parts] or [0.0] * 6
        except ValueError:
            raise ValueError("pose '%s' must be six numbers: x y z roll pitch yaw" % text)
        if not all(math.isfinite(v) for v in values):
            raise ValueError("pose '%s' has a non-finite value" % text)
        return Pose.from_xyz_rpy(*values)

    @property
    def rpy(self):
        return rpy_from_quaternion(self.orientation)

    @property
    def matrix(self):
        return rotation_matrix(self.orientation)

    def compose(self, other):
        """self * other: `other` expressed in self's frame, returned in self's parent frame."""
        moved = rotate(self.orientation, other.position)
        p = self.position
        return Pose((float(p[0]) + moved[0], float(p[1]) + moved[1], float(p[2]) + moved[2]),
                    quaternion_multiply(self.orientation, other.orientation))

    def inverse(self):
        x, y, z, w = self.orientation
        conj = (-x, -y, -z, w)
        moved = rotate(conj, self.position)
        return Pose((-moved[0], -moved[1], -moved[2]), conj)

    def transform_point(self, point):
        return np.asarray(self.position) + self.matrix @ np.asarray(point, dtype=float)
