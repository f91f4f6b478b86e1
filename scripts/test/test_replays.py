"""A run's replay (m2wr_tools.analysis.replays): its frames put m2wr where the track says, turn
its wheels by the distance they rolled, and cast its laser from there."""
import math

import numpy as np
import pytest

from m2wr_tools import paths
from m2wr_tools.analysis import replays
from m2wr_tools.analysis.scene import Scene

SPEED = 0.3                 # [m/s] straight ahead
WHEEL_RADIUS = 0.1          # [m] m2wr's (m2wr.xacro)


@pytest.fixture(scope="module")
def frames():
    urdf = paths.robot_urdf()
    scene = Scene.of_world("world02", urdf)
    try:
        # east from (0, 8) for 0.5 s: 0.15 m, 1.5 rad of each wheel, less than half a turn
        track = [(0.05 * k, SPEED * 0.05 * k, 8.0, 0.1, 0.0, 0.0, 0.0, 1.0) for k in range(11)]
        replay = replays.build(scene, urdf, track, "straight east")
    finally:
        scene.close()
    return replay["frames"]


def _wheel_angle(frame, link):
    """The wheel's rotation about the world's y axis [rad] (m2wr faces +x: axles along y)."""
    qx, qy, qz, qw = frame["robots"]["m2wr"]["links"][link][3:7]
    return 2.0 * math.atan2(qy, qw)


def test_frames_follow_the_track(frames):
    assert [f["t"] for f in frames] == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
    xs = [f["robots"]["m2wr"]["pose"][0] for f in frames]
    assert xs == pytest.approx([SPEED * f["t"] for f in frames], abs=1e-4)


def test_wheels_turn_by_the_distance_rolled(frames):
    # rolling east, a wheel turns about +y (its top moving forward) by distance / radius
    for link in ("link_left_wheel", "link_right_wheel"):
        turned = _wheel_angle(frames[-1], link) - _wheel_angle(frames[0], link)
        assert turned == pytest.approx(SPEED * 0.5 / WHEEL_RADIUS, abs=0.01), link


def test_the_laser_is_cast_from_where_the_robot_is(frames):
    for frame in frames:
        hits = frame["hits"]["m2wr"]
        x = frame["robots"]["m2wr"]["pose"][0]
        assert hits["from"][0] == pytest.approx(x + 0.15, abs=0.05)     # the laser's mount
        points = np.asarray(hits["points"]).reshape(-1, 3)
        assert len(points) > 50
        reach = np.hypot(points[:, 0] - hits["from"][0], points[:, 1] - hits["from"][1])
        assert reach.max() <= 30.0 + 1e-6 and reach.min() > 0.05
