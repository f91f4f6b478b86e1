"""RayCaster against exact geometry and against Bullet's own rayTestBatch.

About the comparison with Bullet: Bullet's ray test against convex shapes is an iterative
convex cast that stops within 1 mm of the surface. Its hit points lie up to 1 mm from the
true surface (inside or outside; measured: 0.999 mm for spheres, cylinders, capsules and
near box edges), so it reports a hit on some rays that pass up to 1 mm outside a shape and
misses some that graze it, and its distances differ from the exact ones by more than 1e-4 m
on roughly half the rays that hit a curved shape. The tests therefore check:
- exactness: every hit of the caster lies on the true surface (signed distance < 1e-9 m);
- Bullet agreement: every Bullet hit lies within BULLET_TOLERANCE of that surface, and the
  two report hits on the same rays except rays that pass within that tolerance of it.

The cost of a 720-beam scan, this caster against rayTestBatch over the same beams in world02,
is a figure of scripts/bench.sh (m2wr_tools.bench.engine), not a test.
"""
import math

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import ray_kernel
from pybullet_gazebo.engine.raycast import RayCaster, rotation_matrices
from pybullet_gazebo.engine.transforms import Pose

BULLET_TOLERANCE = 1.0e-3       # [m] how far from the surface Bullet's ray hits may lie
EXACT = 1.0e-9                  # [m]


@pytest.fixture
def client():
    c = BulletClient(connection_mode=pybullet.DIRECT)
    yield c
    c.disconnect()


def random_quaternion(rng):
    q = rng.normal(size=4)
    return tuple(q / np.linalg.norm(q))


# --- exact signed distances in a shape's own frame -------------------------------------------
def sdf_box(x, half):
    q = np.abs(x) - half
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def sdf_sphere(x, radius):
    return np.linalg.norm(x, axis=-1) - radius


def sdf_cylinder(x, radius, length):
    d = np.stack([np.hypot(x[..., 0], x[..., 1]) - radius, np.abs(x[..., 2]) - length / 2], -1)
    return np.minimum(d.max(axis=-1), 0.0) + np.linalg.norm(np.maximum(d, 0.0), axis=-1)


def sdf_capsule(x, radius, length):
    y = np.array(x, dtype=float)
    y[..., 2] -= np.clip(y[..., 2], -length / 2, length / 2)
    return np.linalg.norm(y, axis=-1) - radius


class Scene:
    """Shapes created in Bullet with the exact signed distance of their union."""

    def __init__(self, client):
        self.client = client
        self.parts = []                       # (body, shape pose in world, local sdf)

    def add(self, geometry, dims, mass=0.0, position=(0, 0, 0), orientation=(0, 0, 0, 1),
            collision_pose=Pose(), inertial_pose=Pose()):
        """A one-shape body; dims as for createCollisionShape. Returns the body id."""
        c = self.client
        kwargs = dict(collisionFramePosition=collision_pose.position,
                      collisionFrameOrientation=collision_pose.orientation)
        if geometry == "box":
            half = np.asarray(dims, dtype=float)
            shape = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half, **kwargs)
            sdf = lambda x: sdf_box(x, half)                                   # noqa: E731
        elif geometry == "sphere":
            shape = c.createCollisionShape(pybullet.GEOM_SPHERE, radius=dims, **kwargs)
            sdf = lambda x: sdf_sphere(x, dims)                                # noqa: E731
        elif geometry == "cylinder":
            r, length = dims
            shape = c.createCollisionShape(pybullet.GEOM_CYLINDER, radius=r, height=length,
                                           **kwargs)
            sdf = lambda x: sdf_cylinder(x, r, length)                         # noqa: E731
        elif geometry == "capsule":
            r, length = dims
            shape = c.createCollisionShape(pybullet.GEOM_CAPSULE, radius=r, height=length,
                                           **kwargs)
            sdf = lambda x: sdf_capsule(x, r, length)                          # noqa: E731
        elif geometry == "plane":
            normal = np.asarray(dims, dtype=float) / np.linalg.norm(dims)
            shape = c.createCollisionShape(pybullet.GEOM_PLANE, planeNormal=normal)
            collision_pose = Pose()
            sdf = lambda x: x @ normal                                         # noqa: E731
        else:
            raise ValueError(geometry)
        body = c.createMultiBody(mass, shape, basePosition=position,
                                 baseOrientation=orientation,
                                 baseInertialFramePosition=inertial_pose.position,
                                 baseInertialFrameOrientation=inertial_pose.orientation)
        self.parts.append((body, Pose(tuple(position), tuple(orientation)).compose(
            collision_pose), sdf, geometry == "plane"))
        return body

    def sdf(self, points, surface_only=False):
        """Signed distance [m] of the union at points (n, 3); planes count as two-sided
        surfaces (|distance|) when surface_only, as Bullet's plane is."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        out = np.full(len(points), np.inf)
        for body, pose, sdf, plane in self.parts:
            local = (points - np.asarray(pose.position)) @ pose.matrix
            d = sdf(local)
            out = np.minimum(out, np.abs(d) if plane or surface_only else d)
        return out


def bullet_ranges(client, origin, directions, range_min, range_max):
    """Bullet's distances from origin for rays tested over [range_min, range_max]."""
    origin = np.asarray(origin, dtype=float)
    starts = origin + directions * range_min
    ends = origin + directions * range_max
    results = client.rayTestBatch(starts.tolist(), ends.tolist())
    return np.array([range_min + r[2] * (range_max - range_min) if r[0] >= 0 else np.inf
                     for r in results])


def min_surface_distance(scene, origin, direction, t0, t1):
    """Smallest |signed distance| along a segment (sampled at 0.2 mm; sdf is 1-Lipschitz)."""
    ts = np.linspace(t0, t1, int((t1 - t0) / 2e-4) + 2)
    return np.min(np.abs(scene.sdf(origin + ts[:, None] * direction)))


