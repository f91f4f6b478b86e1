"""The engine's World, without ROS: world02 and the tutorial's m2wr from its own xacro."""
import math
import os

import numpy as np
import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.ray_sensor import RaySensor
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose, wrap_angle
from pybullet_gazebo.engine.world import ModelNotFound, SpawnError, World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
MODELS = os.path.join(SRC, "pybullet_gazebo", "models")
STEP = 0.005   # [s]


def world_spec(name):
    if name == "empty":
        path = os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world")
    else:
        path = os.path.join(SRC, "my_worlds", "worlds", name + ".world")
    return load_world(path, model_path_from_env(MODELS))


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture
def make_world():
    clients = []

    def make(name="empty", seed=0):
        client = BulletClient(connection_mode=pybullet.DIRECT)
        clients.append(client)
        warnings = []
        world = World(client, world_spec(name), STEP, seed=seed, warn=warnings.append)
        world.warnings = warnings
        return world
    yield make
    for client in clients:
        client.disconnect()


def component(robot, kind):
    return next(c for c in robot.parts if isinstance(c, kind))


def run(world, seconds):
    readings = []
    for _ in range(int(round(seconds / STEP))):
        readings.extend(world.step())
    return readings


def test_world02_has_every_model_and_the_ground(make_world):
    world = make_world("world02")
    names = world.model_names()
    assert len(names) == 32
    assert sum(world.entity(n).is_ground for n in names) == 1
    assert world.model_pose("jersey_barrier_0").position[1] == pytest.approx(9.36)


def test_m2wr_settles_where_spawned_and_reports_its_turn_direction(make_world, m2wr_urdf):
    world = make_world("world02")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.5))
    run(world, 2.0)
    pose = world.model_pose("m2wr")
    assert pose.position[0] == pytest.approx(0.0, abs=0.01)
    assert pose.position[1] == pytest.approx(8.0, abs=0.01)
    assert pose.position[2] == pytest.approx(0.1, abs=0.005)   # chassis frame at wheel axle
    assert world.positive_turn_direction(robot) == "clockwise"
    assert any("<torque>" in w for w in world.warnings)


def test_robot_at_rest_stays_put(make_world, m2wr_urdf):
    world = make_world("empty")
    world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    run(world, 2.0)
    before = world.model_pose("m2wr")
    run(world, 20.0)
    after = world.model_pose("m2wr")
    assert math.dist(before.position, after.position) < 0.005
    assert abs(after.rpy[2] - before.rpy[2]) < 0.001


FRICTIONLESS_CASTER = ('<gazebo reference="link_chassis"><mu1>0</mu1><mu2>0</mu2></gazebo>'
                       '</robot>')


def test_turn_on_the_spot_uses_the_real_track_width(make_world, m2wr_urdf):
    """(0, 0.3): rims at +-0.06 m/s on a 0.3 m track -> 0.4 rad/s clockwise, steadily (each
    wheel meets the ground at its mid-plane, not at a rim edge). The wheels alone: the caster
    is made frictionless the way Gazebo reads it, <gazebo reference> mu1/mu2 0."""
    world = make_world("empty")
    urdf = m2wr_urdf.replace("</robot>", FRICTIONLESS_CASTER)
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    run(world, 1.0)
    component(robot, DiffDrive).set_command(0.0, 0.3)
    run(world, 1.0)
    for _ in range(4):
        start = world.model_pose("m2wr").rpy[2]
        run(world, 1.0)
        turned = wrap_angle(world.model_pose("m2wr").rpy[2] - start)
        assert turned == pytest.approx(-0.4, abs=0.01)


def test_turn_on_the_spot_drags_the_caster_and_keeps_near_the_commanded_rate(make_world,
                                                                            m2wr_urdf):
    """The tutorial's m2wr as it is: its caster has Gazebo's mu 1 (the xacro's mu 0 is never
    read) and is dragged sideways, which takes about 1.5 N m of each wheel's 5 N m. The rate
    stays near 0.4 rad/s clockwise, a little under it: Bullet's solver (50 iterations) leaves
    the wheel motors short under that load (0.34 to 0.39 rad/s over 1 s windows; 200
    iterations give 0.397 to 0.400)."""
    world = make_world("empty")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    run(world, 1.0)
    component(robot, DiffDrive).set_command(0.0, 0.3)
    run(world, 1.0)
    turned = 0.0
    for _ in range(8):
        start = world.model_pose("m2wr").rpy[2]
        run(world, 1.0)
        turned += wrap_angle(world.model_pose("m2wr").rpy[2] - start)
    assert turned / 8.0 == pytest.approx(-0.4, rel=0.1)     # 8 s of it: -0.372 here


