"""The benchmark's engine-only figures (no ROS): world02 + m2wr in a DIRECT pybullet client,
stepped by Bullet alone and by the engine's World (physics, drive, odometry, laser), and the
cost of one 720-beam scan by the engine's ray caster and by Bullet's own rayTestBatch over
the same beams."""
import time

import numpy as np

from ..names import DEFAULT_START, DEFAULT_WORLD, ROBOT

WORLD, START = DEFAULT_WORLD, DEFAULT_START
def engine_figures(steps=2000, scans=300):
    """Physics and scan costs of world02 + m2wr in a DIRECT client, no ROS."""
    import pybullet
    from pybullet_gazebo.engine.client import Client
    from pybullet_gazebo.engine.diff_drive import DiffDrive
    from pybullet_gazebo.engine.ray_sensor import RaySensor
    from pybullet_gazebo.engine.sdf_world import load_world
    from pybullet_gazebo.engine.transforms import Pose
    from pybullet_gazebo.engine.world import World
    from .. import paths

    spec = load_world(paths.world_path(WORLD), paths.model_path())
    urdf = paths.robot_urdf()
    step = 0.005      # [s] the simulator's default max_step_size
    client = Client(connection_mode=pybullet.DIRECT)
    try:
        world = World(client, spec, step, warn=lambda _m: None)
        robot = world.spawn_urdf(ROBOT, urdf, Pose.from_xyz_rpy(START[0], START[1], 0.5,
                                                                 0, 0, START[2]))
        for _ in range(200):            # lands on its wheels
            world.step()
        for drive in robot.parts_with(DiffDrive.KEY):
            drive.set_command(0.0, 0.3)      # turning on the spot: wheels in contact
        t = time.perf_counter()
        for _ in range(steps):
            client.stepSimulation()
        physics = time.perf_counter() - t
        t = time.perf_counter()
        for _ in range(steps):
            world.step()
        engine = time.perf_counter() - t
        sensor = robot.parts_with(RaySensor.KEY)[0]
        # a physics step before each scan, timed apart: the robot turns, so every scan is a
        # real cast (scans from an unchanged pose reuse the last cast), and it meets the
        # caches as Bullet's step leaves them, as in the loop
        scan = 0.0
        for _ in range(scans):
            client.stepSimulation()
            t = time.perf_counter()
            sensor.measure(world.sim_time)
            scan += time.perf_counter() - t
        scan /= scans
        bullet_scan = bullet_ray_test_ms(client, sensor, max(1, scans // 6))
    finally:
        client.disconnect()
    return {
        "physics_only": {"steps_per_s": steps / physics, "x_real_time": steps * step / physics,
                         "us_per_step": 1e6 * physics / steps, "steps": steps},
        "engine_step": {"steps_per_s": steps / engine, "x_real_time": steps * step / engine,
                        "us_per_step": 1e6 * engine / steps, "steps": steps,
                        "what": "World.step: physics + diff drive + odometry 20 Hz + laser 20 Hz"},
        "scan": {"ms_mean": 1e3 * scan, "scans": scans, "beams": 720,
                 "bullet_ray_test_ms_mean": bullet_scan},
        "step_size_s": step,
    }




def bullet_ray_test_ms(client, sensor, casts):
    """Mean cost [ms] of Bullet's rayTestBatch over the sensor's beams from its pose now (what
    the engine's caster replaces)."""
    spec = sensor.spec
    pose = sensor.sensor_pose()
    count = int(round((spec.max_angle - spec.min_angle) / sensor.angle_increment)) + 1
    angles = np.linspace(spec.min_angle, spec.max_angle, count)
    beams = np.stack([np.cos(angles), np.sin(angles), np.zeros(count)], axis=1) @ pose.matrix.T
    origin = np.asarray(pose.position)
    starts = (origin + spec.range_min * beams).tolist()
    ends = (origin + spec.range_max * beams).tolist()
    t = time.perf_counter()
    for _ in range(casts):
        client.rayTestBatch(starts, ends)
    return 1e3 * (time.perf_counter() - t) / casts
