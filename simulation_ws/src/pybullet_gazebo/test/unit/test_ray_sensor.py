"""RaySensor: the tutorial's laser (720 beams, -90..+90 deg, 0.1..10 m, 20 Hz, noise 0.01 m)
facing a box wall at a known distance."""
import math

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.ray_sensor import LaserScanData, RaySensor
from pybullet_gazebo.engine.raycast import RayCaster
from pybullet_gazebo.engine.specs import PluginSpec, RaySensorSpec
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.ros.plugin_names import laser_names

WALL_X = 2.0                    # [m] near face of the wall
WALL_HALF_WIDTH = 1.5           # [m] the wall spans |y| <= 1.5
SENSOR = (0.15, 0.0, 0.2)       # [m] sensor origin in the world (base at x 0, sensor pose x 0.15)
# 720 beams over a symmetric fan: none points exactly ahead; beam 360 is half a step left
AHEAD = 360
AHEAD_ANGLE = -1.570796 + 360 * (2 * 1.570796 / 719)       # [rad]


def laser_spec(**changes):
    values = dict(name="head_hokuyo_sensor", link="sensor_laser",
                  pose=Pose((0.15, 0.0, 0.05)), update_rate=20.0, samples=720,
                  min_angle=-1.570796, max_angle=1.570796, range_min=0.10, range_max=10.0,
                  resolution=0.01, noise_mean=0.0, noise_stddev=0.01,
                  plugin=PluginSpec("gazebo_ros_head_hokuyo_controller", "libgazebo_ros_laser.so",
                                    {"topicName": "/m2wr/laser/scan",
                                     "frameName": "sensor_laser"}))
    values.update(changes)
    return RaySensorSpec(**values)


@pytest.fixture
def client():
    c = BulletClient(connection_mode=pybullet.DIRECT)
    yield c
    c.disconnect()


@pytest.fixture
def scene(client):
    """A robot body (base link frame at (0, 0, 0.15), centre of mass offset, a bumper box
    in front of the sensor that the sensor must not see) and a box wall."""
    bumper = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(0.02, 0.3, 0.1),
                                         collisionFramePosition=(0.5, 0.0, 0.05))
    robot = client.createMultiBody(5.0, bumper, basePosition=(0.0, 0.0, 0.15),
                                   baseInertialFramePosition=(0.0, 0.0, 0.1))
    wall = client.createMultiBody(0.0, client.createCollisionShape(
        pybullet.GEOM_BOX, halfExtents=(0.25, WALL_HALF_WIDTH, 1.0)),
        basePosition=(WALL_X + 0.25, 0.0, 1.0))
    caster = RayCaster(client)
    caster.add_body(robot, static=False)
    caster.add_body(wall, static=True)
    return robot, caster


def analytic_ranges(spec):
    """Exact ranges from SENSOR to the wall's face, inf where a beam misses it."""
    angles = spec.min_angle + (spec.max_angle - spec.min_angle) / (spec.samples - 1) * \
        np.arange(spec.samples)
    with np.errstate(divide="ignore"):
        distance = (WALL_X - SENSOR[0]) / np.cos(angles)
    lateral = distance * np.sin(angles)
    hit = (np.cos(angles) > 0) & (np.abs(lateral) <= WALL_HALF_WIDTH) & \
        (distance <= spec.range_max)
    return np.where(hit, distance, np.inf)


