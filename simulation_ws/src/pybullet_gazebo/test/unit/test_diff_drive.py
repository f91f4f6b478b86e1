"""DiffDrive on a two-wheeled robot with the tutorial's m2wr geometry, on a plane, stepped at
0.005 s in DIRECT mode."""
import math

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive, Odometry
from pybullet_gazebo.engine.specs import PluginSpec
from pybullet_gazebo.ros.plugin_names import drive_names

STEP = 0.005                    # [s]

# m2wr: the joint named "right" sits at +y (the robot's left), "left" at -y
ROBOT = """<robot name="m2wr">
 <link name="link_chassis">
  <inertial><mass value="5"/><origin xyz="0 0 0.1"/>
   <inertia ixx="0.0395416666667" ixy="0" ixz="0" iyy="0.106208333333" iyz="0"
            izz="0.106208333333"/></inertial>
  <collision name="collision_chassis"><geometry><box size="0.5 0.3 0.07"/></geometry></collision>
  <collision name="caster_front_collision"><origin xyz="0.35 0 -0.05"/>
   <geometry><sphere radius="0.05"/></geometry></collision>
 </link>
 %s
 %s
</robot>"""
WHEEL = """<link name="link_%(side)s_wheel">
  <inertial><mass value="0.2"/><origin rpy="0 1.5707 1.5707"/>
   <inertia ixx="0.000526666666667" ixy="0" ixz="0" iyy="0.000526666666667" iyz="0"
            izz="0.001"/></inertial>
  <collision><origin rpy="0 1.5707 1.5707"/>
   <geometry><cylinder length="0.04" radius="0.1"/></geometry></collision>
 </link>
 <joint name="joint_%(side)s_wheel" type="continuous"><origin xyz="-0.05 %(y)s 0"/>
  <child link="link_%(side)s_wheel"/><parent link="link_chassis"/><axis xyz="0 1 0"/>
  <limit effort="10000" velocity="%(limit)s"/></joint>"""

TUTORIAL_PARAMS = {  # the tutorial's <plugin> block (torque, not wheelTorque)
    "legacyMode": "false", "alwaysOn": "true", "updateRate": "20",
    "leftJoint": "joint_left_wheel", "rightJoint": "joint_right_wheel",
    "wheelSeparation": "0.4", "wheelDiameter": "0.2", "torque": "0.1",
    "commandTopic": "cmd_vel", "odometryTopic": "odom", "odometryFrame": "odom",
    "robotBaseFrame": "link_chassis"}


class Sim:
    """A plane and the robot; the drive is stepped as the World steps components."""

    def __init__(self, tmp_path, params=None, implicit_cylinders=True, velocity_limit=1000,
                 **drive_kwargs):
        self.client = c = BulletClient(connection_mode=pybullet.DIRECT)
        c.setTimeStep(STEP)
        c.setGravity(0, 0, -9.8)
        c.createMultiBody(0, c.createCollisionShape(pybullet.GEOM_PLANE))
        urdf = tmp_path / "m2wr.urdf"
        urdf.write_text(ROBOT % (WHEEL % dict(side="right", y=0.15, limit=velocity_limit),
                                 WHEEL % dict(side="left", y=-0.15, limit=velocity_limit)))
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE
        if implicit_cylinders:
            flags |= pybullet.URDF_USE_IMPLICIT_CYLINDER
        self.body = c.loadURDF(str(urdf), basePosition=(0, 0, 0.101), flags=flags)
        self.joints = {c.getJointInfo(self.body, i)[1].decode(): i
                       for i in range(c.getNumJoints(self.body))}
        for index in self.joints.values():            # free joints, Gazebo-like friction
            c.setJointMotorControl2(self.body, index, pybullet.VELOCITY_CONTROL, force=0)
            c.changeDynamics(self.body, index, lateralFriction=1.0)
        c.changeDynamics(self.body, -1, lateralFriction=1.0)    # box and caster: mu 1, as Gazebo
        self.warnings = []
        self.drive = DiffDrive(c, self.body, self.joints,
                               PluginSpec("differential_drive_controller", DiffDrive.KEY,
                                          dict(TUTORIAL_PARAMS if params is None else params)),
                               warn=self.warnings.append, **drive_kwargs)
        self.time = 0.0
        self.run(0.5)                                 # settle on the ground

    def run(self, seconds, record=None):
        for _ in range(int(round(seconds / STEP))):
            self.drive.before_step(self.time, STEP)
            self.client.stepSimulation()
            self.time += STEP
            if record is not None:
                record.append(self.drive.odometry())

    def yaw(self):
        return self.drive.odometry().pose.rpy[2]


