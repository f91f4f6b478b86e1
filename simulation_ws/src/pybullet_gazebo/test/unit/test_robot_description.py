"""robot_description: the tutorial's m2wr (expanded by xacro from m2wr_description) parsed value
by value against the reference, the friction rule, strip_for_bullet's output in pybullet, and
the errors and warnings for bad descriptions."""
import os
import xml.etree.ElementTree as ET

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.robot_description import (
    RobotDescriptionError, effective_link_contact, effective_link_friction, parse_robot,
    strip_for_bullet)
from pybullet_gazebo.engine.specs import PluginSpec
from pybullet_gazebo.engine.transforms import Pose

HERE = os.path.dirname(os.path.abspath(__file__))
M2WR_XACRO = os.path.normpath(os.path.join(
    HERE, "..", "..", "..", "m2wr_description", "urdf", "m2wr.xacro"))


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(M2WR_XACRO).toprettyxml(indent="  ")


@pytest.fixture(scope="module")
def m2wr(m2wr_urdf):
    return parse_robot(m2wr_urdf, "m2wr")


def urdf(body, root='<link name="base"/>'):
    return '<robot name="t">%s%s</robot>' % (root, body)


# --- the tutorial's robot ------------------------------------------------------------------
def test_m2wr_root_link_name_and_no_warnings(m2wr):
    assert m2wr.name == "m2wr"
    assert m2wr.root_link == "link_chassis"
    assert m2wr.warnings == ()


def test_m2wr_ray_sensor_has_the_reference_values(m2wr):
    assert len(m2wr.sensors) == 1
    laser = m2wr.sensors[0]
    assert laser.link == "sensor_laser"
    assert laser.pose == Pose()
    assert laser.update_rate == 20.0
    assert laser.samples == 720
    assert laser.min_angle == -1.570796
    assert laser.max_angle == 1.570796
    assert laser.range_min == 0.10
    assert laser.range_max == 10.0
    assert laser.resolution == 0.01
    assert laser.noise_mean == 0.0
    assert laser.noise_stddev == 0.01
    assert laser.plugin.filename == "libgazebo_ros_laser.so"
    assert laser.plugin.params == {"topicName": "/m2wr/laser/scan", "frameName": "sensor_laser"}


def test_m2wr_diff_drive_plugin_has_the_reference_values(m2wr):
    assert [p.filename for p in m2wr.plugins] == ["libgazebo_ros_diff_drive.so"]
    assert m2wr.plugins[0].params == {
        "legacyMode": "false", "alwaysOn": "true", "updateRate": "20",
        "leftJoint": "joint_left_wheel", "rightJoint": "joint_right_wheel",
        "wheelSeparation": "0.4", "wheelDiameter": "0.2", "torque": "0.1",
        "commandTopic": "cmd_vel", "odometryTopic": "odom", "odometryFrame": "odom",
        "robotBaseFrame": "link_chassis"}


def test_m2wr_joint_named_right_sits_on_the_left(m2wr_urdf, m2wr):
    joints = {j.get("name"): j for j in ET.fromstring(m2wr_urdf).findall("joint")}
    xyz = {name: [float(v) for v in j.find("origin").get("xyz").split()]
           for name, j in joints.items()}
    assert xyz["joint_right_wheel"] == [-0.05, 0.15, 0.0]     # +y: the robot's left
    assert xyz["joint_left_wheel"] == [-0.05, -0.15, 0.0]
    assert xyz["joint_sensor_laser"] == [0.15, 0.0, 0.05]
    assert m2wr.plugins[0].params["rightJoint"] == "joint_right_wheel"


def test_m2wr_links_have_the_reference_values(m2wr_urdf):
    robot = ET.fromstring(m2wr_urdf)
    links = {link.get("name"): link for link in robot.findall("link")}
    assert set(links) == {"link_chassis", "link_left_wheel", "link_right_wheel", "sensor_laser"}
    chassis = links["link_chassis"]
    assert chassis.find("pose").text == "0 0 0.1 0 0 0"
    assert chassis.find("inertial/mass").get("value") == "5"
    assert chassis.find("inertial/origin").get("xyz") == "0 0 0.1"
    inertia = chassis.find("inertial/inertia")
    assert (inertia.get("ixx"), inertia.get("iyy"), inertia.get("izz")) == (
        "0.0395416666667", "0.106208333333", "0.106208333333")
    box, caster = chassis.findall("collision")
    assert box.find("geometry/box").get("size") == "0.5 0.3 0.07"
    assert caster.find("geometry/sphere").get("radius") == "0.05"
    assert caster.find("origin").get("xyz") == "0.35 0 -0.05"
    caster_visual = [v for v in chassis.findall("visual") if v.find("geometry/sphere") is not None]
    assert caster_visual[0].find("origin").get("xyz") == "0.2 0 -0.05"
    for side in ("left", "right"):
        wheel = links["link_%s_wheel" % side]
        cylinder = wheel.find("collision/geometry/cylinder")
        assert (cylinder.get("radius"), cylinder.get("length")) == ("0.1", "0.04")
        assert wheel.find("collision/origin").get("rpy") == "0 1.5707 1.5707"
        assert float(wheel.find("inertial/mass").get("value")) == 0.2
        joint = robot.find("joint[@name='joint_%s_wheel']" % side)
        assert joint.get("type") == "continuous"
        assert joint.find("axis").get("xyz") == "0 1 0"
        assert (joint.find("limit").get("effort"), joint.find("limit").get("velocity")) == (
            "10000", "1000")
    laser = links["sensor_laser"].find("collision/geometry/cylinder")
    assert (laser.get("radius"), laser.get("length")) == ("0.05", "0.1")
    assert float(links["sensor_laser"].find("inertial/mass").get("value")) == 1.0
    assert robot.find("joint[@name='joint_sensor_laser']").get("type") == "fixed"