def test_scan_metadata_and_exact_ranges_without_noise(client, scene):
    robot, caster = scene
    spec = laser_spec(noise_stddev=0.0)
    sensor = RaySensor(client, robot, -1, spec, caster, np.random.default_rng(0))
    assert laser_names(sensor.plugin_params, spec.link) == ("/m2wr/laser/scan", "sensor_laser")
    scan = sensor.measure(1.25)
    assert isinstance(scan, LaserScanData)
    assert scan.stamp == 1.25
    assert scan.angle_min == pytest.approx(-1.570796)
    assert scan.angle_max == pytest.approx(1.570796)
    assert scan.angle_increment == pytest.approx(2 * 1.570796 / 719)
    assert scan.angle_min + 719 * scan.angle_increment == pytest.approx(scan.angle_max)
    assert scan.time_increment == 0.0 and scan.scan_time == pytest.approx(0.05)
    assert (scan.range_min, scan.range_max) == (0.10, 10.0)
    assert scan.ranges.dtype == np.float32 and scan.ranges.shape == (720,)

    expected = analytic_ranges(spec)
    hit = np.isfinite(expected)
    assert 200 < hit.sum() < 700                      # a wall in front, open space aside
    np.testing.assert_array_equal(np.isfinite(scan.ranges), hit)
    np.testing.assert_allclose(scan.ranges[hit], expected[hit].astype(np.float32), rtol=0,
                               atol=1e-6)
    # index 360 looks (almost) straight ahead (+x), 0 to the right (-y): open space there
    assert scan.ranges[AHEAD] == pytest.approx((WALL_X - SENSOR[0]) / math.cos(AHEAD_ANGLE),
                                               abs=1e-6)
    assert np.isinf(scan.ranges[0]) and np.isinf(scan.ranges[719])


def test_noise_on_hits_only_and_seedable(client, scene):
    robot, caster = scene
    spec = laser_spec()
    expected = analytic_ranges(spec)
    hit = np.isfinite(expected)

    def scan(seed):
        sensor = RaySensor(client, robot, -1, spec, caster, np.random.default_rng(seed))
        return sensor.measure(0.0).ranges

    ranges = scan(42)
    np.testing.assert_array_equal(np.isfinite(ranges), hit)      # open space stays +inf
    error = ranges[hit] - expected[hit]
    assert np.max(np.abs(error)) <= 0.04
    assert 0.007 < np.std(error) < 0.013 and abs(np.mean(error)) < 0.003
    np.testing.assert_array_equal(scan(42), ranges)                # same seed, same scan
    assert not np.array_equal(scan(43)[hit], ranges[hit])


def test_noise_mean_shifts_hits(client, scene):
    robot, caster = scene
    spec = laser_spec(noise_mean=0.05, noise_stddev=0.0)
    sensor = RaySensor(client, robot, -1, spec, caster, np.random.default_rng(0))
    ranges = sensor.measure(0.0).ranges
    expected = analytic_ranges(spec)
    hit = np.isfinite(expected)
    np.testing.assert_allclose(ranges[hit], expected[hit] + 0.05, rtol=0, atol=1e-6)


def test_own_body_is_never_hit(client, scene):
    """The bumper box 0.5 m ahead of the base would be seen at 0.33 m if not excluded."""
    robot, caster = scene
    sensor = RaySensor(client, robot, -1, laser_spec(noise_stddev=0.0), caster,
                       np.random.default_rng(0))
    assert sensor.measure(0.0).ranges[AHEAD] == pytest.approx(
        (WALL_X - SENSOR[0]) / math.cos(AHEAD_ANGLE), abs=1e-6)
    bumper_seen = caster.cast(SENSOR, [(1.0, 0.0, 0.0)], 0.1, 10.0)[0]
    assert bumper_seen == pytest.approx(0.5 - 0.02 - 0.15, abs=1e-9)


def test_sensor_follows_the_body(client, scene):
    """Turned 90 deg left, the wall is to the right: beam 0 (-90 deg) looks at it."""
    robot, caster = scene
    sensor = RaySensor(client, robot, -1, laser_spec(noise_stddev=0.0), caster,
                       np.random.default_rng(0))
    # base link frame at (1.0, 0, 0.15) turned +90 deg; sensor at (1.0, 0.15, 0.2)
    yaw = Pose.from_xyz_rpy(yaw=math.pi / 2).orientation
    com = Pose((1.0, 0.0, 0.15), yaw).compose(Pose((0.0, 0.0, 0.1)))
    client.resetBasePositionAndOrientation(robot, com.position, com.orientation)
    ranges = sensor.measure(0.0).ranges
    assert ranges[0] == pytest.approx(WALL_X - 1.0, abs=1e-6)
    assert np.isinf(ranges[719])


