"""Mesh collisions in world files, from the file to Bullet and the laser: OBJ/STL/DAE box
meshes made here at known poses (exact ranges, solid bodies), URI resolution, the primitive
stand-in for a missing model:// mesh, and world03 from our file and from a file with the
structure of the series' own (barrels as inline models with a mesh collision)."""
import math
import os

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import mesh_files
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.specs import Cylinder, Mesh, TriangleMesh
from pybullet_gazebo.engine.world import World

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
STOCK_MODELS = os.path.join(SRC, "pybullet_gazebo", "models")
MY_WORLDS = os.path.join(SRC, "my_worlds", "worlds")
SERIES_WORLD03 = os.path.join(HERE, "..", "fixtures", "sdf_world", "worlds",
                              "series_world03_structure.world")
STEP = 0.005

# a 1 x 2 x 1 m box as 8 vertices and 12 outward triangles, centred on its origin
BOX_VERTICES = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-1.0, 1.0) for z in (-0.5, 0.5)])
BOX_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def write_box(folder, fmt):
    path = os.path.join(str(folder), "box." + fmt)
    if fmt == "obj":
        mesh_files.write_obj(path, BOX_VERTICES, BOX_FACES)
    else:
        import trimesh
        trimesh.Trimesh(BOX_VERTICES, BOX_FACES, process=False).export(path)
    return path


WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="meshes">
  <model name="ground_plane"><static>true</static><link name="link"><collision name="c">
    <geometry><plane><normal>0 0 1</normal></plane></geometry></collision></link></model>
  %s
</world></sdf>"""
MODEL = """<model name="%(name)s"><static>%(static)s</static><pose>%(pose)s</pose>
  <link name="link"><inertial><mass>10</mass></inertial>
    <collision name="hull"><pose>%(cpose)s</pose><geometry><mesh><uri>%(uri)s</uri>
      <scale>%(scale)s</scale></mesh></geometry></collision></link></model>"""


def model(name, uri, static="true", pose="0 0 0 0 0 0", cpose="0 0 0 0 0 0", scale="1 1 1"):
    return MODEL % dict(name=name, uri=uri, static=static, pose=pose, cpose=cpose, scale=scale)


@pytest.fixture
def make_world(tmp_path):
    clients = []

    def make(models_xml, model_path=(STOCK_MODELS,)):
        path = tmp_path / "test.world"
        path.write_text(WORLD % models_xml)
        spec = load_world(str(path), list(model_path))
        client = BulletClient(connection_mode=pybullet.DIRECT)
        clients.append(client)
        warnings = []
        world = World(client, spec, STEP, warn=warnings.append)
        world.warnings = warnings
        return world
    yield make
    for client in clients:
        client.disconnect()


def cast(world, origin, directions, range_max=10.0):
    return world.caster.cast(origin, np.asarray(directions, dtype=float), 0.0, range_max)


def bullet_range(world, origin, direction, length=10.0):
    end = np.asarray(origin) + length * np.asarray(direction)
    hit = world.client.rayTest(origin, end.tolist())[0]
    return hit[2] * length if hit[0] >= 0 else math.inf


# --- meshes that resolve: Bullet and the laser see them ------------------------------------
@pytest.mark.parametrize("fmt", ["obj", "stl", "dae"])
def test_static_box_mesh_gives_the_exact_range(tmp_path, make_world, fmt):
    """The box's near face is at x = 3 - 0.5 * 1.5 (scale) = 2.25 m from the origin."""
    path = write_box(tmp_path, fmt)
    world = make_world(model("boxy", "file://" + path, pose="3 0 0.5 0 0 0", scale="1.5 1 1"))
    assert world.warnings == []
    (collision,) = world.spec.models[1].links[0].collisions
    assert isinstance(collision.geometry, TriangleMesh)
    ranges = cast(world, (0.0, 0.0, 0.5), [(1, 0, 0), (1, 0.3, 0), (0, 1, 0), (1, 0.5, 0)])
    assert ranges[0] == pytest.approx(2.25, abs=1e-9)
    assert ranges[1] == pytest.approx(2.25 * math.hypot(1, 0.3), abs=1e-9)
    assert ranges[2] == math.inf
    assert ranges[3] == math.inf                     # passes the near face's corner y = 1
    assert cast(world, (3.5, -3.0, 0.5), [(0, 1, 0)])[0] == pytest.approx(2.0, abs=1e-9)
    assert cast(world, (3.5, -3.0, 1.01), [(0, 1, 0)])[0] == math.inf  # over the top
    # Bullet's own collision shape is where the laser sees it (its ray test has ~1e-4 slack)
    for direction, expected in zip([(1, 0, 0), (1, 0.3, 0)], ranges):
        unit = np.array(direction) / np.linalg.norm(direction)
        assert bullet_range(world, (0.0, 0.0, 0.5), unit) == pytest.approx(expected, abs=2e-3)