def assert_agrees(scene, caster, origin, directions, range_min, range_max,
                  min_hits=0.1, min_misses=0.1, exact=EXACT):
    origin = np.asarray(origin, dtype=float)
    directions = directions / np.linalg.norm(directions, axis=1)[:, None]
    ours = caster.cast(origin, directions, range_min, range_max)
    theirs = bullet_ranges(scene.client, origin, directions, range_min, range_max)
    hit, bullet_hit = np.isfinite(ours), np.isfinite(theirs)
    assert hit.mean() >= min_hits and (1 - hit.mean()) >= min_misses, "rays not informative"
    assert np.all((ours[hit] >= range_min) & (ours[hit] <= range_max))

    # exact: our hits lie on the union's surface
    ours_points = origin + ours[hit, None] * directions[hit]
    assert np.max(np.abs(scene.sdf(ours_points))) < exact
    # Bullet's hits lie within its tolerance of that surface
    bullet_points = origin + theirs[bullet_hit, None] * directions[bullet_hit]
    assert np.max(np.abs(scene.sdf(bullet_points, surface_only=True))) <= BULLET_TOLERANCE
    # same rays hit, except rays grazing the surface within Bullet's tolerance
    differ = np.flatnonzero(hit != bullet_hit)
    assert len(differ) <= 0.03 * len(directions)
    for i in differ:
        assert min_surface_distance(scene, origin, directions[i], range_min,
                                    range_max) <= BULLET_TOLERANCE + 2e-4, i
    both = hit & bullet_hit
    close = np.abs(ours[both] - theirs[both]) <= 1e-4
    return ours, theirs, close.mean()


def rays_towards(rng, origin, centre, spread, n):
    """n unit directions from origin towards random points of a cube around centre."""
    targets = np.asarray(centre) + rng.uniform(-spread, spread, (n, 3))
    d = targets - origin
    return d / np.linalg.norm(d, axis=1)[:, None]


def random_origin(rng, centre, low, high):
    v = rng.normal(size=3)
    return np.asarray(centre) + v / np.linalg.norm(v) * rng.uniform(low, high)


# --- one primitive at a time ------------------------------------------------------------------
PRIMITIVES = [
    ("box", (0.4, 0.15, 0.8)),
    ("sphere", 0.6),
    ("cylinder", (0.5, 1.6)),
    ("capsule", (0.3, 1.2)),
]


@pytest.mark.parametrize("geometry,dims", PRIMITIVES)
@pytest.mark.parametrize("static", [True, False])
def test_primitive_rotated_matches_geometry_and_bullet(client, geometry, dims, static):
    rng = np.random.default_rng(7)
    scene = Scene(client)
    centre = np.array([1.0, -2.0, 0.5])
    # rotated arbitrarily, shape offset from the link frame, centre of mass offset and turned
    scene.add(geometry, dims, mass=0.0 if static else 2.0, position=centre,
              orientation=random_quaternion(rng),
              collision_pose=Pose((0.1, -0.05, 0.2), random_quaternion(rng)),
              inertial_pose=Pose((0.05, 0.1, -0.1), random_quaternion(rng)))
    caster = RayCaster(client)
    caster.add_body(scene.parts[0][0], static=static)
    assert caster.skipped == []
    for _ in range(4):
        origin = random_origin(rng, centre, 2.0, 8.0)
        assert_agrees(scene, caster, origin, rays_towards(rng, origin, centre, 1.2, 300),
                      0.0, 12.0)


@pytest.mark.parametrize("tilt", [0.0, 0.7])
def test_cylinder_upright_and_tilted(client, tilt):
    rng = np.random.default_rng(3)
    scene = Scene(client)
    centre = (0.0, 3.0, 0.45)
    body = scene.add("cylinder", (0.3, 0.9), position=centre,
                     orientation=Pose.from_xyz_rpy(roll=tilt).orientation)
    caster = RayCaster(client)
    caster.add_body(body, static=True)
    # a horizontal fan centred on +y, as a laser sees it, and rays from all around
    angles = np.linspace(0.0, math.pi, 720)
    fan = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1)
    assert_agrees(scene, caster, (0.0, 0.0, 0.45), fan, 0.1, 10.0, min_hits=0.03)
    for _ in range(3):
        origin = random_origin(rng, centre, 1.5, 6.0)
        assert_agrees(scene, caster, origin, rays_towards(rng, origin, centre, 1.0, 300),
                      0.0, 10.0)
    # exact range along +y through the axis: the section at the ray is an ellipse whose
    # half axis along y is r / cos(tilt)
    along_y = caster.cast((0.0, 0.0, 0.45), [(0.0, 1.0, 0.0)], 0.1, 10.0)[0]
    assert along_y == pytest.approx(3.0 - 0.3 / math.cos(tilt), abs=EXACT)


def test_plane_two_sided_like_bullet(client):
    rng = np.random.default_rng(5)
    scene = Scene(client)
    body = scene.add("plane", (0.2, -0.3, 1.0), position=(0.0, 0.0, 0.5))
    caster = RayCaster(client)
    caster.add_body(body, static=True)
    for origin in [(1.0, 2.0, 3.0), (-2.0, 1.0, -2.0)]:          # above, then below
        directions = rng.normal(size=(400, 3))
        assert_agrees(scene, caster, origin, directions, 0.0, 10.0)
    # straight down onto the plane z = 0.5 through the origin of its frame
    assert caster.cast((0.0, 0.0, 2.5), [(0, 0, -1)], 0.0, 10.0)[0] == pytest.approx(
        2.0, abs=EXACT)


