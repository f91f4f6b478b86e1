"""sdf_world: fixture worlds for <include> resolution, <state>, pose composition, the choice of
<physics>, unsupported elements and errors; then the tutorial's world01 and world02 (with our
stock models) against the reference layout, the barrier's profile at the laser's height and
the robot's start at (0, 8)."""
import math
import os

import numpy as np
import pytest

from pybullet_gazebo.engine.sdf_world import (WorldFileError, find_world, load_world,
                                              model_path_from_env)
from pybullet_gazebo.engine.specs import Box, Cylinder, Mesh, Plane, Sphere

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURES = os.path.normpath(os.path.join(HERE, "..", "fixtures", "sdf_world"))
FIXTURE_WORLDS = os.path.join(FIXTURES, "worlds")
FIXTURE_MODELS = os.path.join(FIXTURES, "models")
EXTRA_MODELS = os.path.join(FIXTURES, "extra_models")
SRC = os.path.normpath(os.path.join(HERE, "..", "..", ".."))        # simulation_ws/src
MY_WORLDS = os.path.join(SRC, "my_worlds", "worlds")
STOCK_MODELS = os.path.join(SRC, "pybullet_gazebo", "models")
HALF_PI = math.pi / 2.0


def fixture_world(name):
    return os.path.join(FIXTURE_WORLDS, name + ".world")


# --- independent geometry helpers (plain matrices, not Pose.compose) ---------------------------
def homogeneous(x, y, z, roll, pitch, yaw):
    """4x4 of an SDF pose: translation, then Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch),
                              math.sin(pitch), math.cos(yaw), math.sin(yaw))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    matrix = np.eye(4)
    matrix[:3, :3] = rz @ ry @ rx
    matrix[:3, 3] = (x, y, z)
    return matrix


def as_matrix(pose):
    matrix = np.eye(4)
    matrix[:3, :3] = pose.matrix
    matrix[:3, 3] = pose.position
    return matrix


def collision_matrix(model, link, collision):
    return as_matrix(model.pose) @ as_matrix(link.pose) @ as_matrix(collision.pose)


def box_corners(model, link, collision):
    """The 8 world corners of a box collision, shape (8, 3)."""
    half = np.array(collision.geometry.size) / 2.0
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    local = np.hstack([signs * half, np.ones((8, 1))])
    return (collision_matrix(model, link, collision) @ local.T).T[:, :3]


def convex_hull(points):
    """Counter-clockwise convex hull of 2D points (monotone chain)."""
    points = sorted(set((round(float(x), 12), round(float(y), 12)) for x, y in points))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower, upper = [], []
    for p in points:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(points):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return [np.array(p) for p in lower[:-1] + upper[:-1]]


def distance_to_polygon(point, polygon):
    """Distance [m] from a 2D point to a convex counter-clockwise polygon (0 inside)."""
    point = np.asarray(point, dtype=float)
    inside, best = True, math.inf
    for a, b in zip(polygon, polygon[1:] + polygon[:1]):
        edge = b - a
        t = min(1.0, max(0.0, float(np.dot(point - a, edge) / np.dot(edge, edge))))
        best = min(best, float(np.linalg.norm(point - (a + t * edge))))
        if edge[0] * (point - a)[1] - edge[1] * (point - a)[0] < 0.0:
            inside = False
    return 0.0 if inside else best


def footprints(models):
    """(model, collision name, xy convex hull) of every box collision of the models."""
    result = []
    for model in models:
        for link in model.links:
            for collision in link.collisions:
                if isinstance(collision.geometry, Box):
                    corners = box_corners(model, link, collision)
                    result.append((model.name, collision.name, convex_hull(corners[:, :2])))
    return result


def width_across(model, z, x=0.0):
    """Extent [m] along the model's y axis of its box collisions on the line (x, ., z) of the
    model frame: the union of the line's intervals inside each box (slab method)."""
    low, high = math.inf, -math.inf
    for link in model.links:
        for collision in link.collisions:
            to_box = np.linalg.inv(as_matrix(link.pose) @ as_matrix(collision.pose))
            origin = to_box @ np.array([x, 0.0, z, 1.0])
            direction = to_box[:3, :3] @ np.array([0.0, 1.0, 0.0])
            half = np.array(collision.geometry.size) / 2.0
            t0, t1 = -math.inf, math.inf
            for axis in range(3):
                if abs(direction[axis]) < 1e-12:
                    if abs(origin[axis]) > half[axis]:
                        t0, t1 = math.inf, -math.inf
                    continue
                a = (-half[axis] - origin[axis]) / direction[axis]
                b = (half[axis] - origin[axis]) / direction[axis]
                t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
            if t0 <= t1:
                low, high = min(low, t0), max(high, t1)
    return high - low