def test_duplicate_name_fails_and_leaves_the_first_alone(make_world, m2wr_urdf):
    world = make_world("empty")
    world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    run(world, 1.0)
    before = world.model_pose("m2wr")
    with pytest.raises(SpawnError, match="already exists"):
        world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(3, 0, 0.5))
    assert world.model_pose("m2wr") == before
    assert world.model_names().count("m2wr") == 1


def test_spawn_inside_an_obstacle_is_spawned_with_a_warning_naming_both(make_world, m2wr_urdf):
    """Gazebo spawns a model that overlaps another; so does the stand-in, and says so."""
    world = make_world("world02")
    bodies = world.client.getNumBodies()
    world.spawn_urdf("stuck", m2wr_urdf, Pose.from_xyz_rpy(-0.94, 4.73, 0.2))
    assert world.client.getNumBodies() == bodies + 1
    assert "stuck" in world.model_names()
    assert any("'stuck' inside 'jersey_barrier" in w and "spawned anyway" in w
               for w in world.warnings)
    run(world, 0.5)
    assert all(math.isfinite(v) for v in world.model_pose("stuck").position)


@pytest.mark.parametrize("text, message", [
    ("", "empty"),
    ("<robot name='x'><link name='a'>", "line"),
    ("<robot name='x'/>", "link"),
])
def test_bad_descriptions_are_refused(make_world, text, message):
    world = make_world("empty")
    with pytest.raises(SpawnError, match=message):
        world.spawn_urdf("bad", text, Pose())
    assert world.model_names() == ["ground_plane"]


def test_non_finite_spawn_pose_is_refused(make_world, m2wr_urdf):
    world = make_world("empty")
    with pytest.raises(SpawnError, match="not finite"):
        world.spawn_urdf("m2wr", m2wr_urdf, Pose((0.0, float("nan"), 0.5)))


def test_set_and_get_model_state_round_trip(make_world):
    world = make_world("world02")
    target = Pose.from_xyz_rpy(1.5, 2.5, 0.0, 0, 0, 0.7)
    world.set_model_state("coke_can", target)
    got = world.model_pose("coke_can")
    assert got.position == pytest.approx(target.position, abs=1e-9)
    assert got.orientation == pytest.approx(target.orientation, abs=1e-9)
    with pytest.raises(ModelNotFound, match="no_such_model"):
        world.model_pose("no_such_model")
    with pytest.raises(ValueError, match="non-finite"):
        world.set_model_state("coke_can", Pose((float("inf"), 0.0, 0.0)))


def test_reset_simulation_restores_poses_and_time(make_world, m2wr_urdf):
    world = make_world("empty")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    component(robot, DiffDrive).set_command(0.6, 0.0)
    run(world, 2.0)
    # 0.6 m/s, less the spinning wheels' slip on landing from 0.5 m (wheel-ground mu 1)
    assert world.model_pose("m2wr").position[0] > 0.9
    world.reset_simulation()
    assert world.sim_time == 0.0
    assert world.model_pose("m2wr").position == pytest.approx((0.0, 0.0, 0.5), abs=1e-9)
    assert component(robot, DiffDrive).command == (0.0, 0.0)


def test_driving_into_a_barrier_is_counted_as_a_contact(make_world, m2wr_urdf):
    world = make_world("world02")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 7.0, 0.5, 0, 0, -math.pi / 2))
    run(world, 1.0)
    assert world.contact_events == []
    component(robot, DiffDrive).set_command(0.5, 0.0)        # row A's face is ~1.7 m ahead
    run(world, 6.0)
    first = world.contact_events[0]
    assert first.robot == "m2wr" and first.other.startswith("jersey_barrier")
    assert 3.0 < first.sim_time < 7.0                         # 1.6 m at 0.5 m/s after 1 s
    assert world.touching()


def test_scans_and_odometry_come_at_their_rates(make_world, m2wr_urdf):
    world = make_world("world02")
    world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.5))
    readings = run(world, 2.0)
    scans = [r for r in readings if isinstance(r.part, RaySensor)]
    odometry = [r for r in readings if isinstance(r.part, DiffDrive)]
    assert len(scans) == 40
    assert len(odometry) == 40
    assert len(scans[-1].data.ranges) == 720