def test_many_random_shapes_static_and_dynamic(client):
    rng = np.random.default_rng(11)
    scene = Scene(client)
    caster = RayCaster(client)
    origin = np.array([0.0, 0.0, 0.2])
    for i in range(60):
        geometry, _ = PRIMITIVES[i % 4]
        dims = {"box": tuple(rng.uniform(0.05, 0.8, 3)), "sphere": rng.uniform(0.05, 0.8),
                "cylinder": (rng.uniform(0.05, 0.6), rng.uniform(0.1, 2.0)),
                "capsule": (rng.uniform(0.05, 0.6), rng.uniform(0.1, 2.0))}[geometry]
        while True:
            position = rng.uniform(-8, 8, 3)
            if np.linalg.norm(position - origin) > 3.0:
                break
        body = scene.add(geometry, dims, mass=float(i % 2), position=position,
                         orientation=random_quaternion(rng),
                         collision_pose=Pose(tuple(rng.uniform(-0.3, 0.3, 3)),
                                             random_quaternion(rng)),
                         inertial_pose=Pose(tuple(rng.uniform(-0.2, 0.2, 3)),
                                            random_quaternion(rng)))
        caster.add_body(body, static=i % 2 == 0)
    directions = rng.normal(size=(3000, 3))
    _, _, close = assert_agrees(scene, caster, origin, directions, 0.3, 12.0, min_hits=0.05)
    assert close > 0.5


def test_fan_of_coplanar_rays_matches_rays_cast_one_by_one(client):
    """A laser's rays share a plane, which lets the caster pair each shape only with the rays
    inside the angle it spans; a lone ray takes the general path. Both must agree, also for
    full circles (angles wrapping past +-pi) and shapes whose projection holds the origin."""
    rng = np.random.default_rng(4)
    scene = Scene(client)
    caster = RayCaster(client)
    origin = np.array([0.0, 0.0, 0.2])
    # a slab tilted 45 deg right above the origin: it crosses the tilted planes below and its
    # projection on them contains the origin
    slab = scene.add("box", (1.0, 0.6, 0.05), position=(0.0, 0.0, 0.9),
                     orientation=Pose.from_xyz_rpy(roll=0.8).orientation)
    caster.add_body(slab, static=True)
    for i in range(40):
        geometry, _ = PRIMITIVES[i % 4]
        dims = {"box": tuple(rng.uniform(0.05, 0.8, 3)), "sphere": rng.uniform(0.05, 0.8),
                "cylinder": (rng.uniform(0.05, 0.6), rng.uniform(0.1, 2.0)),
                "capsule": (rng.uniform(0.05, 0.6), rng.uniform(0.1, 2.0))}[geometry]
        position = rng.uniform(-6, 6, 3) * (1, 1, 0.2)
        if np.linalg.norm(position - origin) < 2.5:
            continue
        body = scene.add(geometry, dims, position=position, orientation=random_quaternion(rng))
        caster.add_body(body, static=True)
    for roll, pitch, yaw, first, span in [(0, 0, 0, -math.pi / 2, math.pi),
                                          (0, 0, 0, 0.3, 2 * math.pi),
                                          (0.5, -0.3, 1.0, -2.0, 2 * math.pi),
                                          (1.2, 0.2, 0.0, 2.5, 2.0)]:
        plane = Pose.from_xyz_rpy(0, 0, 0, roll, pitch, yaw).matrix
        angles = first + np.linspace(0.0, span, 1441)
        fan = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1) @ plane.T
        together = caster.cast(origin, fan, 0.1, 10.0)
        one_by_one = np.array([caster.cast(origin, d[None], 0.1, 10.0)[0] for d in fan])
        np.testing.assert_array_equal(np.isfinite(together), np.isfinite(one_by_one))
        hit = np.isfinite(together)
        assert 20 <= hit.sum() < len(fan)
        np.testing.assert_allclose(together[hit], one_by_one[hit], rtol=0, atol=1e-12)
        assert np.max(np.abs(scene.sdf(origin + together[hit, None] * fan[hit]))) < EXACT
    # straight up, the ray runs along the slab's centre line: it enters the lower face
    # 0.05 / cos(0.8) before the centre, 0.7 m above the origin
    up = caster.cast(origin, [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0)], 0.1, 10.0)
    assert up[0] == pytest.approx(0.7 - 0.05 / math.cos(0.8), abs=EXACT)