def test_mesh_pose_link_pose_and_turn_are_applied(tmp_path, make_world):
    """Model at (0, 4) turned 90 deg, the collision 0.5 m up: the box's long side (2 m) now
    lies along x, its near face at y = 4 - 0.5."""
    path = write_box(tmp_path, "obj")
    world = make_world(model("boxy", path, pose="0 4 0 0 0 1.5707963267948966",
                             cpose="0 0 0.5 0 0 0"))
    ranges = cast(world, (0.0, 0.0, 0.5), [(0, 1, 0), (0.9 / 3.5, 1, 0), (1.1 / 3.5, 1, 0)])
    assert ranges[0] == pytest.approx(3.5, abs=1e-9)
    assert ranges[1] == pytest.approx(math.hypot(0.9, 3.5), abs=1e-9)
    assert ranges[2] == math.inf                     # past the box's end at x = 1


def test_dynamic_mesh_is_a_solid_convex_hull(tmp_path, make_world):
    """A dynamic box mesh dropped from 1 m rests on the ground on its 1 m tall side, and the
    laser follows it; a sphere thrown at a static mesh box does not go through."""
    path = write_box(tmp_path, "stl")
    world = make_world(model("falling", path, static="false", pose="0 3 1.5 0 0 0")
                       + model("wall", path, pose="-3 0 0.5 0 0 0"))
    for _ in range(int(2.0 / STEP)):
        world.step()
    pose = world.model_pose("falling")
    assert pose.position[2] == pytest.approx(0.5, abs=0.01)
    assert cast(world, (pose.position[0], 0.0, 0.5), [(0, 1, 0)])[0] == pytest.approx(
        pose.position[1] - 1.0, abs=1e-3)
    client = world.client
    ball = client.createMultiBody(1.0, client.createCollisionShape(pybullet.GEOM_SPHERE,
                                                                   radius=0.1),
                                  basePosition=[-1.0, 0.0, 0.5])
    client.resetBaseVelocity(ball, [-5.0, 0.0, 0.0])
    for _ in range(int(1.0 / STEP)):
        client.stepSimulation()
        assert client.getBasePositionAndOrientation(ball)[0][0] > -2.5 - 0.1 - 0.02


# --- URIs ------------------------------------------------------------------------------------
def test_uris_resolve_on_the_model_path_file_and_relative(tmp_path):
    models = tmp_path / "models"
    (models / "thing" / "meshes").mkdir(parents=True)
    path = write_box(models / "thing" / "meshes", "obj")
    base = str(tmp_path)
    assert mesh_files.resolve("model://thing/meshes/box.obj", [str(models)], base) == path
    assert mesh_files.resolve("file://" + path, [], "/") == path
    assert mesh_files.resolve("models/thing/meshes/box.obj", [], base) == path
    assert mesh_files.resolve(path, [], "/") == path
    assert mesh_files.resolve("model://thing/meshes/nope.obj", [str(models)], base) is None
    assert mesh_files.resolve("package://no_such_package_here/x.obj", [], base) is None
    assert mesh_files.model_name("model://thing/meshes/box.obj") == "thing"
    assert mesh_files.model_name("file:///x.obj") is None


def test_unreadable_mesh_file_is_reported_and_left_out(tmp_path, make_world):
    broken = tmp_path / "broken.stl"
    broken.write_text("solid nothing\nendsolid nothing\n")
    world = make_world(model("broken", str(broken)))
    assert "broken" not in world.model_names()
    assert any("model 'broken'" in w and str(broken) in w for w in world.spec.warnings)


def test_missing_mesh_without_a_stand_in_is_dropped_with_a_warning(make_world):
    world = make_world(model("ghost", "model://no_such_model/meshes/ghost.dae"))
    assert "ghost" not in world.model_names()
    (warning,) = [w for w in world.spec.warnings if "ghost" in w]
    assert warning.startswith("model 'ghost':")
    assert "model://no_such_model/meshes/ghost.dae" in warning
    assert any("model 'ghost' has no collision" in w for w in world.warnings)


