"""A robot told to stand still stands still (Bullet's motor and friction used to let m2wr
roll backwards at 6e-5 m/s: 0.2 m per hour of sim time). DIRECT mode, no ROS."""
import math
import os

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005            # [s]

MAX_CREEP = 1e-6        # [m/s] the bound
MAX_TURN = 1e-6         # [rad/s]


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture
def make_world():
    clients = []

    def make(name):
        if name == "empty":
            path = os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world")
        else:
            path = os.path.join(SRC, "my_worlds", "worlds", name + ".world")
        models = model_path_from_env(os.path.join(SRC, "pybullet_gazebo", "models"))
        clients.append(BulletClient(connection_mode=pybullet.DIRECT))
        return World(clients[-1], load_world(path, models), STEP, warn=lambda m: None)
    yield make
    for client in clients:
        client.disconnect()


def run(world, seconds):
    for _ in range(int(round(seconds / STEP))):
        world.step()


def component(robot, kind):
    return next(p for p in robot.parts if isinstance(p, kind))


def drift_over(world, seconds):
    """(speed [m/s], turn rate [rad/s]) of m2wr averaged over `seconds` of sim time."""
    before = world.model_pose("m2wr")
    run(world, seconds)
    after = world.model_pose("m2wr")
    turned = math.atan2(math.sin(after.rpy[2] - before.rpy[2]),
                        math.cos(after.rpy[2] - before.rpy[2]))
    return math.dist(before.position[:2], after.position[:2]) / seconds, abs(turned) / seconds


def test_a_robot_never_commanded_does_not_creep_over_60_s(make_world, m2wr_urdf):
    world = make_world("empty")
    world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    run(world, 2.0)                                  # dropped from 0.5 m: let it settle
    speed, turn = drift_over(world, 60.0)
    assert speed < MAX_CREEP
    assert turn < MAX_TURN


def test_a_robot_stopped_after_driving_and_turning_stays_where_it_stopped(make_world, m2wr_urdf):
    world = make_world("world02")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.5))
    drive = component(robot, DiffDrive)
    run(world, 1.0)
    drive.set_command(0.4, 0.2)
    run(world, 2.0)
    moved_from = world.model_pose("m2wr").position
    drive.set_command(0.0, 0.0)
    run(world, 1.0)                                  # brakes within the motor's torque
    assert math.dist(moved_from[:2], world.model_pose("m2wr").position[:2]) < 0.2
    run(world, 10.0)                                 # the turn's sway dies out (~1 s decay)
    speed, turn = drift_over(world, 60.0)
    assert speed < MAX_CREEP
    assert turn < MAX_TURN


def test_a_stopped_robot_teleported_stays_where_it_was_put(make_world, m2wr_urdf):
    """set_model_state zeroes the wheel joints: the hold must not pull them back to the
    angles they stopped at (the robot would roll away from where it was put)."""
    world = make_world("empty")
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    drive = component(robot, DiffDrive)
    run(world, 1.0)
    drive.set_command(0.5, 0.0)
    run(world, 2.0)                                  # wheels turned ~10 rad
    drive.set_command(0.0, 0.0)
    run(world, 1.0)
    world.set_model_state("m2wr", Pose.from_xyz_rpy(2.0, 3.0, 0.1))
    run(world, 1.0)
    assert world.model_pose("m2wr").position[:2] == pytest.approx((2.0, 3.0), abs=0.01)
    speed, _ = drift_over(world, 20.0)
    assert speed < MAX_CREEP


def test_a_reset_repeats_the_run_whatever_state_it_interrupted(make_world, m2wr_urdf):
    """reset_simulation + set_model_state, then the same commands, give the same trajectory
    however long the robot stood before the reset: Bullet's cached contact points (friction
    anchors of a standing robot) do not survive the teleport. Before the fix, standing 5
    steps before the reset moved the next run by 7 mm and its first scan by 7.5 cm."""
    commands = [(0.5, 0.0)] * 15 + [(0.3, 0.6)] * 15 + [(0.0, -0.8)] * 15 + [(0.5, 0.0)] * 15
    start = Pose.from_xyz_rpy(0.0, 8.0, 0.1, 0.0, 0.0, 0.0)

    def episode(world, drive):
        path = []
        for command in commands:
            drive.set_command(*command)
            run(world, 0.1)
            pose = world.model_pose("m2wr")
            path.append((pose.position[0], pose.position[1], pose.rpy[2]))
        return path

    paths = []
    for standing_steps in (0, 5):
        world = make_world("world02")
        drive = component(world.spawn_urdf("m2wr", m2wr_urdf, start), DiffDrive)
        world.step()
        episode(world, drive)
        drive.set_command(0.0, 0.0)
        for _ in range(standing_steps):
            world.step()
        world.reset_simulation()
        world.set_model_state("m2wr", start)
        world.step()
        paths.append(episode(world, drive))
    assert paths[1] == paths[0]


def test_a_robot_pressed_against_a_barrier_end_turns_free_with_gazebos_friction(make_world,
                                                                                m2wr_urdf):
    """Issue 15's wedge: m2wr driven into the east end of world02's row A (x 5.02), then told
    to turn in place. With Gazebo's wheel-ground friction (mu 1) it turns free; with Bullet's
    product before (1 x 100, capped at 10) half of these poses stayed pinned (6 of 12 turned
    under 1 rad in 10 s). One pose still blocks when turned one way: the chassis corner
    swings into the barrier's face (rigid geometry); the other way it turns free."""
    pressed, turned_far = 0, 0
    for y in (4.45, 4.65, 4.81, 5.01):
        for yaw in (math.pi - 0.4, math.pi, math.pi + 0.4):
            angles = []
            for turn in (0.8, -0.8):
                world = make_world("world02")
                drive = component(world.spawn_urdf(
                    "m2wr", m2wr_urdf, Pose.from_xyz_rpy(6.0, y, 0.1, 0.0, 0.0, yaw)), DiffDrive)
                world.step()
                drive.set_command(0.5, 0.0)
                run(world, 4.0)                                   # into the barrier's end
                if not world.touching():
                    break
                drive.set_command(0.0, turn)
                turned, last = 0.0, world.model_pose("m2wr").rpy[2]
                for _ in range(100):                               # 10 s, turning in place
                    run(world, 0.1)
                    now = world.model_pose("m2wr").rpy[2]
                    turned += math.atan2(math.sin(now - last), math.cos(now - last))
                    last = now
                angles.append(abs(turned))
            if len(angles) == 2:
                pressed += 2
                turned_far += sum(a > 1.0 for a in angles)
                assert max(angles) > 1.0, (y, yaw, angles)         # one way always frees it
    assert pressed >= 6 and turned_far >= pressed - 1, (pressed, turned_far)