@pytest.mark.parametrize("implicit_cylinders", [True, False])
def test_straight_line_3_m_in_5_s(tmp_path, implicit_cylinders):
    sim = Sim(tmp_path, implicit_cylinders=implicit_cylinders)
    start = sim.drive.odometry().pose
    heading = np.array([math.cos(start.rpy[2]), math.sin(start.rpy[2]), 0.0])
    assert sim.drive.set_command(0.6, 0.0)
    sim.run(5.0)
    moved = np.asarray(sim.drive.odometry().pose.position) - np.asarray(start.position)
    assert moved @ heading == pytest.approx(3.0, rel=0.05)
    assert abs(np.cross(heading, moved)[2]) < 0.15      # little drift sideways
    odom = sim.drive.odometry()
    assert odom.linear[0] == pytest.approx(0.6, abs=0.03)


def mean_yaw_rate(sim, seconds=8.0):
    """Yaw rate [rad/s] averaged over `seconds` of driving. A long window: Bullet touches the
    ground with one rim edge of a flat wheel at a time (y = +-0.02 m off the wheel's centre
    plane), and which edge it is changes as the robot turns, so the instantaneous rate of a
    turn on the spot swings between (0.06 + 0.06) / 0.338 = 0.355 and 0.12 / 0.262 = 0.458."""
    yaws = []
    for _ in range(int(seconds / 0.25) + 1):
        yaws.append(sim.yaw())
        sim.run(0.25)
    return (np.unwrap(yaws)[-1] - yaws[0]) / seconds


@pytest.mark.parametrize("implicit_cylinders", [True, False])
def test_positive_angular_z_turns_m2wr_clockwise(tmp_path, implicit_cylinders):
    """angular.z = +0.3: joint_left_wheel (at -y) gets (0 - 0.3*0.2)/0.1 = -0.6 rad/s,
    joint_right_wheel (at +y) +0.6 rad/s: the robot's left side moves forward, so it turns
    clockwise at (-0.06 - 0.06) / 0.3 (the real track) = -0.4 rad/s."""
    sim = Sim(tmp_path, implicit_cylinders=implicit_cylinders)
    assert sim.drive.wheel_speeds(0.0, 0.3) == pytest.approx((-0.6, 0.6))
    sim.drive.set_command(0.0, 0.3)
    sim.run(1.0)
    left, right = (sim.client.getJointState(sim.body, sim.joints[name])[1]
                   for name in ("joint_left_wheel", "joint_right_wheel"))
    tolerance = 0.02 if implicit_cylinders else 0.1     # convex-hull wheels are polygons
    assert left == pytest.approx(-0.6, abs=tolerance)
    assert right == pytest.approx(0.6, abs=tolerance)
    assert mean_yaw_rate(sim) == pytest.approx(-0.4, rel=0.10)


@pytest.mark.parametrize("urdf_legacy", ["false", "true"])
def test_kinetic_legacy_mode_turns_m2wr_counter_clockwise_whatever_the_urdf_says(tmp_path,
                                                                               urdf_legacy):
    """The simulator's legacy_mode:=true: Kinetic's drive with legacyMode true, so a positive
    angular.z turns m2wr counter-clockwise (REP 103) at +0.4 rad/s, with no warning."""
    sim = Sim(tmp_path, dict(TUTORIAL_PARAMS, legacyMode=urdf_legacy), kinetic_legacy_mode=True)
    assert sim.drive.legacy_mode is True
    assert not any("legacyMode" in w for w in sim.warnings)
    assert sim.drive.wheel_speeds(0.0, 0.3) == pytest.approx((0.6, -0.6))
    sim.drive.set_command(0.0, 0.3)
    sim.run(1.0)
    assert mean_yaw_rate(sim) == pytest.approx(0.4, rel=0.10)


@pytest.mark.parametrize("swaps,expected", [(False, -0.4), (True, 0.4)])
def test_legacy_mode_true_is_ignored_as_in_noetic_unless_emulated(tmp_path, swaps, expected):
    params = dict(TUTORIAL_PARAMS, legacyMode="true")
    sim = Sim(tmp_path, params, legacy_mode_swaps=swaps)
    assert sim.drive.legacy_mode is swaps
    assert any("legacyMode" in w for w in sim.warnings) is not swaps
    assert sim.drive.wheel_speeds(0.0, 0.3) == pytest.approx((0.6, -0.6) if swaps else (-0.6, 0.6))
    sim.drive.set_command(0.0, 0.3)
    sim.run(1.0)
    assert mean_yaw_rate(sim) == pytest.approx(expected, rel=0.10)


