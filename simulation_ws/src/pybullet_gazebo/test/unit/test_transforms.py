"""transforms: poses composed and inverted agree with 4x4 homogeneous matrices."""
import math

import numpy as np
import pytest

from pybullet_gazebo.engine.transforms import (Pose, cross, quaternion_from_rpy, rotate,
                                               rotation_matrix, wrap_angle, yaw_from_quaternion)


def homogeneous(pose):
    out = np.eye(4)
    out[:3, :3] = rotation_matrix(pose.orientation)
    out[:3, 3] = pose.position
    return out


POSES = [Pose.from_xyz_rpy(1.0, -2.0, 0.5, 0.3, -0.7, 2.9),
         Pose.from_xyz_rpy(-4.0, 0.25, 3.0, -2.0, 1.2, -0.4),
         Pose.from_xyz_rpy(0.0, 0.0, 0.0, 0.0, 0.0, math.pi)]


def test_rotate_and_cross_agree_with_numpy():
    rng = np.random.default_rng(3)
    for _ in range(20):
        a, b = rng.normal(size=3), rng.normal(size=3)
        assert cross(a, b) == pytest.approx(tuple(np.cross(a, b)), abs=1e-12)
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        assert rotate(tuple(q), tuple(a)) == pytest.approx(tuple(rotation_matrix(q) @ a),
                                                           abs=1e-12)


@pytest.mark.parametrize("a", POSES)
@pytest.mark.parametrize("b", POSES)
def test_compose_and_inverse_are_matrix_products(a, b):
    assert homogeneous(a.compose(b)) == pytest.approx(homogeneous(a) @ homogeneous(b), abs=1e-12)
    assert homogeneous(a.inverse()) == pytest.approx(np.linalg.inv(homogeneous(a)), abs=1e-12)
    assert all(type(v) is float for v in a.compose(b).position + a.inverse().position)


@pytest.mark.parametrize("yaw", [0.0, 0.5, -2.0, math.pi - 1e-6, -math.pi + 1e-6])
def test_yaw_from_quaternion_reads_back_the_heading(yaw):
    assert yaw_from_quaternion(quaternion_from_rpy(0.0, 0.0, yaw)) == pytest.approx(yaw, abs=1e-9)
    # a tilted robot still heads the same way
    assert yaw_from_quaternion(quaternion_from_rpy(0.1, -0.05, yaw)) == pytest.approx(yaw, abs=1e-9)


@pytest.mark.parametrize("angle, wrapped", [(0.0, 0.0), (3 * math.pi / 2, -math.pi / 2),
                                            (-3 * math.pi / 2, math.pi / 2), (7.0, 7.0 - 2 * math.pi)])
def test_wrap_angle(angle, wrapped):
    assert wrap_angle(angle) == pytest.approx(wrapped, abs=1e-12)