def test_urdf_links_inertial_frames_and_several_collisions(client, tmp_path):
    """Shapes of a multi-link URDF (turned inertial frames, two collisions on one link,
    an implicit cylinder, a capsule) against geometry computed from the URDF's own frames."""
    urdf = tmp_path / "robot.urdf"
    urdf.write_text("""<robot name="r">
 <link name="base">
  <inertial><origin xyz="0.02 0 0.1" rpy="0.1 0.2 0.3"/><mass value="5"/>
   <inertia ixx="0.04" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><box size="0.5 0.3 0.07"/></geometry></collision>
  <collision><origin xyz="0.35 0 -0.05"/><geometry><sphere radius="0.05"/></geometry></collision>
 </link>
 <link name="wheel">
  <inertial><origin xyz="0 0.01 0"/><mass value="0.2"/>
   <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><origin rpy="0 1.5707 1.5707"/>
   <geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>
 </link>
 <joint name="j_wheel" type="continuous"><parent link="base"/><child link="wheel"/>
  <origin xyz="-0.05 0.15 0"/><axis xyz="0 1 0"/></joint>
 <link name="mast">
  <inertial><origin xyz="0.01 0.02 0.03" rpy="0.4 0 0"/><mass value="0.3"/>
   <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><origin xyz="0 0 0.1" rpy="0.3 0 0"/>
   <geometry><capsule radius="0.05" length="0.2"/></geometry></collision>
 </link>
 <joint name="j_mast" type="revolute"><parent link="base"/><child link="mast"/>
  <origin xyz="0.2 0 0.04"/><axis xyz="1 0 0"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>""")
    body = client.loadURDF(str(urdf), basePosition=(1.0, 0.5, 0.3),
                           baseOrientation=Pose.from_xyz_rpy(yaw=0.4, pitch=0.2).orientation,
                           flags=pybullet.URDF_USE_IMPLICIT_CYLINDER)
    client.resetJointState(body, 0, 0.8)
    client.resetJointState(body, 1, 0.5)
    caster = RayCaster(client)
    caster.add_body(body, static=False)
    assert caster.skipped == []

    # the URDF link frames as Bullet holds them, composed with the URDF's collision origins
    base = Pose(*client.getBasePositionAndOrientation(body)).compose(Pose(
        *client.getDynamicsInfo(body, -1)[3:5]).inverse())
    links = [base] + [Pose(*client.getLinkState(body, i, computeForwardKinematics=True)[4:6])
                      for i in range(2)]
    scene = Scene(client)
    for link, origin, sdf in [
            (0, Pose(), lambda x: sdf_box(x, np.array([0.25, 0.15, 0.035]))),
            (0, Pose((0.35, 0, -0.05)), lambda x: sdf_sphere(x, 0.05)),
            (1, Pose.from_xyz_rpy(0, 0, 0, 0, 1.5707, 1.5707),
             lambda x: sdf_cylinder(x, 0.1, 0.04)),
            (2, Pose.from_xyz_rpy(0, 0, 0.1, 0.3, 0, 0), lambda x: sdf_capsule(x, 0.05, 0.2))]:
        scene.parts.append((body, links[link].compose(origin), sdf, False))
    rng = np.random.default_rng(2)
    for _ in range(4):
        origin = random_origin(rng, base.position, 1.0, 4.0)
        # pybullet keeps link frames in single precision: exact to 1e-6 m here
        assert_agrees(scene, caster, origin, rays_towards(rng, origin, base.position, 0.35, 400),
                      0.0, 10.0, min_hits=0.1, exact=1e-6)


def test_mesh_shapes_are_skipped_and_listed(client, tmp_path):
    urdf = tmp_path / "can.urdf"
    urdf.write_text("""<robot name="can"><link name="can">
  <inertial><mass value="0.4"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><cylinder radius="0.2" length="0.5"/></geometry></collision>
 </link></robot>""")
    body = client.loadURDF(str(urdf), basePosition=(3.0, 0.0, 0.0))   # cylinder -> convex hull
    caster = RayCaster(client)
    caster.add_body(body, static=True)
    assert caster.skipped == [(body, -1)]
    assert np.isinf(caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0)[0])
    caster.remove_body(body)
    assert caster.skipped == []


# --- ray semantics ----------------------------------------------------------------------------
def wall(client, x_near, x_far, mass=0.0):
    """A box filling x_near..x_far, |y| <= 1, |z| <= 1."""
    shape = client.createCollisionShape(pybullet.GEOM_BOX,
                                        halfExtents=((x_far - x_near) / 2, 1.0, 1.0))
    return client.createMultiBody(mass, shape, basePosition=((x_near + x_far) / 2, 0, 0))


def test_box_at_known_distance_gives_analytic_range(client):
    box = wall(client, 2.0, 2.5)
    caster = RayCaster(client)
    caster.add_body(box, static=True)
    angles = np.radians([-25.0, -10.0, 0.0, 10.0, 25.0])
    directions = np.stack([np.cos(angles), np.sin(angles), np.zeros(5)], axis=1)
    ranges = caster.cast((0.0, 0.0, 0.3), directions, 0.1, 10.0)
    np.testing.assert_allclose(ranges, 2.0 / np.cos(angles), rtol=0, atol=EXACT)
    # directions need not be unit: distances are still in metres
    assert caster.cast((0, 0, 0), [(5.0, 0, 0)], 0.0, 10.0)[0] == pytest.approx(2.0, abs=EXACT)


def test_range_min_and_range_max(client):
    near = wall(client, 2.0, 2.5)
    far = wall(client, 5.0, 6.0)
    caster = RayCaster(client)
    caster.add_body(near, static=True)
    caster.add_body(far, static=True)

    def cast(range_min, range_max):
        return caster.cast((0, 0, 0), [(1, 0, 0)], range_min, range_max)[0]

    assert cast(0.1, 10.0) == pytest.approx(2.0)
    assert cast(0.1, 1.99) == np.inf                    # beyond range_max
    assert cast(0.1, 2.0) == pytest.approx(2.0)        # range_max inclusive
    assert cast(2.0, 10.0) == pytest.approx(2.0)       # range_min inclusive
    assert cast(2.2, 10.0) == pytest.approx(5.0)       # starts inside the near wall: not hit
    assert cast(3.0, 10.0) == pytest.approx(5.0)       # near wall before range_min: ignored
    assert cast(5.5, 10.0) == np.inf                    # starts inside the far wall
    assert cast(3.0, 2.0) == np.inf                     # empty range
    # Bullet agrees on the inside start and the ignored near wall
    assert bullet_ranges(client, (0, 0, 0), np.array([[1.0, 0, 0]]), 2.2, 10.0)[0] == \
        pytest.approx(5.0, abs=1e-6)


def test_exclude_body(client):
    near = wall(client, 2.0, 2.5, mass=1.0)
    far = wall(client, 5.0, 6.0)
    caster = RayCaster(client)
    caster.add_body(near, static=False)
    caster.add_body(far, static=True)
    assert caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0)[0] == pytest.approx(2.0)
    assert caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0, exclude_body=near)[0] == \
        pytest.approx(5.0)
    assert caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0, exclude_body=far)[0] == \
        pytest.approx(2.0)
    caster.remove_body(near)
    assert caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0)[0] == pytest.approx(5.0)