def test_nan_command_is_refused_and_the_last_one_kept(tmp_path):
    sim = Sim(tmp_path)
    assert sim.drive.set_command(0.6, 0.0)
    assert not sim.drive.set_command(math.nan, 0.0)
    assert not sim.drive.set_command(0.2, math.inf)
    assert not sim.drive.set_command("fast", 0.0)
    assert sim.drive.command == (0.6, 0.0)
    assert sum("non-finite" in w for w in sim.warnings) == 1      # reported once
    x0 = sim.drive.odometry().pose.position[0]
    sim.run(2.0)
    assert sim.drive.odometry().pose.position[0] - x0 == pytest.approx(1.2, rel=0.08)


def test_last_command_held_for_ever_by_default(tmp_path):
    sim = Sim(tmp_path)
    sim.drive.set_command(0.6, 0.0)
    sim.run(4.0)
    assert sim.drive.odometry().linear[0] == pytest.approx(0.6, abs=0.03)


def test_command_timeout_stops_the_robot(tmp_path):
    sim = Sim(tmp_path, command_timeout=0.5)
    sim.drive.set_command(0.6, 0.0)
    sim.run(0.4)
    assert sim.drive.odometry().linear[0] == pytest.approx(0.6, abs=0.05)
    sim.run(1.6)
    assert abs(sim.drive.odometry().linear[0]) < 0.01
    x = sim.drive.odometry().pose.position[0]
    assert 0.25 < x < 0.5                              # drove ~0.5 s, then stopped
    sim.drive.set_command(0.6, 0.0)                    # a new command moves it again
    sim.run(0.4)
    assert sim.drive.odometry().linear[0] == pytest.approx(0.6, abs=0.05)


def test_huge_command_is_clamped_to_the_joint_velocity_limit(tmp_path):
    """With a URDF velocity limit of 8 rad/s (0.8 m/s at the rim) a command of 1e6 m/s drives
    the robot at 0.8 m/s, on its wheels."""
    sim = Sim(tmp_path, velocity_limit=8)
    z0 = sim.drive.odometry().pose.position[2]
    sim.drive.set_command(1e6, 0.0)
    record = []
    sim.run(3.0, record)
    assert sum("velocity limit" in w for w in sim.warnings) == 2      # once per wheel
    heights = [o.pose.position[2] for o in record]
    assert max(heights) - z0 < 0.03 and min(heights) - z0 > -0.01
    assert all(abs(o.pose.rpy[0]) < 0.05 for o in record)                # no roll-over
    assert record[-1].linear[0] == pytest.approx(0.8, abs=0.03)
    for name in ("joint_left_wheel", "joint_right_wheel"):
        speed = sim.client.getJointState(sim.body, sim.joints[name])[1]     # [rad/s]
        assert speed == pytest.approx(8.0, abs=0.1)


def test_wheel_acceleration_limits_the_ramp(tmp_path):
    params = dict(TUTORIAL_PARAMS, wheelAcceleration="0.5", updateRate="0")
    sim = Sim(tmp_path, params)
    sim.drive.set_command(0.6, 0.0)
    sim.run(0.5)
    assert sim.drive.odometry().linear[0] == pytest.approx(0.25, abs=0.03)
    sim.run(1.0)
    assert sim.drive.odometry().linear[0] == pytest.approx(0.6, abs=0.03)


def test_odometry_is_the_base_link_frame(tmp_path):
    """pybullet places the base at its centre of mass (0.1 above link_chassis here); odometry
    reports link_chassis itself: at the axle height, 0.1 m."""
    sim = Sim(tmp_path)
    odom = sim.drive.odometry()
    assert isinstance(odom, Odometry)
    assert odom.pose.position[2] == pytest.approx(0.1, abs=0.002)
    com = sim.client.getBasePositionAndOrientation(sim.body)[0]
    assert com[2] == pytest.approx(0.2, abs=0.002)
    sim.drive.set_command(0.6, 0.3)
    sim.run(3.0)
    odom = sim.drive.odometry()
    assert odom.linear[0] == pytest.approx(0.6, abs=0.04)    # in the base frame, not world
    assert abs(odom.linear[1]) < 0.05
    assert odom.angular[2] == pytest.approx(-0.4, rel=0.1)


