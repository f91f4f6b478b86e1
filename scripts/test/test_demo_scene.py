"""m2wr_tools.analysis.scene: obstacles cut at scan height, the robot's clearance and link poses, on a
fixture world with obstacles at known places (scripts/test/fixtures/scene.world) and the
project's own m2wr description."""
import math
import os

import numpy as np
import pytest
import xacro

from m2wr_tools.analysis import scene as scene_mod
from m2wr_tools.analysis.scene import Scene, cut_convex, cut_cylinder
from pybullet_gazebo.engine.transforms import Pose, rotation_matrix, quaternion_from_rpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
WORLD = os.path.join(HERE, "fixtures", "scene.world")
XACRO = os.path.join(ROOT, "simulation_ws", "src", "m2wr_description", "urdf", "m2wr.xacro")


@pytest.fixture(scope="module")
def scene():
    s = Scene(WORLD, [], xacro.process_file(XACRO).toxml())
    yield s
    s.close()


def by_model(outlines):
    return {o.model: o for o in outlines}


def test_upright_box_is_cut_into_its_footprint(scene):
    wall = by_model(scene.outlines(0.15))["wall"]
    assert wall.kind == "polygon"
    np.testing.assert_allclose(sorted(wall.points),
                               sorted([(2.9, -2.0), (3.1, -2.0), (3.1, 2.0), (2.9, 2.0)]),
                               atol=1e-6)


def test_turned_box_is_a_rotated_rectangle(scene):
    turned = by_model(scene.outlines(0.15))["turned"]
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    expected = [(-3 + c * dx - s * dy, s * dx + c * dy) for dx, dy in
                ((1, 0.25), (-1, 0.25), (-1, -0.25), (1, -0.25))]
    np.testing.assert_allclose(sorted(turned.points), sorted(expected), atol=1e-6)


def test_cylinder_and_sphere_are_circles_and_low_box_is_not_cut(scene):
    outlines = by_model(scene.outlines(0.15))
    assert outlines["post"].kind == "circle"
    assert outlines["post"].center == pytest.approx((0.0, 3.0))
    assert outlines["post"].radius == pytest.approx(0.25)
    assert outlines["ball"].radius == pytest.approx(math.sqrt(0.3 ** 2 - 0.05 ** 2))
    assert "low" not in outlines                 # 0.1 m tall: below the scan plane
    assert "ground" not in outlines and scene.robot_name not in outlines
    assert "low" in by_model(scene.outlines(0.05))


def test_clearance_to_the_wall_ahead_is_measured_from_the_caster(scene):
    # the caster sphere (r 0.05 at x 0.35) is the robot's front-most shape: 1 + 0.4 = 1.4
    result = scene.clearance([Pose.from_xyz_rpy(1.0, 0.0, 0.1)])
    assert result[0].distance == pytest.approx(1.5, abs=1e-3)
    assert result[0].model == "wall"


def test_penetration_is_negative(scene):
    result = scene.clearance([Pose.from_xyz_rpy(2.55, 0.0, 0.1)])
    assert result[0].distance == pytest.approx(-0.05, abs=1e-3)


def test_wheel_ground_contact_spheres_do_not_count(scene):
    # side-on to the wall: the wheel's outer face (y 0.17) is 0.03 m from it; the engine's
    # ground-contact sphere (r 0.1 at the wheel centre, y 0.15) would reach 0.05 past it
    result = scene.clearance([Pose.from_xyz_rpy(2.7, 0.0, 0.1, 0, 0, math.pi / 2)])
    assert result[0].distance == pytest.approx(0.03, abs=1e-3)


def test_nothing_within_max_distance_is_inf(scene):
    result = scene.clearance([Pose.from_xyz_rpy(30.0, 30.0, 0.1)], max_distance=2.0)
    assert result[0].distance == math.inf and result[0].model == ""


def test_clearance_is_per_pose_in_order(scene):
    poses = [Pose.from_xyz_rpy(x, 0.0, 0.1) for x in (0.5, 1.0, 1.5)]
    distances = [c.distance for c in scene.clearance(poses)]
    assert distances == pytest.approx([2.0, 1.5, 1.0], abs=1e-3)
    assert [c.index for c in scene.clearance(poses)] == [0, 1, 2]


def test_laser_frame_pose(scene):
    pose = scene.frame_pose(Pose.from_xyz_rpy(1.0, 2.0, 0.1, 0, 0, math.pi / 2), "sensor_laser")
    assert pose.position == pytest.approx((1.0, 2.15, 0.15), abs=1e-6)
    assert pose.rpy[2] == pytest.approx(math.pi / 2, abs=1e-6)
    with pytest.raises(KeyError, match="no link 'nope'"):
        scene.frame_pose(Pose(), "nope")


def test_moved_models_follow_and_unknown_names_are_returned(scene):
    unknown = scene.set_model_poses({"post": Pose.from_xyz_rpy(1.0, -1.0, 0.5), "ghost": Pose()})
    try:
        assert unknown == ["ghost"]
        assert by_model(scene.outlines(0.15))["post"].center == pytest.approx((1.0, -1.0))
    finally:
        scene.set_model_poses({"post": Pose.from_xyz_rpy(0.0, 3.0, 0.5)})


def test_rolled_box_cut_is_wider_than_its_thickness():
    # a 0.1 m thick slab rolled 45 deg about x, centred at z 0.5: at z 0.5 the cut spans
    # y = +-0.05 / cos(45 deg) (and x = +-1)
    rotation = rotation_matrix(quaternion_from_rpy(math.pi / 4, 0, 0))
    polygon = cut_convex(scene_mod.box_vertices((0, 0, 0.5), rotation, (2.0, 0.1, 3.0)), 0.5)
    ys = [p[1] for p in polygon]
    assert max(ys) == pytest.approx(0.05 / math.cos(math.pi / 4))
    assert min(ys) == pytest.approx(-0.05 / math.cos(math.pi / 4))
    assert cut_convex(scene_mod.box_vertices((0, 0, 0.5), np.eye(3), (1, 1, 1)), 1.5) == []


def test_tilted_cylinder_is_cut_as_a_polygon():
    rotation = rotation_matrix(quaternion_from_rpy(math.pi / 2, 0, 0))   # axis along y
    outline = cut_cylinder((0, 0, 0.5), rotation, 0.5, 2.0, 0.5, "log")
    assert outline.kind == "polygon"
    xs = [p[0] for p in outline.points]
    ys = [p[1] for p in outline.points]
    assert max(ys) == pytest.approx(1.0) and min(ys) == pytest.approx(-1.0)
    assert max(xs) == pytest.approx(0.5, abs=1e-9)
    assert cut_cylinder((0, 0, 0.5), np.eye(3), 0.5, 0.2, 0.8, "stub") is None


def test_nearest_is_the_closest_of_all_poses_measured_one_by_one(scene):
    # a track that passes the wall ahead closer and closer, then turns away
    poses = [Pose.from_xyz_rpy(x, y, 0.1, 0, 0, yaw) for x, y, yaw in
             [(0.0, 0.0, 0.0), (1.0, 0.5, 0.3), (2.0, -0.5, -0.2), (2.4, 0.0, 1.0),
              (1.5, 1.0, 2.0), (0.5, -1.0, 3.0)]]
    every = scene.clearance(poses)
    best = min(every, key=lambda c: (c.distance, c.index))
    assert scene.nearest(poses) == best
    assert best.index == 3 and best.model
    assert scene.nearest(list(reversed(poses))).distance == best.distance
    assert scene.nearest([]) is None