def test_dynamic_body_seen_where_it_moved(client):
    barrel = client.createMultiBody(
        5.0, client.createCollisionShape(pybullet.GEOM_CYLINDER, radius=0.3, height=0.9),
        basePosition=(3.0, 0.0, 0.45))
    caster = RayCaster(client)
    caster.add_body(barrel, static=False)
    ray = [(1.0, 0.0, 0.0)]
    assert caster.cast((0, 0, 0.2), ray, 0.1, 10.0)[0] == pytest.approx(2.7, abs=EXACT)
    client.resetBasePositionAndOrientation(barrel, (6.0, 0.0, 0.45), (0, 0, 0, 1))
    assert caster.cast((0, 0, 0.2), ray, 0.1, 10.0)[0] == pytest.approx(5.7, abs=EXACT)
    # falling under gravity (no ground): gone below the ray after a second
    client.setGravity(0, 0, -9.8)
    for _ in range(240):
        client.stepSimulation()
    assert caster.cast((0, 0, 0.2), ray, 0.1, 10.0)[0] == np.inf


def test_static_body_is_cached_until_added_again(client):
    box = wall(client, 2.0, 2.5)
    caster = RayCaster(client)
    caster.add_body(box, static=True)
    client.resetBasePositionAndOrientation(box, (4.25, 0, 0), (0, 0, 0, 1))
    assert caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0)[0] == pytest.approx(2.0)
    caster.add_body(box, static=True)
    assert caster.cast((0, 0, 0), [(1, 0, 0)], 0.0, 10.0)[0] == pytest.approx(4.0)


# --- a world like the tutorial's world02, and the cost of a scan ------------------------------
BARRIERS = [  # (x, y, yaw) of jersey barriers, from the reference's effective layout
    (-5.66, 9.46, 0), (-1.66, 9.36, 0), (2.40, 9.29, 0), (6.45, 9.34, 0),
    (6.71, -9.54, 0), (2.60, -9.51, 0), (-1.33, -9.51, 0), (-5.45, -9.50, 0),
    (9.45, 5.36, -1.5687), (9.37, 1.33, -1.5687), (9.43, -2.63, -1.5687), (9.45, -6.53, -1.5687),
    (-9.54, -6.33, -1.5687), (-9.62, -2.35, -1.5687), (-9.59, 1.70, -1.5687),
    (-9.45, 5.84, -1.5687), (-4.97, 4.73, 0), (-0.94, 4.73, 0), (2.99, 4.72, 0),
    (-2.28, -0.40, 0), (1.77, -0.39, 0), (-4.71, -2.79, -1.581)]
CYLINDERS = [  # (x, y, radius, height, mass): barrels and a coke can
    (9.07, 7.91, 0.3, 0.9, 500), (8.13, 8.42, 0.3, 0.9, 500), (-9.27, 8.48, 0.3, 0.9, 500),
    (-8.34, 8.94, 0.3, 0.9, 500), (9.45, -9.29, 0.3, 0.9, 500), (-8.13, -9.57, 0.3, 0.9, 500),
    (-8.94, -8.96, 0.3, 0.9, 500), (-4.40, -0.66, 0.3, 0.9, 500), (-3.01, -2.51, 0.033, 0.12, 0.4)]


def build_world02(client, scene=None):
    """Ground plane, 22 six-box jersey barriers (static) and 9 dynamic cylinders; returns
    (static bodies, dynamic bodies)."""
    length = 4.06542
    boxes = [  # (half extents, position, roll) of one barrier, in its own frame
        ((length / 2, 0.15315, 0.5715), (0, 0, 0.5715), 0.0),
        ((length / 2, 0.40535, 0.03225), (0, 0, 0.032), 0.0),
        ((length / 2, 0.325, 0.05), (0, 0, 0.1), 0.0),
        ((length / 2, 0.25, 0.05), (0, 0, 0.2), 0.0),
        ((length / 2, 0.2, 0.025), (0, 0.12, 0.35), 0.9),
        ((length / 2, 0.2, 0.025), (0, -0.12, 0.35), -0.9)]
    static, dynamic = [], []
    ground = client.createMultiBody(0, client.createCollisionShape(
        pybullet.GEOM_PLANE, planeNormal=(0, 0, 1)))
    static.append(ground)
    if scene is not None:
        scene.parts.append((ground, Pose(), lambda x: x[:, 2], True))
    for x, y, yaw in BARRIERS:
        shapes = [client.createCollisionShape(
            pybullet.GEOM_BOX, halfExtents=half, collisionFramePosition=pos,
            collisionFrameOrientation=Pose.from_xyz_rpy(roll=roll).orientation)
            for half, pos, roll in boxes]
        frame = Pose.from_xyz_rpy(x, y, 0, 0, 0, yaw)
        links = len(shapes) - 1
        body = client.createMultiBody(
            0, shapes[0], basePosition=frame.position, baseOrientation=frame.orientation,
            linkMasses=[0] * links, linkCollisionShapeIndices=shapes[1:],
            linkVisualShapeIndices=[-1] * links, linkPositions=[(0, 0, 0)] * links,
            linkOrientations=[(0, 0, 0, 1)] * links, linkInertialFramePositions=[(0, 0, 0)] * links,
            linkInertialFrameOrientations=[(0, 0, 0, 1)] * links, linkParentIndices=[0] * links,
            linkJointTypes=[pybullet.JOINT_FIXED] * links, linkJointAxis=[(0, 0, 1)] * links)
        static.append(body)
        if scene is not None:
            for half, pos, roll in boxes:
                scene.parts.append((body, frame.compose(Pose.from_xyz_rpy(*pos, roll=roll)),
                                    lambda p, h=np.array(half): sdf_box(p, h), False))
    for x, y, radius, height, mass in CYLINDERS:
        body = client.createMultiBody(mass, client.createCollisionShape(
            pybullet.GEOM_CYLINDER, radius=radius, height=height),
            basePosition=(x, y, height / 2))
        dynamic.append(body)
        if scene is not None:
            scene.parts.append((body, Pose((x, y, height / 2)),
                                lambda p, r=radius, h=height: sdf_cylinder(p, r, h), False))
    return static, dynamic


