"""engine/planar.py: the convex hull the gym's footprints and the demo's scene cuts share."""
import math

import numpy as np
import pytest

from pybullet_gazebo.engine.planar import convex_hull
from pybullet_gazebo.engine.transforms import quaternion_from_rpy, rotation_matrix


def cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def test_convex_hull_drops_inner_and_collinear_points():
    points = [(0, 0), (2, 0), (1, 0), (2, 2), (0, 2), (1, 1)]
    assert convex_hull(points) == [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]


def test_a_rotated_box_seen_from_above_is_its_four_corners():
    # the 8 corners of a 2 x 1 x 0.5 box yawed 30 deg: top and bottom corners meet from
    # above up to rounding noise; the hull is the 4 corners of the footprint
    rotation = rotation_matrix(quaternion_from_rpy(0, 0, math.radians(30)))
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    corners = (signs * [1.0, 0.5, 0.25]) @ rotation.T + [3.0, -1.0, 0.25]
    hull = convex_hull(corners[:, :2], decimals=9)
    assert len(hull) == 4
    expected = {(round(x, 9), round(y, 9)) for x, y in corners[:, :2]}
    assert set(hull) == expected
    area = 0.5 * sum(cross((0, 0), hull[i], hull[(i + 1) % 4]) for i in range(4))
    assert area == pytest.approx(2.0 * 1.0)          # counter-clockwise: positive


@pytest.mark.parametrize("seed", range(20))
def test_every_point_is_inside_and_every_corner_turns_left(seed):
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(int(rng.integers(3, 80)), 2)).round(int(rng.integers(1, 6)))
    hull = convex_hull(points)
    n = len(hull)
    assert n >= 3
    for i in range(n):                 # strictly convex, counter-clockwise
        assert cross(hull[i], hull[(i + 1) % n], hull[(i + 2) % n]) > 0
    for p in points:                   # nothing outside any edge
        assert all(cross(hull[i], hull[(i + 1) % n], p) >= -1e-9 for i in range(n))
    assert set(hull) <= {(float(x), float(y)) for x, y in points}


def test_fewer_than_three_distinct_points_come_back_sorted():
    assert convex_hull([(1, 1), (0, 0), (1, 1)]) == [(0.0, 0.0), (1.0, 1.0)]
    assert convex_hull([]) == []
