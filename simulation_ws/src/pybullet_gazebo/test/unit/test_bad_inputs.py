"""The engine's World refuses bad spawns and bad model states with a clear error and leaves the
world as it was; a huge drive command is clamped and the state stays finite, in the world and
out of the obstacles.

What "clamped" means: DiffDrive caps each wheel's target speed at its URDF <limit velocity>
(1000 rad/s for m2wr, i.e. 100 m/s at the rim) and drives it with the plugin's torque (5 N m);
Bullet in turn never turns a joint faster than its maxJointVelocity (100 rad/s by default).
Under such a command m2wr rears up and may turn over (physics, as in Gazebo); what must hold is
a finite state, no penetration into an obstacle, and a speed far below what would let it jump
through a barrier in one step.
"""
import math
import os

import numpy as np
import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.placement import MAX_COORDINATE
from pybullet_gazebo.engine.world import SpawnError, World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005                        # [s]
BARRIER_THICKNESS = 0.3063          # [m] upright box of a jersey barrier
WALL_LIMIT = 9.5                    # [m] every perimeter barrier's centre line is beyond +-9.29
# [m] where both walls of each pair stand (tutorial_worlds.md); the corners are open: a robot
# sliding along a wall's end may leave the yard there (with Gazebo's wheel-ground friction 1
# the reversing robot of command1 does), which is no tunnelling
WALLS_ALONG_X = (-7.48, 8.49)       # north and south walls
WALLS_ALONG_Y = (-8.36, 7.39)       # east and west walls


def through_a_wall(x, y):
    """True when (x, y) lies beyond a perimeter wall's centre line where the wall stands."""
    return (abs(y) >= WALL_LIMIT and WALLS_ALONG_X[0] < x < WALLS_ALONG_X[1]) or \
        (abs(x) >= WALL_LIMIT and WALLS_ALONG_Y[0] < y < WALLS_ALONG_Y[1])

SMALL = ("<robot name='s'><link name='base'><inertial><mass value='1'/><inertia ixx='0.01' "
         "iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial><collision>"
         "<geometry><box size='0.2 0.2 0.2'/></geometry></collision></link></robot>")


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture(scope="module")
def world02_spec():
    return load_world(os.path.join(SRC, "my_worlds", "worlds", "world02.world"),
                      model_path_from_env(os.path.join(SRC, "pybullet_gazebo", "models")))


@pytest.fixture
def world(world02_spec, m2wr_urdf):
    """world02 with m2wr settled at (0, 8), the tutorial's start."""
    client = BulletClient(connection_mode=pybullet.DIRECT)
    warnings = []
    result = World(client, world02_spec, STEP, warn=warnings.append)
    result.warnings = warnings
    result.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 8, 0.5))
    for _ in range(100):
        result.step()
    yield result
    client.disconnect()


def snapshot(world):
    """What a failed request must leave alone: bodies, models and every model's pose."""
    return (world.client.getNumBodies(), world.model_names(),
            [world.model_pose(name) for name in world.model_names()])


# --- spawn: descriptions that are XML but not a usable robot --------------------------------
def m2wr_with(urdf, old, new):
    assert old in urdf
    return urdf.replace(old, new, 1)


SMALL_BAD = {
    "box size not numbers": (("size='0.2 0.2 0.2'", "size='a b c'"),
                             "link 'base' <collision/geometry/box size=\"a b c\">: expected 3"),
    "box size negative": (("size='0.2 0.2 0.2'", "size='-1 0.2 0.2'"), ">= 0"),
    "box size two numbers": (("size='0.2 0.2 0.2'", "size='0.2 0.2'"), "expected 3 finite"),
    "mass nan": (("mass value='1'", "mass value='nan'"), "<inertial/mass value=\"nan\">"),
    "mass negative": (("mass value='1'", "mass value='-5'"), "expected 1 finite number >= 0"),
    "inertia inf": (("ixx='0.01'", "ixx='inf'"), "<inertial/inertia ixx=\"inf\">"),
    "origin garbage": (("<collision>", "<collision><origin xyz='1 2'/>"),
                       "<collision/origin xyz=\"1 2\">"),
}
M2WR_BAD = {
    "joint type unknown": (('type="continuous"', 'type="wobbly"'),
                           "joint 'joint_right_wheel' has type 'wobbly'"),
    "joint axis zero": (('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>'), "is a zero vector"),
    "joint limit nan": (('velocity="1000"', 'velocity="nan"'), "<limit velocity=\"nan\">"),
    "drive names a missing joint": (("<leftJoint>joint_left_wheel</leftJoint>",
                                     "<leftJoint>ghost</leftJoint>"),
                                    "<leftJoint> names joint 'ghost'"),
    "drive wheel diameter negative": (("<wheelDiameter>0.2</wheelDiameter>",
                                       "<wheelDiameter>-1</wheelDiameter>"),
                                      "<wheelDiameter> is -1"),
    "mesh file missing": (('<cylinder length="0.04" radius="0.1"/>',
                           '<mesh filename="package://nowhere/wheel.stl"/>'),
                          "Bullet could not load the URDF"),
    "laser samples zero": (("<samples>720</samples>", "<samples>0</samples>"),
                           "ray sensor 'head_hokuyo_sensor' on link 'sensor_laser': <samples> "
                           "is 0; it must be >= 1"),
    "laser range max below min": (("<max>10.0</max>", "<max>0.05</max>"),
                                  "<range/max> is 0.05; it must be > 0.1"),
    "laser noise negative": (("<stddev>0.01</stddev>", "<stddev>-0.01</stddev>"),
                             "<noise/stddev> is -0.01; it must be >= 0.0"),
}