def test_encoder_odometry_follows_the_wheels(tmp_path):
    params = dict(TUTORIAL_PARAMS, odometrySource="encoder")
    sim = Sim(tmp_path, params)
    sim.drive.set_command(0.6, 0.0)
    sim.run(3.0)
    odom = sim.drive.odometry()
    assert odom.pose.position[0] == pytest.approx(1.8, rel=0.05)
    assert odom.linear[0] == pytest.approx(0.6, abs=0.03)


def test_due_at_update_rate(tmp_path):
    sim = Sim(tmp_path)
    times = [k * STEP for k in range(400)]             # 2 s of sim time
    due = [t for t in times if sim.drive.due(t)]
    assert len(due) == 40
    np.testing.assert_allclose(np.diff(due), 0.05, atol=1e-9)
    sim.drive.reset()
    assert sim.drive.due(0.0)                          # after a reset, due at once
    every_step = Sim(tmp_path, dict(TUTORIAL_PARAMS, updateRate="0")).drive
    assert all(every_step.due(t) for t in times[:10])
    silent = Sim(tmp_path, dict(TUTORIAL_PARAMS, publishTf="false")).drive
    assert not any(silent.due(t) for t in times[:10])


def test_wheel_targets_change_at_update_rate_only(tmp_path):
    """Noetic applies a new command at its next update (20 Hz here), not at once."""
    sim = Sim(tmp_path)                                # updates at 0, 0.05, ... since t=0
    sim.run(0.02)                                      # t = 0.52: between updates
    sim.drive.set_command(0.6, 0.0)
    sim.run(0.02)                                      # t = 0.54: not applied yet
    wheel = sim.client.getJointState(sim.body, sim.joints["joint_left_wheel"])[1]
    assert abs(wheel) < 0.05
    sim.run(0.05)
    wheel = sim.client.getJointState(sim.body, sim.joints["joint_left_wheel"])[1]
    assert wheel > 3.0


def test_reset_zeroes_the_command(tmp_path):
    sim = Sim(tmp_path)
    sim.drive.set_command(0.6, 0.0)
    sim.run(1.0)
    sim.drive.reset()
    assert sim.drive.command == (0.0, 0.0)
    sim.run(1.0)
    assert abs(sim.drive.odometry().linear[0]) < 0.01


def test_parameters_as_noetic_reads_them(tmp_path):
    sim = Sim(tmp_path)
    d = sim.drive
    assert drive_names(d.plugin_params) == ("cmd_vel", "odom", "odom", "link_chassis")
    assert d.update_rate == 20.0 and d.publish_odom_tf is True and d.publish_tf is True
    assert d.wheel_separation == 0.4 and d.wheel_radius == 0.1
    assert d.wheel_torque == 5.0                       # <torque> 0.1 is not read by Noetic
    assert d.wheel_acceleration == 0.0 and d.odometry_source == "world"
    assert (d.left_joint, d.right_joint) == ("joint_left_wheel", "joint_right_wheel")
    assert d.legacy_mode is False
    assert [w for w in sim.warnings if "torque" in w] == [
        "diff drive plugin 'differential_drive_controller' (libgazebo_ros_diff_drive.so): "
        "<torque>0.1</torque> is not read by ROS Noetic's gazebo_ros_diff_drive (the tag is "
        "<wheelTorque>); the wheels get Noetic's default 5 N m, as in Gazebo"]

    params = {"leftJoint": "joint_left_wheel", "rightJoint": "joint_right_wheel",
              "wheelTorque": "2.5", "wheelSeparation": "0.3", "wheelDiameter": "0.2"}
    d = Sim(tmp_path, params).drive
    assert drive_names(d.plugin_params) == ("cmd_vel", "odom", "odom", "base_footprint")
    assert d.update_rate == 100.0 and d.wheel_torque == 2.5 and d.publish_odom_tf is True
    assert d.publish_wheel_tf is False


def test_unknown_joint_is_named_with_the_model_joints(tmp_path):
    params = dict(TUTORIAL_PARAMS, rightJoint="joint_rigth_wheel")
    with pytest.raises(ValueError) as err:
        Sim(tmp_path, params)
    message = str(err.value)
    assert "joint_rigth_wheel" in message and "rightJoint" in message
    assert "joint_left_wheel, joint_right_wheel" in message


@pytest.mark.parametrize("tag,value", [("wheelDiameter", "big"), ("wheelDiameter", "0"),
                                       ("wheelSeparation", "nan"), ("publishOdomTF", "yes")])
def test_bad_parameter_values_are_named(tmp_path, tag, value):
    with pytest.raises(ValueError, match=tag):
        Sim(tmp_path, dict(TUTORIAL_PARAMS, **{tag: value}))