def laser_directions(yaw=0.0, samples=720):
    angles = yaw + np.linspace(-math.pi / 2, math.pi / 2, samples)
    return np.stack([np.cos(angles), np.sin(angles), np.zeros(samples)], axis=1)


def test_world02_scan_agrees_with_geometry_and_bullet(client):
    scene = Scene(client)
    static, dynamic = build_world02(client, scene)
    caster = RayCaster(client)
    for body in static:
        caster.add_body(body, static=True)
    for body in dynamic:
        caster.add_body(body, static=False)
    for origin, yaw in [((0.15, 8.0, 0.15), 0.0), ((-3.5, -1.5, 0.15), 2.5),
                        ((5.0, 0.0, 0.15), -1.2)]:
        ranges, _, _ = assert_agrees(scene, caster, origin, laser_directions(yaw), 0.1, 10.0,
                                     min_hits=0.3, min_misses=0.0)
    # from the episode's start, straight ahead (+x) passes north of the east wall and meets
    # the corner barrel at (9.07, 7.91), r 0.3
    ahead = caster.cast((0.15, 8.0, 0.15), [(1.0, 0.0, 0.0)], 0.1, 10.0)[0]
    assert ahead == pytest.approx(9.07 - math.sqrt(0.3 ** 2 - 0.09 ** 2) - 0.15, abs=EXACT)


# --- a laser's fan: each shape tried only on the beams that can reach it ---------------------
def _fan_scans(caster, origin, rotation, angle_min, increment, samples, exclude_body=None):
    """(ranges with the fan hint, ranges without) for a fan built as RaySensor builds it."""
    angles = angle_min + increment * np.arange(samples)
    beams = np.stack([np.cos(angles), np.sin(angles), np.zeros(samples)], axis=1)
    directions = beams @ rotation.T
    hinted = caster.cast(origin, directions, 0.1, 10.0, exclude_body=exclude_body,
                         fan=(rotation[:, 0], rotation[:, 1], angle_min, increment))
    plain = caster.cast(origin, directions, 0.1, 10.0, exclude_body=exclude_body)
    return hinted, plain


@pytest.mark.parametrize("name", ["world01", "world02", "world03"])
def test_fan_hint_gives_the_same_ranges_to_the_last_bit(name):
    """The culled kernel against the full one (the caster's code before the hint) on many
    laser poses in the tutorial's worlds: level and tilted, 180 and 360 degree fans, and
    fans aimed so that a beam runs exactly through a box's corner or along its face."""
    client, world = _tutorial_world(name)
    try:
        caster = world.caster
        static_shapes = caster._static()[0]
        rng = np.random.default_rng(sum(map(ord, name)))
        hits = 0
        for trial in range(300):
            origin, _, rotation, angle_min, increment, samples = _laser_pose(rng, trial)
            if trial % 2 == 1:                    # a beam exactly through a box corner
                j = rng.integers(len(static_shapes.kind))
                corner = static_shapes.position[j] + static_shapes.rotation[j] @ (
                    static_shapes.size[j] * rng.choice([-1.0, 1.0], 3))
                local = rotation.T @ (corner - origin)
                beam = rng.integers(samples)
                angle_min = math.atan2(local[1], local[0]) - beam * increment
            hinted, plain = _fan_scans(caster, origin, rotation, angle_min, increment, samples)
            assert hinted.tobytes() == plain.tobytes(), (name, trial)
            hits += np.isfinite(plain).sum()
        assert hits > 300 * 720 * 0.2             # the scans did meet the worlds' models
    finally:
        client.disconnect()


def _laser_pose(rng, trial):
    """A laser pose over one of the tutorial's worlds, drawn from `rng`: (origin (3,),
    orientation quaternion (4,), rotation (3, 3), angle_min [rad], increment [rad],
    samples); every third one tilted a little, every fourth an all-round lidar, the others
    m2wr's 180 degree laser."""
    origin = np.array([rng.uniform(-9, 9), rng.uniform(-9, 9), rng.uniform(0.05, 0.6)])
    tilt = rng.normal(0.0, 0.05, 2) if trial % 3 == 0 else (0.0, 0.0)
    orientation = np.array(pybullet.getQuaternionFromEuler(
        (*tilt, rng.uniform(-math.pi, math.pi))))
    rotation = rotation_matrices(orientation)[0]
    samples = 720
    if trial % 4 == 0:                            # lidar: all round, wrapping at +-pi
        return origin, orientation, rotation, -math.pi, 2 * math.pi / samples, samples
    return origin, orientation, rotation, -math.pi / 2, math.pi / (samples - 1), samples


def _tutorial_world(name):
    """(client, World) of one of the tutorial's worlds (disconnect the client when done)."""
    import os
    from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
    from pybullet_gazebo.engine.world import World
    src = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
    spec = load_world(os.path.join(src, "my_worlds", "worlds", name + ".world"),
                      model_path_from_env(os.path.join(src, "pybullet_gazebo", "models")))
    client = BulletClient(connection_mode=pybullet.DIRECT)
    return client, World(client, spec, 0.005, warn=lambda message: None)