# --- the stand-in for a missing model:// mesh -------------------------------------------------
def test_missing_barrel_mesh_takes_the_stand_in_cylinder_scaled_and_placed(make_world):
    """Our construction_barrel is a cylinder r 0.3, h 1 standing on its origin: at scale
    (2, 2, 0.5) and model pose (4, 0, 0) the laser at z 0.2 sees it at 4 - 0.6."""
    world = make_world(model("Construction Barrel",
                             "model://construction_barrel/meshes/construction_barrel.dae",
                             static="false", pose="4 0 0 0 0 0", scale="2 2 0.5"))
    (collision,) = world.spec.models[1].links[0].collisions
    assert collision.geometry == Cylinder(radius=0.6, length=0.5)
    assert collision.pose.position == pytest.approx((0.0, 0.0, 0.25))
    (warning,) = world.spec.warnings
    assert "Construction Barrel" in warning and "model://construction_barrel" in warning
    assert cast(world, (0.0, 0.0, 0.2), [(1, 0, 0)])[0] == pytest.approx(3.4, abs=1e-9)
    assert cast(world, (0.0, 0.0, 0.6), [(1, 0, 0)])[0] == math.inf     # above it


# --- world03 ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def world03_specs():
    ours = load_world(os.path.join(MY_WORLDS, "world03.world"), model_path_from_env(STOCK_MODELS))
    series = load_world(SERIES_WORLD03, [STOCK_MODELS])
    return ours, series


def world_of(spec):
    client = BulletClient(connection_mode=pybullet.DIRECT)
    return World(client, spec, STEP, warn=lambda m: None), client


def test_world03_has_32_models_from_either_file(world03_specs):
    ours, series = world03_specs
    assert ours.warnings == ()
    assert len(ours.models) == len(series.models) == 32
    barrels = [m for m in series.models if m.name.startswith("Construction Barrel")]
    assert [m.name for m in barrels] == ["Construction Barrel"] + [
        "Construction Barrel_%d" % i for i in range(6)]
    for barrel in barrels:                      # each: the stand-in's cylinder, dynamic
        assert not barrel.static
        assert [c.geometry for c in barrel.links[0].collisions] == [Cylinder(0.3, 1.0)]
    assert sum("model://construction_barrel" in w for w in series.warnings) == 7
    assert not any(isinstance(c.geometry, Mesh) for m in series.models for link in m.links
                   for c in link.collisions)


def barrel_and_barrier_rays():
    """(origin, direction, expected range [m]) from tutorial_worlds.md's layout."""
    return [
        ((0.0, 8.0, 0.6), (0, -1, 0), 8.0 - 2.936 - 0.3063 / 2),        # barrier b, upright
        ((0.0, 8.0, 0.6), (0, 1, 0), 9.36 - 0.3063 / 2 - 8.0),          # north wall
        ((6.13, 8.42, 0.5), (1, 0, 0), 2.0 - 0.3),                      # corner barrel
        ((-4.0, -9.57, 0.5), (-1, 0, 0), 8.13 - 4.0 - 0.3),             # SW barrel
        ((1.5, 1.0, 0.6), (0, -1, 0), 1.0 + 0.501 - 0.3063 / 2),        # barrier d
    ]


@pytest.mark.parametrize("which", [0, 1])
def test_world03_ranges_match_the_layout_in_both_files(world03_specs, which):
    world, client = world_of(world03_specs[which])
    try:
        for origin, direction, expected in barrel_and_barrier_rays():
            assert cast(world, origin, [direction])[0] == pytest.approx(expected, abs=1e-6), \
                (origin, direction)
    finally:
        client.disconnect()


def test_series_world03_barrels_are_solid_to_a_moving_body(world03_specs):
    """A 2 kg ball thrown at 4 m/s at the corner barrel at (8.13, 8.42) bounces off its side."""
    world, client = world_of(world03_specs[1])
    try:
        ball = client.createMultiBody(2.0, client.createCollisionShape(
            pybullet.GEOM_SPHERE, radius=0.1), basePosition=[7.0, 8.42, 0.6])
        client.resetBaseVelocity(ball, [4.0, 0.0, 0.0])
        farthest = 0.0
        for _ in range(int(1.0 / STEP)):
            world.step()
            farthest = max(farthest, client.getBasePositionAndOrientation(ball)[0][0])
        assert farthest + 0.1 <= 8.13 - 0.3 + 0.03          # 0.02 m per step at 4 m/s
        assert client.getBaseVelocity(ball)[0][0] < 0.0                 # on its way back
    finally:
        client.disconnect()