def test_m2wr_caster_friction_is_zero_and_goes_to_the_chassis(m2wr):
    assert m2wr.collision_friction == {("link_chassis", "caster_front_collision"): (0.0, 0.0)}
    assert m2wr.link_friction == {}
    assert effective_link_friction(m2wr) == {"link_chassis": (0.0, 0.0)}


def test_stripped_m2wr_loads_in_pybullet_with_its_joints_and_inertias(m2wr_urdf, tmp_path):
    text = strip_for_bullet(parse_robot(m2wr_urdf, "m2wr"))
    robot = ET.fromstring(text)
    assert robot.find("gazebo") is None
    assert robot.find("link/pose") is None
    assert robot.find("link/collision/surface") is None
    assert len(robot.findall("link/collision")) == 5
    assert len(robot.findall("link/visual")) == 5
    path = tmp_path / "m2wr.urdf"
    path.write_text(text)
    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        body = client.loadURDF(str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        assert client.getBodyInfo(body) == (b"link_chassis", b"m2wr")
        joints = [client.getJointInfo(body, j) for j in range(client.getNumJoints(body))]
        assert [(j[1].decode(), j[2]) for j in joints] == [
            ("joint_right_wheel", pybullet.JOINT_REVOLUTE),
            ("joint_left_wheel", pybullet.JOINT_REVOLUTE),
            ("joint_sensor_laser", pybullet.JOINT_FIXED)]
        mass, _, inertia = client.getDynamicsInfo(body, -1)[:3]
        assert mass == 5.0
        assert inertia == pytest.approx((0.0395416666667, 0.106208333333, 0.106208333333))
    finally:
        client.disconnect()


# --- errors ----------------------------------------------------------------------------------
@pytest.mark.parametrize("text", ["", "   \n"])
def test_empty_description_is_an_error(text):
    with pytest.raises(RobotDescriptionError, match="robot_description is empty: "):
        parse_robot(text, "m")


def test_malformed_xml_names_the_line():
    text = '<robot name="t">\n  <link name="a">\n</robot>\n'
    with pytest.raises(RobotDescriptionError, match=r"not valid XML: line 3, column 3: "
                                                    r"mismatched tag"):
        parse_robot(text, "m")


def test_root_that_is_not_robot_is_an_error():
    with pytest.raises(RobotDescriptionError, match=r"root element is <sdf>, not <robot>"):
        parse_robot('<sdf version="1.6"><model name="a"/></sdf>', "m")


def test_two_root_links_are_an_error():
    with pytest.raises(RobotDescriptionError, match=r"2 root links \(base, loose\)"):
        parse_robot(urdf('<link name="loose"/>'), "m")


def test_no_link_is_an_error():
    with pytest.raises(RobotDescriptionError, match="has no <link>"):
        parse_robot('<robot name="t"/>', "m")


def test_joint_to_a_missing_link_is_an_error():
    joint = '<joint name="j" type="fixed"><parent link="base"/><child link="nope"/></joint>'
    with pytest.raises(RobotDescriptionError, match=r"joint 'j': its <child link=...> names "
                                                    r"'nope'"):
        parse_robot(urdf(joint), "m")


def test_sensor_value_that_is_not_a_number_is_an_error():
    block = ('<gazebo reference="base"><sensor type="ray" name="s"><ray><scan><horizontal>'
             '<samples>many</samples></horizontal></scan></ray></sensor></gazebo>')
    with pytest.raises(RobotDescriptionError, match=r"sensor 's' on link 'base': "
                                                    r"<scan/horizontal/samples> is 'many'"):
        parse_robot(urdf(block), "m")


def test_sensor_on_a_missing_link_is_an_error():
    block = '<gazebo reference="ghost"><sensor type="ray" name="s"/></gazebo>'
    with pytest.raises(RobotDescriptionError, match="no link 'ghost'"):
        parse_robot(urdf(block), "m")


# --- what is kept, and what is reported -----------------------------------------------------
def test_unknown_plugin_is_kept_by_filename():
    block = ('<gazebo><plugin name="mine" filename="libmy_controller.so">'
             '<gain> 2.5 </gain></plugin></gazebo>')
    spec = parse_robot(urdf(block), "m")
    assert spec.plugins == (PluginSpec("mine", "libmy_controller.so", {"gain": "2.5"}),)
    assert spec.warnings == ()


def test_unknown_tags_in_a_gazebo_block_warn_once_each():
    block = ('<gazebo reference="base"><selfCollide>true</selfCollide><minDepth>0.001</minDepth>'
             '<material>Gazebo/Red</material></gazebo><gazebo><static>true</static></gazebo>')
    warnings = parse_robot(urdf(block), "m").warnings
    assert len(warnings) == 3
    assert "<selfCollide>" in warnings[0] and "<minDepth>" in warnings[1]
    assert "<static>" in warnings[2]


def test_other_sensor_types_warn_with_type_and_link():
    block = '<gazebo reference="base"><sensor type="camera" name="cam"/></gazebo>'
    spec = parse_robot(urdf(block), "m")
    assert spec.sensors == ()
    assert len(spec.warnings) == 1
    assert "'camera'" in spec.warnings[0] and "link 'base'" in spec.warnings[0]


def test_gazebo_mu_sets_link_friction_and_wins_over_collision_surfaces():
    link = ('<link name="base"><collision name="skid"><geometry><sphere radius="0.1"/>'
            '</geometry><surface><friction><ode><mu>0.2</mu></ode></friction></surface>'
            '</collision><collision><geometry><box size="1 1 1"/></geometry><surface>'
            '<friction><ode><mu>0.1</mu><mu2>0.3</mu2></ode></friction></surface></collision>'
            '</link><link name="wheel"/>')
    joint = '<joint name="j" type="fixed"><parent link="base"/><child link="wheel"/></joint>'
    block = '<gazebo reference="wheel"><mu1>0.7</mu1></gazebo>'
    spec = parse_robot(urdf(joint + block, root=link), "m")
    # a missing mu2 is SDF's default 1; an unnamed collision is keyed by its index
    assert spec.collision_friction == {("base", "skid"): (0.2, 1.0), ("base", "1"): (0.1, 0.3)}
    assert spec.link_friction == {"wheel": (0.7, 1.0)}
    assert effective_link_friction(spec) == {"base": (0.1, 0.3), "wheel": (0.7, 1.0)}

    block = '<gazebo reference="base"><mu1>0.9</mu1><mu2>0.8</mu2></gazebo>'
    overridden = parse_robot(urdf(joint + block, root=link), "m")
    assert effective_link_friction(overridden)["base"] == (0.9, 0.8)


def test_gazebo_kp_kd_set_the_link_contact_spring_and_win_over_collision_surfaces():
    link = ('<link name="base"><collision name="pad"><geometry><sphere radius="0.1"/>'
            '</geometry><surface><contact><ode><kp>5e4</kp><kd>20</kd></ode></contact>'
            '</surface></collision><collision><geometry><box size="1 1 1"/></geometry>'
            '<surface><contact><ode><kp>1e6</kp></ode></contact></surface></collision></link>'
            '<link name="wheel"/><link name="other"/>')
    joints = ('<joint name="j" type="fixed"><parent link="base"/><child link="wheel"/></joint>'
              '<joint name="k" type="fixed"><parent link="base"/><child link="other"/></joint>')
    block = '<gazebo reference="wheel"><kp>1e5</kp></gazebo>'
    spec = parse_robot(urdf(joints + block, root=link), "m")
    assert spec.warnings == ()
    assert spec.collision_contact == {("base", "pad"): (5e4, 20.0), ("base", "1"): (1e6, None)}
    # the softest collision of a link; a value given nowhere is SDF's default (kd 1)
    assert effective_link_contact(spec) == {"base": (5e4, 20.0), "wheel": (1e5, 1.0)}
    block = '<gazebo reference="base"><kd>3</kd></gazebo>'
    spec = parse_robot(urdf(joints + block, root=link), "m")
    assert effective_link_contact(spec)["base"] == (5e4, 3.0)


def test_m2wr_has_gazebo_default_contact_springs(m2wr):
    assert effective_link_contact(m2wr) == {}           # every link: kp 1e12, kd 1


def test_a_bad_kp_is_refused_naming_the_link():
    block = '<gazebo reference="base"><kp>-5</kp></gazebo>'
    with pytest.raises(RobotDescriptionError, match=r'reference="base".*<kp> -5'):
        parse_robot(urdf(block), "m")