@pytest.mark.parametrize("case", sorted(SMALL_BAD))
def test_small_robot_with_bad_values_is_refused_and_the_world_untouched(world, case):
    (old, new), message = SMALL_BAD[case]
    before = snapshot(world)
    with pytest.raises(SpawnError) as error:
        world.spawn_urdf("bad", m2wr_with(SMALL, old, new), Pose.from_xyz_rpy(2, 7, 0.5))
    assert message in str(error.value)
    assert str(error.value).startswith("model 'bad': ")
    assert snapshot(world) == before


@pytest.mark.parametrize("case", sorted(M2WR_BAD))
def test_m2wr_with_bad_values_is_refused_and_the_world_untouched(world, m2wr_urdf, case):
    (old, new), message = M2WR_BAD[case]
    before = snapshot(world)
    with pytest.raises(Exception) as error:
        world.spawn_urdf("bad", m2wr_with(m2wr_urdf, old, new), Pose.from_xyz_rpy(2, 7, 0.5))
    assert message in str(error.value)
    assert snapshot(world) == before
    world.step()                                   # and the world steps on
    assert all(math.isfinite(v) for v in world.model_pose("m2wr").position)


def test_unexpanded_xacro_is_refused_with_what_to_do(world):
    with open(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")) as source:
        text = source.read()
    before = snapshot(world)
    with pytest.raises(SpawnError, match=r"holds <xacro:include>: it is a xacro file, not yet "
                                         r"a URDF; expand it first"):
        world.spawn_urdf("raw", text, Pose.from_xyz_rpy(2, 7, 0.5))
    assert snapshot(world) == before


# --- spawn: poses --------------------------------------------------------------------------
@pytest.mark.parametrize("pose, message", [
    (Pose((2.0, 7.0, 0.5), (0.0, 0.0, 0.0, 0.0)), "zero quaternion"),
    (Pose((2.0, 7.0, 0.5), (0.0, 0.0, 0.0, 1e-200)), "zero quaternion"),
    (Pose((1e300, 7.0, 0.5)), "over 1e+06 m from the origin"),
    (Pose((2.0, -2e6, 0.5)), "over 1e+06 m from the origin"),
    (Pose((2.0, 7.0, -5.0)), "puts all of 'bad' under ground_plane; raise -z"),
    (Pose((2.0, 7.0, math.inf)), "not finite"),
])
def test_bad_spawn_pose_is_refused_and_the_world_untouched(world, m2wr_urdf, pose, message):
    before = snapshot(world)
    with pytest.raises(SpawnError, match=message.replace("+", r"\+")):
        world.spawn_urdf("bad", m2wr_urdf, pose)
    assert snapshot(world) == before


def test_zero_quaternion_in_set_model_state_is_the_identity_and_the_model_moves(world):
    """Gazebo normalizes the target rotation; an all-zero quaternion becomes the identity
    (the series' programs send exactly that)."""
    world.set_model_state("m2wr", Pose((1.0, 6.0, 0.3), (0.0, 0.0, 0.0, 0.0)))
    pose = world.model_pose("m2wr")
    assert pose.position == pytest.approx((1.0, 6.0, 0.3), abs=1e-9)
    assert pose.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-9)


def test_unnormalised_quaternion_is_normalised(world):
    world.spawn_urdf("box", SMALL, Pose((2.0, 7.0, 0.5), (0.0, 0.0, 3.0, 4.0)))
    q = world.model_pose("box").orientation
    assert q == pytest.approx((0.0, 0.0, 0.6, 0.8), abs=1e-6)


def test_robot_partly_in_the_ground_is_pushed_onto_its_wheels(world, m2wr_urdf):
    """z 0: the wheels reach 0.1 m into the ground. Accepted (as Gazebo does); it comes up."""
    world.spawn_urdf("low", m2wr_urdf, Pose.from_xyz_rpy(2, 7, 0.0))
    for _ in range(200):
        world.step()
    assert world.model_pose("low").position == pytest.approx((2.0, 7.0, 0.1), abs=0.01)


