"""The joint-state part: the wheel joint states every diff drive gets (for rviz), and
Gazebo's gazebo_ros_joint_state_publisher plugin. DIRECT mode, no ROS."""
import math
import os

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.joint_states import JointStatePublisher
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import SpawnError, World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005            # [s]
PLUGIN = ('<gazebo><plugin name="joint_states" filename="libgazebo_ros_joint_state_publisher.so">'
          '<jointName>%s</jointName><updateRate>%s</updateRate></plugin></gazebo></robot>')


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture
def world():
    client = BulletClient(connection_mode=pybullet.DIRECT)
    path = os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world")
    yield World(client, load_world(path, model_path_from_env(
        os.path.join(SRC, "pybullet_gazebo", "models"))), STEP, warn=lambda m: None)
    client.disconnect()


def parts_of(robot, kind):
    return [p for p in robot.parts if isinstance(p, kind)]


def test_m2wr_wheel_joint_states_follow_the_wheels_at_the_drive_rate(world, m2wr_urdf):
    robot = world.spawn_urdf("m2wr", m2wr_urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    (states,) = parts_of(robot, JointStatePublisher)
    (drive,) = parts_of(robot, DiffDrive)
    assert states.names == ("joint_left_wheel", "joint_right_wheel")
    for _ in range(int(1.0 / STEP)):
        world.step()
    drive.set_command(0.5, 0.0)
    readings = []
    start = world.model_pose("m2wr").position
    for _ in range(int(2.0 / STEP)):
        readings += [r.data for r in world.step() if r.part is states]
    travelled = math.dist(start[:2], world.model_pose("m2wr").position[:2])
    assert len(readings) == pytest.approx(2.0 * 20, abs=1)      # updateRate 20 Hz
    first, last = readings[0], readings[-1]
    for joint in range(2):
        turned = last.positions[joint] - first.positions[joint]
        # the wheels roll the distance the robot travelled (r = 0.1 m), within a step's worth
        assert turned * 0.1 == pytest.approx(travelled, abs=0.03)
        assert last.velocities[joint] == pytest.approx(0.5 / 0.1, rel=0.05)


def test_a_joint_state_plugin_replaces_the_wheel_states(world, m2wr_urdf):
    urdf = m2wr_urdf.replace("</robot>", PLUGIN % ("joint_right_wheel, joint_sensor_laser", 50))
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    (states,) = parts_of(robot, JointStatePublisher)
    assert states.names == ("joint_right_wheel", "joint_sensor_laser")
    assert states.period == pytest.approx(0.02)


def test_a_joint_state_plugin_naming_a_missing_joint_is_refused(world, m2wr_urdf):
    urdf = m2wr_urdf.replace("</robot>", PLUGIN % ("joint_wheel_3", 50))
    with pytest.raises(SpawnError, match="joint_wheel_3.*joint_left_wheel"):
        world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    assert "m2wr" not in world.model_names()


def test_the_drive_s_publish_wheel_flags_work_or_are_reported(m2wr_urdf):
    """publishWheelJointState: the wheel states come whatever it says (rviz needs them);
    publishWheelTF true: not simulated, and the warning says so by name."""
    warnings = []
    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        path = os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world")
        world = World(client, load_world(path, model_path_from_env(
            os.path.join(SRC, "pybullet_gazebo", "models"))), STEP, warn=warnings.append)
        flags = ("<legacyMode>false</legacyMode><publishWheelTF>true</publishWheelTF>"
                 "<publishWheelJointState>true</publishWheelJointState>")
        urdf = m2wr_urdf.replace("<legacyMode>false</legacyMode>", flags)
        assert urdf != m2wr_urdf
        robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
        (states,) = robot.parts_with(JointStatePublisher.KEY)
        assert states.names == ("joint_left_wheel", "joint_right_wheel")
        reported = [w for w in warnings if "publishWheelTF" in w]
        assert len(reported) == 1 and "not simulated" in reported[0]
        assert reported[0].startswith("model 'm2wr': ")
        assert not any("publishWheelJointState" in w for w in warnings)
    finally:
        client.disconnect()