# --- model path and find_world ---------------------------------------------------------------
def test_model_path_puts_package_first_then_env_entries(monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", ":/opt/a::/home/u/models:")
    assert model_path_from_env("/pkg/models") == ["/pkg/models", "/opt/a", "/home/u/models"]
    monkeypatch.delenv("GAZEBO_MODEL_PATH")
    assert model_path_from_env("/pkg/models") == ["/pkg/models"]


def test_find_world_accepts_name_file_name_and_path(monkeypatch):
    expected = os.path.join(FIXTURE_WORLDS, "state.world")
    assert find_world("state", FIXTURE_WORLDS) == expected
    assert find_world("state.world", FIXTURE_WORLDS) == expected
    assert find_world(expected, "/nonexistent") == expected
    monkeypatch.chdir(FIXTURES)
    assert find_world("worlds/poses.world", MY_WORLDS) == fixture_world("poses")


@pytest.mark.parametrize("name", ["world04", "", "no/such/file.world", "worlds"])
def test_find_world_unknown_lists_the_known_worlds(name):
    with pytest.raises(WorldFileError) as error:
        find_world(name, MY_WORLDS)
    assert str(error.value) == (
        "world '%s' not found; pass world:=NAME with NAME one of world01, world02, world03 (from %s) "
        "or a path to a .world file" % (name, MY_WORLDS))


def test_find_world_looks_up_relative_paths_in_the_resource_path(monkeypatch, tmp_path):
    # gazebo_ros's default world_name, worlds/empty.world, is relative to GAZEBO_RESOURCE_PATH
    monkeypatch.chdir(tmp_path)
    package = os.path.join(SRC, "pybullet_gazebo")
    assert find_world("worlds/empty.world", MY_WORLDS, ["", "/nonexistent", package]) == \
        os.path.join(package, "worlds", "empty.world")
    with pytest.raises(WorldFileError):
        find_world("worlds/empty.world", MY_WORLDS, ["/nonexistent"])


def test_find_world_finds_the_tutorial_worlds():
    assert find_world("world02", MY_WORLDS) == os.path.join(MY_WORLDS, "world02.world")
    assert find_world("world01.world", MY_WORLDS) == os.path.join(MY_WORLDS, "world01.world")


# --- <include> -------------------------------------------------------------------------------
@pytest.fixture
def includes(monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", EXTRA_MODELS)
    return load_world(fixture_world("includes"), model_path_from_env(FIXTURE_MODELS))


def by_name(world):
    return {model.name: model for model in world.models}


def test_include_names_poses_and_static(includes):
    assert [m.name for m in includes.models] == [
        "block_a", "fx_block", "block_static", "cone", "fx_meshy", "shelf"]
    models = by_name(includes)
    block = models["block_a"]
    assert block.pose.position == (1.0, 2.0, 0.0)
    assert block.pose.rpy == pytest.approx((0.0, 0.0, 0.5), abs=1e-12)
    assert block.static is False
    assert models["fx_block"].pose.position == (9.0, 8.0, 7.0)     # the model's own pose
    assert models["block_static"].static is True
    assert models["cone"].static is False                           # include overrides true


def test_include_reads_links_inertials_and_friction_from_the_package_dir(includes):
    (link,) = by_name(includes)["block_a"].links
    assert link.name == "body"
    assert link.pose.position == (0.0, 0.0, 0.25)
    assert link.inertial.mass == 2.5
    assert link.inertial.pose.position == (0.0, 0.0, 0.01)
    assert link.inertial.inertia == (0.1, 0.2, 0.3)
    (collision,) = link.collisions
    # models/fx_block (1 x 0.5 x 0.5) shadows extra_models/fx_block (7 x 7 x 7)
    assert collision.geometry == Box((1.0, 0.5, 0.5))
    assert (collision.mu, collision.mu2) == (0.3, 0.4)


def test_include_from_gazebo_model_path_with_default_sdf_file(includes):
    (link,) = by_name(includes)["cone"].links
    assert [(c.name, c.geometry, c.pose.position) for c in link.collisions] == [
        ("stem", Cylinder(radius=0.2, length=1.0), (0.0, 0.0, 0.5)),
        ("ball", Sphere(radius=0.15), (0.0, 0.0, 1.1))]
    assert link.inertial.mass == 1.0 and link.inertial.inertia == (1.0, 1.0, 1.0)


def test_include_nested_in_a_model_is_flattened(includes):
    shelf = by_name(includes)["shelf"]
    assert [link.name for link in shelf.links] == ["board", "slot::body"]
    assert shelf.links[1].pose.position == (0.0, 0.0, 1.25)
    assert shelf.links[1].collisions[0].geometry == Box((1.0, 0.5, 0.5))


def test_mesh_replacement_file_and_one_warning_for_the_rest(includes):
    link, antenna = by_name(includes)["fx_meshy"].links
    assert [c.name for c in link.collisions] == ["foot", "shell_box", "shell_top"]
    assert link.collisions[1].geometry == Box((0.3, 0.3, 0.6))
    assert link.collisions[1].pose.position == (0.0, 0.0, 0.4)
    assert (link.collisions[2].mu, link.collisions[2].mu2) == (0.5, 0.6)
    (tip,) = antenna.collisions
    assert tip.geometry == Mesh("model://fx_meshy/meshes/tip.stl", (2.0, 2.0, 2.0))
    assert len(includes.warnings) == 1
    (warning,) = includes.warnings
    assert "fx_meshy" in warning and "'tip'" in warning and "shell" not in warning
    assert os.path.join(FIXTURE_MODELS, "fx_meshy", "pybullet_collision.sdf") in warning


def test_include_without_gazebo_model_path_names_model_and_path(monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    with pytest.raises(WorldFileError) as error:
        load_world(fixture_world("includes"), model_path_from_env(FIXTURE_MODELS))
    message = str(error.value)
    assert "model://fx_cone" in message and "[%s]" % FIXTURE_MODELS in message
    assert "GAZEBO_MODEL_PATH" in message


def test_unknown_include_names_model_and_path_searched():
    with pytest.raises(WorldFileError) as error:
        load_world(fixture_world("unknown_include"), [FIXTURE_MODELS, EXTRA_MODELS])
    message = str(error.value)
    assert fixture_world("unknown_include") in message
    assert "model://no_such_model" in message
    assert "[%s, %s]" % (FIXTURE_MODELS, EXTRA_MODELS) in message


def test_include_whose_model_file_is_missing(tmp_path):
    model_dir = tmp_path / "hollow"
    model_dir.mkdir()
    (model_dir / "model.config").write_text(
        "<model><name>hollow</name><sdf version='1.6'>gone.sdf</sdf></model>")
    world = tmp_path / "w.world"
    world.write_text("<sdf version='1.6'><world name='w'><include><uri>model://hollow</uri>"
                     "</include></world></sdf>")
    with pytest.raises(WorldFileError) as error:
        load_world(str(world), [str(tmp_path)])
    assert str(model_dir / "gone.sdf") in str(error.value)
    assert "not found" in str(error.value)


# --- <state> ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def state_world():
    return load_world(fixture_world("state"), [FIXTURE_MODELS])


def test_state_overrides_model_poses(state_world):
    models = by_name(state_world)
    crate = models["crate"]
    assert crate.pose.position == (3.0, -2.0, 0.0)
    assert crate.pose.rpy == pytest.approx((0.0, 0.0, HALF_PI), abs=1e-12)
    assert models["post"].pose.position == (5.0, 5.0, 0.0)       # not in the state
    assert models["lever"].pose.position == (10.0, 0.0, 0.0)


def test_state_link_poses_are_world_poses(state_world):
    (crate_link,) = by_name(state_world)["crate"].links
    assert crate_link.pose.position == pytest.approx((0.0, 0.0, 0.5), abs=1e-12)
    assert crate_link.pose.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-12)
    base, arm = by_name(state_world)["lever"].links
    assert base.pose.position == (0.0, 0.0, 0.0)                  # no pose in its state
    assert arm.pose.position == pytest.approx((0.0, 1.0, 1.0), abs=1e-12)   # was (0, 0, 1)


def test_state_reports_what_it_cannot_apply(state_world):
    assert len(state_world.warnings) == 3
    joined = "\n".join(state_world.warnings)
    assert "'ghost'" in joined and "'missing'" in joined
    assert "<velocity> in the <state> of link 'arm'" in joined


# --- pose composition and physics --------------------------------------------------------------
@pytest.fixture(scope="module")
def poses():
    return load_world(fixture_world("poses"), [FIXTURE_MODELS])


def test_default_physics_is_chosen_with_its_gravity(poses):
    assert (poses.physics.max_step_size, poses.physics.real_time_factor,
            poses.physics.real_time_update_rate) == (0.002, 0.5, 500.0)
    assert poses.physics.gravity == (0.0, 0.0, -3.7)
    assert poses.warnings == ()


def test_nested_model_link_and_collision_poses_compose_exactly(poses):
    outer = by_name(poses)["outer"]
    base, inner = outer.links
    assert inner.name == "inner::l"
    expected = (homogeneous(1, 2, 0.5, 0, 0, HALF_PI) @ homogeneous(0, 1, 0, 0, 0, HALF_PI)
                @ homogeneous(1, 0, 0, 0, 0.2, 0) @ homogeneous(0, 0, 1, 0.1, -0.2, 0.4))
    assert collision_matrix(outer, inner, inner.collisions[0]) == pytest.approx(expected,
                                                                                 abs=1e-12)
    expected = (homogeneous(1, 2, 0.5, 0, 0, HALF_PI) @ homogeneous(0.5, 0, 0, 0, 0, 0)
                @ homogeneous(0, 0, 0.1, 0.3, 0, 0))
    assert collision_matrix(outer, base, base.collisions[0]) == pytest.approx(expected,
                                                                               abs=1e-12)
    # the sphere's centre, by hand: inner frame at (0, 2) facing -x; link 1 m ahead = (-1, 2)
    assert collision_matrix(outer, inner, inner.collisions[0])[:3, 3] == pytest.approx(
        (-1.0 - math.sin(0.2), 2.0, 0.5 + math.cos(0.2)), abs=1e-12)
    assert inner.inertial.mass == 3.0
    assert inner.inertial.pose.position == (0.1, 0.0, 0.0)       # stays in the link frame


def test_turned_box_footprint(poses):
    wall = by_name(poses)["wall"]
    assert wall.static is True
    corners = box_corners(wall, wall.links[0], wall.links[0].collisions[0])
    assert sorted(map(tuple, np.round(corners, 12) + 0.0)) == sorted(
        (x, y, z) for x in (1.9, 2.1) for y in (-2.0, 2.0) for z in (0.0, 1.0))


# --- unsupported elements --------------------------------------------------------------------
@pytest.fixture(scope="module")
def unsupported():
    return load_world(fixture_world("unsupported"), [FIXTURE_MODELS])


EXPECTED_REPORTS = [          # (element as named in the warning, owner)
    ("<ode> in <physics>", "world 'unsupported'"),
    ("<plugin> in the world", "world 'unsupported'"),
    ("<actor>", "world 'unsupported'"),
    ("<road>", "world 'unsupported'"),
    ("<population>", "world 'unsupported'"),
    ("<joint> in the world", "world 'unsupported'"),
    ("<heightmap> geometry", "model 'terrain'"),
    ("<bounce>", "model 'robotish'"),
    ("<kinematic>1</kinematic>", "model 'robotish'"),
    ("<sensor>", "model 'robotish'"),
    ("<plugin> in the model", "model 'robotish'"),
    ("<joint> in the model", "model 'robotish'"),
    ("mesh collisions 'hull' (link 'link', file://hull.stl), 'keel' (link 'link', "
     "file://keel.stl)", "model 'meshy_inline'"),
]


@pytest.mark.parametrize("element, owner", EXPECTED_REPORTS)
def test_each_unsupported_element_is_reported_once(unsupported, element, owner):
    hits = [w for w in unsupported.warnings if w.startswith(owner + ":") and element in w]
    assert len(hits) == 1, unsupported.warnings


def test_nothing_else_is_reported(unsupported):
    assert len(unsupported.warnings) == len(EXPECTED_REPORTS)
    joined = "\n".join(unsupported.warnings)
    for silent in ("visual", "light", "scene", "gui", "audio", "spherical_coordinates", "wind",
                   "magnetic_field", "atmosphere", "material", "self_collide", "enable_wind",
                   "gravity", "laser_retro", "max_contacts", "allow_auto_disable", "contact",
                   "torsional", "empty", "nothing"):
        assert silent not in joined


def test_unsupported_geometry_is_left_out_and_meshes_kept(unsupported):
    models = by_name(unsupported)
    assert models["terrain"].links[0].collisions == ()
    assert [c.name for c in models["robotish"].links[0].collisions] == ["c", "c2"]
    assert [c.geometry for c in models["meshy_inline"].links[0].collisions] == [
        Mesh("file://hull.stl"), Mesh("file://keel.stl")]
    assert unsupported.physics.gravity == (0.0, 0.0, -9.81)


# --- errors ----------------------------------------------------------------------------------
def test_missing_world_file(tmp_path):
    path = str(tmp_path / "nowhere.world")
    with pytest.raises(WorldFileError) as error:
        load_world(path, [FIXTURE_MODELS])
    assert str(error.value) == "world file not found: %s; check the path" % path
    with pytest.raises(WorldFileError) as error:
        load_world(str(tmp_path), [FIXTURE_MODELS])
    assert str(error.value).startswith("cannot read world file %s (" % tmp_path)


def test_malformed_xml_gives_file_line_and_column():
    with pytest.raises(WorldFileError) as error:
        load_world(fixture_world("malformed"), [FIXTURE_MODELS])
    message = str(error.value)
    assert fixture_world("malformed") in message
    assert "line 5, column 25" in message and "mismatched tag" in message


def test_non_numeric_pose_names_model_and_text():
    with pytest.raises(WorldFileError) as error:
        load_world(fixture_world("bad_pose"), [FIXTURE_MODELS])
    message = str(error.value)
    assert fixture_world("bad_pose") in message
    assert "model 'crooked'" in message and "'1 2 abc 0 0 0'" in message


def test_duplicate_model_names():
    with pytest.raises(WorldFileError) as error:
        load_world(fixture_world("duplicate"), [FIXTURE_MODELS])
    assert "two models are named 'twin'" in str(error.value)


@pytest.mark.parametrize("text, expected", [
    ("<sdf version='1.6'><model name='m'/></sdf>", "no <sdf><world> element"),
    ("<sdf version='1.6'><world name='w'><model name='m'><link name='l'><collision name='c'>"
     "<geometry><box><size>1 2</size></box></geometry></collision></link></model></world>"
     "</sdf>", "model 'm': <size> '1 2' must be 3 finite number(s)"),
    ("<sdf version='1.6'><world name='w'><physics><max_step_size>nan</max_step_size></physics>"
     "</world></sdf>", "<max_step_size> 'nan' must be 1 finite number(s)"),
    ("<sdf version='1.6'><world name='w'><model name='m'><static>maybe</static></model>"
     "</world></sdf>", "<static> 'maybe' must be true or false"),
    ("<sdf version='1.6'><world name='w'><include><uri>file:///x</uri></include></world>"
     "</sdf>", "uri 'file:///x' is not supported; use model://NAME"),
])
def test_invalid_content_is_an_error(tmp_path, text, expected):
    path = tmp_path / "bad.world"
    path.write_text(text)
    with pytest.raises(WorldFileError) as error:
        load_world(str(path), [FIXTURE_MODELS])
    assert str(error.value).startswith(str(path) + ": ")
    assert expected in str(error.value)


# --- the tutorial's worlds -------------------------------------------------------------------
@pytest.fixture(scope="module")
def world01():
    return load_world(os.path.join(MY_WORLDS, "world01.world"), [STOCK_MODELS])


@pytest.fixture(scope="module")
def world02():
    return load_world(os.path.join(MY_WORLDS, "world02.world"), [STOCK_MODELS])


E, T = -1.5687, -1.581        # yaw [rad] of the turned barriers
PERIMETER = [(-5.66, 9.46, 0), (-1.66, 9.36, 0), (2.40, 9.29, 0), (6.45, 9.34, 0),
             (6.71, -9.54, 0), (2.60, -9.51, 0), (-1.33, -9.51, 0), (-5.45, -9.50, 0),
             (9.45, 5.36, E), (9.37, 1.33, E), (9.43, -2.63, E), (9.45, -6.53, E),
             (-9.54, -6.33, E), (-9.62, -2.35, E), (-9.59, 1.70, E), (-9.45, 5.84, E)]
CORNER_BARRELS = [(9.07, 7.91), (8.13, 8.42), (-9.27, 8.48), (-8.34, 8.94), (9.45, -9.29),
                  (-8.13, -9.57), (-8.94, -8.96)]
INTERIOR = [(-4.97, 4.73, 0), (-0.94, 4.73, 0), (2.99, 4.72, 0), (-2.28, -0.40, 0),
            (1.77, -0.39, 0), (-4.71, -2.79, T)]


def of_kind(world, kind):
    return [m for m in world.models if m.name == kind or m.name.startswith(kind + "_")]


def layout(models):
    return sorted((round(m.pose.position[0], 6), round(m.pose.position[1], 6),
                   round(m.pose.rpy[2], 6)) for m in models)


def test_tutorial_worlds_physics_and_ground(world01, world02):
    for world in (world01, world02):
        assert world.warnings == ()
        assert (world.physics.max_step_size, world.physics.real_time_factor,
                world.physics.real_time_update_rate) == (0.001, 1.0, 1000.0)
        assert world.physics.gravity == (0.0, 0.0, -9.8)
        ground = world.models[0]
        assert (ground.name, ground.static) == ("ground_plane", True)
        (collision,) = ground.links[0].collisions
        assert collision.geometry == Plane((0.0, 0.0, 1.0), (100.0, 100.0))


def test_world01_is_the_perimeter(world01):
    assert len(world01.models) == 1 + 16 + 7
    barriers = of_kind(world01, "jersey_barrier")
    barrels = of_kind(world01, "construction_barrel")
    assert len(barriers) == 16 and len(barrels) == 7 and not of_kind(world01, "coke_can")
    assert layout(barriers) == layout_of(PERIMETER)
    assert sorted(m.pose.position[:2] for m in barrels) == sorted(CORNER_BARRELS)
    assert all(m.static for m in barriers) and not any(m.static for m in barrels)
    assert all(m.pose.position[2] == 0.0 for m in world01.models)


def layout_of(rows):
    return sorted((round(x, 6), round(y, 6), round(yaw, 6)) for x, y, yaw in rows)


def test_world02_adds_the_interior(world01, world02):
    assert len(world02.models) == len(world01.models) + 6 + 1 + 1
    assert layout(of_kind(world02, "jersey_barrier")) == layout_of(PERIMETER + INTERIOR)
    first = by_name(world01)
    for model in world02.models:               # world01's models are unchanged in world02
        if model.name in first:
            assert model == first[model.name]
    barrel = by_name(world02)["construction_barrel_6"]
    assert barrel.pose.position == (-4.40, -0.66, 0.0)
    (can,) = of_kind(world02, "coke_can")
    assert can.pose.position == (-3.01, -2.51, 0.0) and can.static is False


def test_barrier_names_follow_gazebos_copies(world02):
    names = [m.name for m in of_kind(world02, "jersey_barrier")]
    assert names == ["jersey_barrier"] + ["jersey_barrier_%d" % i for i in range(21)]
    models = by_name(world02)
    assert models["jersey_barrier_7"].pose.position == (9.45, 5.36, 0.0)
    assert models["jersey_barrier_7"].pose.rpy[2] == pytest.approx(-1.5687, abs=1e-12)
    assert models["jersey_barrier_20"].pose.rpy[2] == pytest.approx(-1.581, abs=1e-12)


@pytest.mark.parametrize("names, axis, low, high", [
    (["jersey_barrier", "jersey_barrier_0", "jersey_barrier_1", "jersey_barrier_2"],
     0, -7.69, 8.49),                                                   # north wall, x
    (["jersey_barrier_3", "jersey_barrier_4", "jersey_barrier_5", "jersey_barrier_6"],
     0, -7.48, 8.74),                                                   # south wall, x
    (["jersey_barrier_7", "jersey_barrier_8", "jersey_barrier_9", "jersey_barrier_10"],
     1, -8.57, 7.39),                                                   # east wall, y
    (["jersey_barrier_15", "jersey_barrier_16", "jersey_barrier_17"], 0, -7.01, 5.02),
    (["jersey_barrier_18", "jersey_barrier_19"], 0, -4.31, 3.80),
    (["jersey_barrier_20"], 1, -4.82, -0.75),
])
def test_wall_extents_match_the_reference(world02, names, axis, low, high):
    models = by_name(world02)
    ends = []
    for name in names:
        model = models[name]
        link = model.links[0]
        (upright,) = [c for c in link.collisions if c.name == "upright"]
        ends.extend(box_corners(model, link, upright)[:, axis])
    assert min(ends) == pytest.approx(low, abs=0.015)
    assert max(ends) == pytest.approx(high, abs=0.015)


def test_jersey_barrier_profile(world01):
    barrier = by_name(world01)["jersey_barrier"]
    assert barrier.static is True
    assert width_across(barrier, 0.03) == pytest.approx(0.8107, abs=1e-9)
    assert width_across(barrier, 0.14) == pytest.approx(0.65, abs=1e-9)
    assert width_across(barrier, 0.16) == pytest.approx(0.5, abs=1e-9)
    for z in np.linspace(0.14, 0.16, 11):           # the laser's height, ~0.15 m
        assert 0.5 - 1e-9 <= width_across(barrier, z) <= 0.65 + 1e-9
    for z in np.linspace(0.25, 0.40, 16):           # sloped faces narrow towards the wall
        assert 0.3063 - 1e-9 <= width_across(barrier, z) <= 0.5 + 0.003
    assert width_across(barrier, 0.8) == pytest.approx(0.3063, abs=1e-9)
    assert width_across(barrier, 1.15) == -math.inf          # above the 1.143 m wall
    slab = [c for c in barrier.links[0].collisions if c.name == "slab_left"][0]
    assert slab.pose.rpy[0] == pytest.approx(-0.9, abs=1e-12)


def test_stock_barrel_and_can(world02):
    models = by_name(world02)
    barrel, can = models["construction_barrel"], models["coke_can"]
    assert barrel.links[0].inertial.mass == 500.0
    assert barrel.links[0].collisions[0].geometry == Cylinder(radius=0.3, length=1.0)
    assert barrel.links[0].collisions[0].pose.position == (0.0, 0.0, 0.5)   # on the ground
    assert can.links[0].inertial.mass == 0.39
    (collision,) = can.links[0].collisions
    assert collision.geometry == Cylinder(radius=0.033, length=0.12)
    top = can.pose.position[2] + collision.pose.position[2] + collision.geometry.length / 2
    assert top == pytest.approx(0.12) and top < 0.15            # below the scan plane


def test_robot_start_in_world02_is_clear_of_every_barrier(world02):
    barriers = footprints(of_kind(world02, "jersey_barrier"))
    distances = [(distance_to_polygon((0.0, 8.0), hull), name, collision)
                 for name, collision, hull in barriers]
    nearest = min(distances)
    # the north wall's 0.8107 m base at y 9.36: 9.36 - 0.8107 / 2 - 8
    assert nearest[0] == pytest.approx(9.36 - 0.40535 - 8.0, abs=1e-9)
    assert nearest[1:] == ("jersey_barrier_0", "base")
    assert min(d for d, _, c in distances if c == "upright") > 1.0
    row_a = [d for d, name, _ in distances
             if name in ("jersey_barrier_15", "jersey_barrier_16", "jersey_barrier_17")]
    assert min(row_a) == pytest.approx(8.0 - 4.73 - 0.40535, abs=1e-9)


def test_dynamic_models_start_clear_of_the_barriers(world02):
    barriers = footprints(of_kind(world02, "jersey_barrier"))
    for model in world02.models:
        if model.static:
            continue
        radius = model.links[0].collisions[0].geometry.radius
        gap = min(distance_to_polygon(model.pose.position[:2], hull)
                  for _, _, hull in barriers) - radius
        assert gap > 0.2, model.name
    # the barrel in the L corner of row B reaches into both barrier ends, so it is static
    corner = by_name(world02)["construction_barrel_6"]
    assert corner.static is True
    gap = min(distance_to_polygon(corner.pose.position[:2], hull)
              for _, _, hull in barriers) - 0.3
    assert gap < -0.2