def _grazing_angle(rng, shapes, origin, rotation):
    """The angle [rad] in the laser's plane (frame `rotation`, at `origin`) of a beam that
    grazes a shape: through a box's corner, or tangent to a cylinder, capsule or sphere."""
    j = rng.integers(len(shapes.kind))
    centre = shapes.position[j]
    if shapes.kind[j] == ray_kernel.BOX:
        point = centre + shapes.rotation[j] @ (shapes.size[j] * rng.choice([-1.0, 1.0], 3))
        local = rotation.T @ (point - origin)
        return math.atan2(local[1], local[0])
    local = rotation.T @ (centre - origin)
    rho = math.hypot(local[0], local[1])
    radius = shapes.size[j][0]
    side = math.asin(min(1.0, radius / rho)) if rho > radius else 0.0
    return math.atan2(local[1], local[0]) + rng.choice([-1.0, 1.0]) * side


@pytest.mark.parametrize("name", ["world01", "world02", "world03"])
def test_laser_fan_matches_the_float64_reference(name):
    """The laser's own path (ray_kernel.fan_rays lays out the beams, RayCaster.cast_fan casts
    them) against the reference: the same beams built in numpy float64 as the caster's
    tests build them, cast one shape against every ray (no culling, no hint). On many
    poses in the tutorial's worlds, level and tilted, 180 and 360 degree fans, a beam aimed
    to graze a shape (through a box corner, tangent to a barrel) in every other pose:
    - culled and unculled fans give the same ranges to the last bit;
    - every range is the reference's within 1e-9 m, or, on a beam that grazes a shape,
      the reference's answer for that beam turned by 1e-12 rad either way (the two
      lay the beams out with different roundings, ~1e-16 rad: on a grazing beam either
      answer is right)."""
    client, world = _tutorial_world(name)
    try:
        caster = world.caster
        static_shapes = caster._static()[0]
        rng = np.random.default_rng(sum(map(ord, name)) + 1)
        frame, fan = np.empty((4, 3)), np.empty(8)
        hits = grazing = 0
        trials = 300
        for trial in range(trials):
            origin, orientation, rotation, angle_min, increment, samples = \
                _laser_pose(rng, trial)
            if trial % 2 == 1:
                angle_min = _grazing_angle(rng, static_shapes, origin, rotation) \
                    - rng.integers(samples) * increment
            angles = angle_min + increment * np.arange(samples)
            cos_sin = np.ascontiguousarray(np.stack([np.cos(angles), np.sin(angles)], axis=1))
            directions = np.empty((samples, 3))
            assert ray_kernel.fan_rays(origin, orientation, np.zeros(3),
                                       np.array([0.0, 0.0, 0.0, 1.0]), cos_sin, angle_min,
                                       increment, frame, fan, directions)
            culled = caster.cast_fan(frame, directions, fan, 0.1, 10.0)
            plain = caster.cast_fan(frame, directions, fan, 0.1, 10.0, cull=False)
            assert culled.tobytes() == plain.tobytes(), (name, trial)

            def reference(turn=0.0):
                a = angles + turn
                beams = np.stack([np.cos(a), np.sin(a), np.zeros(samples)], axis=1) @ rotation.T
                return caster.cast(origin, beams, 0.1, 10.0)
            expected = reference()
            with np.errstate(invalid="ignore"):           # inf - inf where both miss
                same = (culled == expected) | (np.abs(culled - expected) <= EXACT)
            for i in np.flatnonzero(~same):
                turned = [reference(turn)[i] for turn in (-1e-12, 1e-12)]
                assert any(t == culled[i] or abs(t - culled[i]) <= EXACT for t in turned), \
                    (name, trial, i, culled[i], expected[i], turned)
                grazing += 1
            hits += np.isfinite(expected).sum()
        assert hits > trials * 720 * 0.2          # the scans did meet the worlds' models
        assert grazing <= trials                  # rare: about one beam a scan at most
    finally:
        client.disconnect()


def test_a_wrong_fan_hint_is_ignored(client):
    """A hint that does not describe the directions changes nothing."""
    caster = RayCaster(client)
    box = client.createMultiBody(0, client.createCollisionShape(pybullet.GEOM_BOX,
                                                                halfExtents=(0.5, 0.5, 0.5)),
                                 basePosition=(3.0, 0.0, 0.0))
    caster.add_body(box, static=True)
    directions = laser_directions(0.0)
    wrong = (np.array([0.0, 1.0, 0.0]), np.array([-1.0, 0.0, 0.0]), -math.pi / 2,
             math.pi / 719)                       # turned by 90 degrees
    hinted = caster.cast((0, 0, 0), directions, 0.1, 10.0, fan=wrong)
    assert hinted.tobytes() == caster.cast((0, 0, 0), directions, 0.1, 10.0).tobytes()
    assert np.isfinite(hinted).sum() > 50


def test_fan_hint_gives_the_same_ranges_on_meshes(client):
    """Triangle meshes (a world model's mesh collisions) with and without the hint, beams
    aimed through their vertices among others."""
    rng = np.random.default_rng(11)
    caster = RayCaster(client)
    vertices = []
    for index in range(12):
        triangles = rng.uniform(-0.6, 0.6, size=(8, 3, 3))
        centre = (rng.uniform(-6, 6), rng.uniform(-6, 6), rng.uniform(0.0, 0.4))
        body = client.createMultiBody(0, client.createCollisionShape(
            pybullet.GEOM_SPHERE, radius=0.01), basePosition=centre)
        caster.add_body(body, static=True,
                        base_shapes=[(pybullet.GEOM_MESH, triangles, (0.0, 0.0, 0.0),
                                      (0.0, 0.0, 0.0, 1.0))])
        vertices += list(triangles.reshape(-1, 3) + centre)
    hits = 0
    for trial in range(200):
        origin = np.array([rng.uniform(-6, 6), rng.uniform(-6, 6), rng.uniform(0.0, 0.4)])
        rotation = np.asarray(pybullet.getMatrixFromQuaternion(pybullet.getQuaternionFromEuler(
            (rng.normal(0, 0.05), rng.normal(0, 0.05), rng.uniform(-3, 3))))).reshape(3, 3)
        increment = math.pi / 719
        angle_min = -math.pi / 2
        if trial % 2:
            local = rotation.T @ (vertices[rng.integers(len(vertices))] - origin)
            angle_min = math.atan2(local[1], local[0]) - rng.integers(720) * increment
        hinted, plain = _fan_scans(caster, origin, rotation, angle_min, increment, 720)
        assert hinted.tobytes() == plain.tobytes(), trial
        hits += np.isfinite(plain).sum()
    assert hits > 200 * 720 * 0.05