def test_same_seed_and_commands_give_identical_runs(make_world, m2wr_urdf):
    def trajectory(seed):
        world = make_world("world02", seed=seed)
        robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.5))
        drive = component(robot, DiffDrive)
        poses, scans = [], []
        for second in range(6):
            drive.set_command(0.6 if second % 2 == 0 else 0.0, 0.3 if second % 3 == 0 else 0.0)
            for reading in run(world, 1.0):
                if isinstance(reading.part, RaySensor):
                    scans.append(reading.data.ranges.copy())
            poses.append(world.model_pose("m2wr"))
        return poses, np.array(scans)

    poses_a, scans_a = trajectory(seed=7)
    poses_b, scans_b = trajectory(seed=7)
    poses_c, scans_c = trajectory(seed=8)
    assert poses_a == poses_b
    assert np.array_equal(scans_a, scans_b)
    assert not np.array_equal(scans_a, scans_c)             # the noise follows the seed


def test_a_run_after_reset_simulation_repeats_the_first(make_world, m2wr_urdf):
    """What a batch or a Gym episode does: the same commands after reset_simulation give the
    same trajectory (the drive's standing state, e.g. its friction anchors, starts over)."""
    world = make_world("world02", seed=3)
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.5))
    drive = component(robot, DiffDrive)

    def trajectory():
        poses = []
        for second in range(4):        # lands and stands, drives, stands, turns
            drive.set_command(0.5 if second % 2 == 1 else 0.0, 0.4 if second == 3 else 0.0)
            run(world, 0.5)
            poses.append(world.model_pose("m2wr"))
        return poses

    first = trajectory()
    world.reset_simulation()
    assert trajectory() == first


def test_dynamic_world_models_keep_their_sdf_mass_and_inertia_and_stay_at_rest(make_world):
    world = make_world("world02")
    dynamic = [m for m in world_spec("world02").models if not m.static]
    assert {m.name for m in dynamic} >= {"coke_can", "construction_barrel"}
    start = {m.name: world.model_pose(m.name).position for m in dynamic}
    for model in dynamic:
        mass, _, inertia = world.client.getDynamicsInfo(world.entity(model.name).body_ids[0],
                                                        -1)[:3]
        assert mass == pytest.approx(model.links[0].inertial.mass)
        assert inertia == pytest.approx(model.links[0].inertial.inertia)
    run(world, 2.0)
    for model in dynamic:
        assert world.model_pose(model.name).position == pytest.approx(start[model.name],
                                                                      abs=1e-3)


def test_the_ground_is_only_tested_against_models_that_can_move(make_world):
    world = make_world("world02")
    run(world, 0.1)
    ground = world.entity("ground_plane").body_ids[0]
    owner = {body: name for name in world.model_names() for body in world.entity(name).body_ids}
    touching = {owner[point[2]] for point in world.client.getContactPoints(bodyA=ground)}
    assert "coke_can" in touching
    assert [name for name in touching if world.entity(name).static] == []


def test_the_laser_sees_a_static_model_where_set_model_state_put_it(make_world, m2wr_urdf):
    world = make_world("world02")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(-6, 2, 0.5))   # open floor
    run(world, 0.5)
    laser = component(robot, RaySensor)
    ahead = len(laser.measure(world.sim_time).ranges) // 2           # the beam along +x
    assert laser.measure(world.sim_time).ranges[ahead] > 3.0
    assert world.entity("jersey_barrier").static
    world.set_model_state("jersey_barrier", Pose.from_xyz_rpy(-4.0, 2.0, 0.0, 0, 0, math.pi / 2))
    assert 1.2 < laser.measure(world.sim_time).ranges[ahead] < 2.0


def test_reset_world_puts_moved_static_models_back_where_the_laser_sees_them(make_world):
    """reset_world refreshes the ray caster's static shapes once for all models; a static
    model moved away is hit again at its initial place."""
    world = make_world("world02")
    name, entity = next((n, e) for n, e in world.entities.items()
                        if e.static and not e.is_ground)
    x, y, _ = world.model_pose(name).position
    down = np.array([[0.0, 0.0, -1.0]])

    def height_below(px, py):
        return world.caster.cast((px, py, 20.0), down, 0.0, 40.0)[0]
    seen = height_below(x, y)
    world.set_model_state(name, Pose((x + 50.0, y + 50.0, 0.0)))
    assert height_below(x, y) > seen + 1e-3          # gone from there
    world.reset_world()
    assert height_below(x, y) == pytest.approx(seen, abs=1e-9)