def test_any_model_name_is_accepted_as_text(world):
    world.spawn_urdf("a/b c", SMALL, Pose.from_xyz_rpy(2, 7, 0.5))
    assert "a/b c" in world.model_names()
    world.delete_model("a/b c")
    assert "a/b c" not in world.model_names()


# --- set_model_state ----------------------------------------------------------------------
@pytest.mark.parametrize("name, pose, linear, angular, message", [
    ("m2wr", Pose((0, 8, 0.2)), (1e160, 0, 0), (0, 0, 0), "over 1e+06 m/s or rad/s"),
    ("construction_barrel", Pose((-4.4, -0.66, 0)), (0, 0, 0), (0, 0, 1e160), "over 1e+06"),
    ("m2wr", Pose((1e300, 8, 0.2)), (0, 0, 0), (0, 0, 0), "over 1e+06 m from the origin"),
    ("m2wr", Pose((0, math.nan, 0.2)), (0, 0, 0), (0, 0, 0), "non-finite"),
])
def test_bad_model_state_is_refused_and_the_world_stays_finite(world, name, pose, linear,
                                                              angular, message):
    """A twist of 1e160 turned every body it touched into NaN and stopped the ray sensor."""
    before = snapshot(world)
    with pytest.raises(ValueError, match=message.replace("+", r"\+")):
        world.set_model_state(name, pose, linear, angular)
    assert snapshot(world) == before
    for _ in range(50):
        world.step()
    for model in world.model_names():
        assert all(math.isfinite(v) for v in world.model_pose(model).position)


# --- huge drive commands ------------------------------------------------------------------
@pytest.mark.parametrize("command", [(1e9, 0.0), (-1e9, 0.0), (0.0, 1e9), (1e300, -1e300),
                                     (10.0, 0.0), (-10.0, 0.0)])
def test_huge_command_is_clamped_and_the_robot_stays_finite_and_out_of_obstacles(world,
                                                                                 command):
    robot = world.entities["m2wr"].robot
    drive = next(c for c in robot.parts if isinstance(c, DiffDrive))
    client = world.client
    wheels = [robot.joints["joint_left_wheel"], robot.joints["joint_right_wheel"]]
    assert drive.set_command(*command)
    deepest, fastest, fastest_wheel = 0.0, 0.0, 0.0
    for _ in range(int(4.0 / STEP)):
        for reading in world.step():
            data = reading.data
            if hasattr(data, "ranges"):
                values = data.ranges
            elif hasattr(data, "positions"):             # the wheels' joint states
                values = np.concatenate([data.positions, data.velocities])
            else:
                values = np.concatenate([data.pose.position, data.pose.orientation, data.linear,
                                         data.angular])
            assert not np.any(np.isnan(values))
        pose = world.model_pose("m2wr")
        assert all(math.isfinite(v) for v in pose.position + pose.orientation)
        assert not through_a_wall(*pose.position[:2]), pose.position
        assert -0.05 < pose.position[2] < 1.5               # on or near the ground
        for point in client.getContactPoints(bodyA=robot.body_id):
            if not world.entities[world._body_owner[point[2]]].is_ground:
                deepest = min(deepest, point[8])            # [m], negative = penetration
        linear, _ = world.model_twist("m2wr")
        fastest = max(fastest, math.hypot(linear[0], linear[1]))
        fastest_wheel = max(fastest_wheel, *(abs(client.getJointState(robot.body_id, j)[1])
                                             for j in wheels))
    assert deepest > -0.05                                   # never into an obstacle
    assert fastest * STEP < BARRIER_THICKNESS / 4            # cannot jump a barrier in a step
    assert fastest_wheel <= 100.0 + 1e-6                     # Bullet's joint speed cap
    limit_warnings = [w for w in world.warnings if "URDF velocity limit 1000" in w]
    if max(abs(drive.wheel_speeds(*command)[0]), abs(drive.wheel_speeds(*command)[1])) > 1000:
        assert len(limit_warnings) == 2                      # once per wheel
    else:
        assert limit_warnings == []


def test_far_spawn_is_refused_at_the_bound_and_accepted_below_it(world):
    with pytest.raises(SpawnError):
        world.spawn_urdf("far", SMALL, Pose((MAX_COORDINATE * 1.001, 0.0, 0.5)))
    world.spawn_urdf("far", SMALL, Pose((MAX_COORDINATE * 0.999, 0.0, 0.5)))
    world.step()
    assert world.model_pose("far").position[0] == pytest.approx(MAX_COORDINATE * 0.999)