def test_sensor_on_a_child_link(client, tmp_path):
    """The m2wr layout: sensor_laser on a fixed joint at (0.15, 0, 0.05) of the chassis."""
    urdf = tmp_path / "bot.urdf"
    urdf.write_text("""<robot name="bot">
 <link name="link_chassis">
  <inertial><origin xyz="0 0 0.1"/><mass value="5"/>
   <inertia ixx="0.04" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><box size="0.5 0.3 0.07"/></geometry></collision>
 </link>
 <link name="sensor_laser">
  <inertial><mass value="1"/>
   <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision>
 </link>
 <joint name="joint_sensor_laser" type="fixed"><parent link="link_chassis"/>
  <child link="sensor_laser"/><origin xyz="0.15 0 0.05"/></joint>
</robot>""")
    body = client.loadURDF(str(urdf), basePosition=(-1.0, 0.5, 0.1),
                           flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
    wall = client.createMultiBody(0.0, client.createCollisionShape(
        pybullet.GEOM_BOX, halfExtents=(0.25, 3.0, 1.0)), basePosition=(2.25, 0.0, 1.0))
    caster = RayCaster(client)
    caster.add_body(body, static=False)
    caster.add_body(wall, static=True)
    spec = laser_spec(pose=Pose(), noise_stddev=0.0,
                      plugin=PluginSpec("laser", "libgazebo_ros_laser.so", {}))
    sensor = RaySensor(client, body, 0, spec, caster, np.random.default_rng(0))
    # no frameName: the link's name; no topicName: gazebo_ros_laser's default
    assert laser_names(sensor.plugin_params, spec.link) == ("/world", "sensor_laser")
    scan = sensor.measure(0.0)
    assert scan.ranges[AHEAD] == pytest.approx(2.85 / math.cos(AHEAD_ANGLE), abs=1e-6)
    angle = spec.min_angle + 500 * sensor.angle_increment
    assert scan.ranges[500] == pytest.approx(2.85 / math.cos(angle), abs=1e-6)


def test_due_cadence_at_20_hz_and_reset(client, scene):
    robot, caster = scene
    sensor = RaySensor(client, robot, -1, laser_spec(), caster, np.random.default_rng(0))
    step = 0.005                                      # [s]
    stamps = []
    for k in range(400):                              # 2 s of sim time
        now = k * step
        if sensor.due(now):
            stamps.append(sensor.measure(now).stamp)
    assert len(stamps) == 40
    np.testing.assert_allclose(np.diff(stamps), 0.05, atol=1e-9)
    assert stamps[0] == 0.0
    assert not sensor.due(stamps[-1] + 0.045)
    sensor.reset()
    assert sensor.due(stamps[-1] + 0.001)
    sensor.measure(5.0)
    assert sensor.due(0.0)                            # sim time went back (reset_simulation)


def test_update_rate_zero_is_every_step(client, scene):
    robot, caster = scene
    sensor = RaySensor(client, robot, -1, laser_spec(update_rate=0.0), caster,
                       np.random.default_rng(0))
    sensor.measure(0.0)
    assert sensor.due(0.0) and sensor.due(0.001)


@pytest.mark.parametrize("changes,message", [
    (dict(samples=0), "samples"),
    (dict(min_angle=1.0, max_angle=-1.0), "max_angle"),
    (dict(range_min=5.0, range_max=1.0), "range"),
    (dict(update_rate=-1.0), "update_rate"),
])
def test_bad_specs_are_refused_by_name(client, scene, changes, message):
    robot, caster = scene
    with pytest.raises(ValueError, match=message) as err:
        RaySensor(client, robot, -1, laser_spec(**changes), caster, np.random.default_rng(0))
    assert "head_hokuyo_sensor" in str(err.value)


def test_a_sensor_at_rest_sees_a_body_moved_or_pushed_into_its_fan(client, scene):
    """The robot stands still (its rays and the last scan are reused while nothing moves);
    a barrel teleported into the beams, then pushed along them, shows in the very next scan
    where its geometry puts it, the scan goes back to the wall once it is taken away, and
    the beams follow the robot once it moves."""
    robot, caster = scene
    barrel = client.createMultiBody(2.0, client.createCollisionShape(
        pybullet.GEOM_CYLINDER, radius=0.2, height=0.6), basePosition=(0.0, 5.0, 0.3))
    caster.add_body(barrel, static=False)
    sensor = RaySensor(client, robot, -1, laser_spec(noise_stddev=0.0), caster,
                       np.random.default_rng(0))
    to_wall = (WALL_X - SENSOR[0]) / math.cos(AHEAD_ANGLE)
    assert sensor.measure(0.0).ranges[AHEAD] == pytest.approx(to_wall, abs=1e-6)
    assert sensor.measure(0.05).ranges[AHEAD] == pytest.approx(to_wall, abs=1e-6)

    def barrel_face(x):
        """Range along beam AHEAD to a barrel of radius 0.2 centred at (x, 0)."""
        d = np.array([math.cos(AHEAD_ANGLE), math.sin(AHEAD_ANGLE)])
        c = np.array([x - SENSOR[0], 0.0])
        along = c @ d
        return along - math.sqrt(0.2 ** 2 - (c @ c - along ** 2))

    client.resetBasePositionAndOrientation(barrel, (1.0, 0.0, 0.3), (0, 0, 0, 1))
    assert sensor.measure(0.1).ranges[AHEAD] == pytest.approx(barrel_face(1.0), abs=1e-6)
    client.resetBaseVelocity(barrel, (1.0, 0.0, 0.0))           # pushed away, no gravity
    for _ in range(60):
        client.stepSimulation()                                  # 0.25 s at 240 Hz
    x = client.getBasePositionAndOrientation(barrel)[0][0]
    assert 1.2 < x < 1.3
    assert sensor.measure(0.15).ranges[AHEAD] == pytest.approx(barrel_face(x), abs=1e-6)
    client.resetBasePositionAndOrientation(barrel, (0.0, 5.0, 0.3), (0, 0, 0, 1))
    assert sensor.measure(0.2).ranges[AHEAD] == pytest.approx(to_wall, abs=1e-6)
    # and once the robot itself turns 90 deg left in place, its beams turn with it
    yaw = Pose.from_xyz_rpy(yaw=math.pi / 2).orientation
    com = Pose((1.0, 0.0, 0.15), yaw).compose(Pose((0.0, 0.0, 0.1)))
    client.resetBasePositionAndOrientation(robot, com.position, com.orientation)
    assert sensor.measure(0.25).ranges[0] == pytest.approx(WALL_X - 1.0, abs=1e-6)


def test_a_scan_at_rest_draws_its_noise_anew(client, scene):
    """Reusing the cast of a robot at rest does not reuse its noise: every scan takes one
    draw per beam from the generator, as a scan cast anew would."""
    robot, caster = scene
    sensor = RaySensor(client, robot, -1, laser_spec(), caster, np.random.default_rng(7))
    first, second = sensor.measure(0.0).ranges, sensor.measure(0.05).ranges
    reference = np.random.default_rng(7)
    expected = analytic_ranges(laser_spec())
    hit = np.isfinite(expected)
    for ranges in (first, second):
        normals = reference.standard_normal(720)
        np.testing.assert_allclose(ranges[hit], expected[hit] + 0.01 * normals[hit], rtol=0,
                                   atol=1e-6)
    assert not np.array_equal(first[hit], second[hit])