def test_cached_placement_and_answers_match_a_fresh_caster_to_the_last_bit(client):
    """The caster re-places a dynamic body only when its pose changed and answers a repeated
    question about the same beams from memory while nothing moved: after every kind of move (teleported, pushed,
    falling, a linked body's joint turned, at rest) its fan gives exactly what a new caster,
    with nothing cached, gives for the same beams."""
    rng = np.random.default_rng(3)
    client.setGravity(0, 0, -9.8)
    client.createMultiBody(0.0, client.createCollisionShape(pybullet.GEOM_PLANE))
    crates = [client.createMultiBody(      # boxes: Bullet's own rays are exact on them
        2.0, client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(0.2, 0.3, 0.3)),
        basePosition=(x, y, 0.3)) for x, y in rng.uniform(-3, 3, size=(6, 2))]
    box = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(0.1, 0.4, 0.3))
    arm = client.createMultiBody(                          # a base and a link on a hinge
        1.0, box, basePosition=(2.5, 0.0, 0.3), linkMasses=[1.0],
        linkCollisionShapeIndices=[box], linkVisualShapeIndices=[-1],
        linkPositions=[(0.0, 0.8, 0.0)], linkOrientations=[(0, 0, 0, 1)],
        linkInertialFramePositions=[(0, 0, 0)], linkInertialFrameOrientations=[(0, 0, 0, 1)],
        linkParentIndices=[0], linkJointTypes=[pybullet.JOINT_REVOLUTE],
        linkJointAxis=[(0, 0, 1)])
    walls = [wall(client, 4.0, 4.5), wall(client, -4.5, -4.0)]
    dynamic = crates + [arm]

    def fresh():
        caster = RayCaster(client)
        for body in walls:
            caster.add_body(body, static=True)
        for body in dynamic:
            caster.add_body(body, static=False)
        return caster

    kept = fresh()
    angles = -math.pi + 2 * math.pi / 720 * np.arange(720)
    cos_sin = np.ascontiguousarray(np.stack([np.cos(angles), np.sin(angles)], axis=1))
    frame, fan, directions = np.empty((4, 3)), np.empty(8), np.empty((720, 3))
    assert ray_kernel.fan_rays(np.array([0.0, 0.0, 0.3]), np.array([0.0, 0.0, 0.0, 1.0]),
                               np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), cos_sin,
                               angles[0], angles[1] - angles[0], frame, fan, directions)
    seen = []
    for round_ in range(40):
        if round_ % 5 == 1:                                    # teleported
            body = crates[rng.integers(len(crates))]
            client.resetBasePositionAndOrientation(
                body, (*rng.uniform(-3, 3, size=2), 0.3), random_quaternion(rng))
        elif round_ % 5 == 2:                                  # pushed
            client.resetBaseVelocity(crates[rng.integers(len(crates))],
                                     (*rng.uniform(-2, 2, size=2), 0.0))
        elif round_ % 5 == 3:                                  # a joint turned
            client.resetJointState(arm, 0, rng.uniform(-1.5, 1.5))
        if round_ % 5 != 4:                                    # (4: nothing moves)
            for _ in range(rng.integers(1, 20)):
                client.stepSimulation()
        expected = fresh().cast_fan(frame, directions, fan, 0.1, 10.0)
        for _ in range(2):                                     # cast, then asked again
            ranges = kept.cast_fan(frame, directions, fan, 0.1, 10.0, same_rays=round_ > 0)
            np.testing.assert_array_equal(ranges, expected)
        seen.append(ranges)
        # and against Bullet's own rays, where the geometry really is
        hits = client.rayTestBatch([(0.0, 0.0, 0.3)] * 720,
                                   list(map(tuple, (0, 0, 0.3) + 10.0 * directions)))
        bullet = np.array([h[2] * 10.0 if h[0] >= 0 else np.inf for h in hits])
        clear = bullet > 0.1 + BULLET_TOLERANCE             # no ray starting inside a crate
        with np.errstate(invalid="ignore"):                 # inf - inf where both miss
            agree = (ranges == bullet) | (np.abs(ranges - bullet) <= BULLET_TOLERANCE)
        assert np.mean(agree[clear]) > 0.99, round_          # (Bullet errs on grazing beams)
    # the scene did change under the fan, or this test would prove nothing
    assert len({r.tobytes() for r in seen}) > 20


def test_compiled_rotation_matrices_are_the_plain_float_arithmetic_to_the_bit():
    """rotation_matrices runs compiled; its numbers must stay those of the plain IEEE
    operations (no fused multiply-adds, no reordering), or placed shapes and so every
    range would change in the last bits."""
    q = np.random.default_rng(5).normal(size=(2000, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    x, y, z, w = q.T
    expected = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                         2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                         2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
                        axis=1).reshape(-1, 3, 3)
    np.testing.assert_array_equal(rotation_matrices(q), expected)
    np.testing.assert_array_equal(rotation_matrices(tuple(q[7])), expected[7:8])
