"""robot_description: the tutorial's m2wr (expanded by xacro from m2wr_description) parsed value
by value against the reference, friction and contact as Gazebo takes them from a URDF (only
from <gazebo reference>; a <surface> inside a <collision> is ignored, with a warning),
strip_for_bullet's output in pybullet, and the errors and warnings for bad descriptions."""
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
CASTER_WARNING = (
    "link 'link_chassis' collision 'caster_front_collision': <surface> is ignored, as in "
    "Gazebo: a URDF <collision> is read for its name, <origin> and <geometry> only, so this "
    "collision has the link's friction, mu = mu2 = 1 (SDF's default). To set friction or "
    "contact values, use <gazebo reference=\"link_chassis\"> with <mu1>/<mu2> (<kp>/<kd>) "
    "instead")


def test_m2wr_root_link_name_and_one_warning_for_the_casters_surface(m2wr):
    assert m2wr.name == "m2wr"
    assert m2wr.root_link == "link_chassis"
    assert m2wr.warnings == (CASTER_WARNING,)


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


def test_m2wr_casters_surface_is_ignored_as_gazebo_ignores_it(m2wr_urdf, m2wr):
    """The xacro writes mu = mu2 = 0 inside the caster's URDF <collision>, where Gazebo never
    reads it: no link gets a friction from the description (all keep SDF's mu = mu2 = 1)."""
    caster = ET.fromstring(m2wr_urdf).find("link/collision[@name='caster_front_collision']")
    assert caster.find("surface/friction/ode/mu").text == "0"       # the tutorial's text
    assert m2wr.link_friction == {}
    assert effective_link_friction(m2wr) == {}
    assert effective_link_contact(m2wr) == {}


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


SURFACES = ('<link name="base"><collision name="skid"><geometry><sphere radius="0.1"/>'
            '</geometry><surface><friction><ode><mu>0.2</mu></ode></friction></surface>'
            '</collision><collision><geometry><box size="1 1 1"/></geometry><surface>'
            '<friction><ode><mu>0.1</mu><mu2>0.3</mu2></ode></friction><contact><ode><kp>5e4'
            '</kp><kd>20</kd></ode></contact></surface><surface/><material name="red"/>'
            '</collision></link><link name="wheel"/>')
WHEEL_JOINT = '<joint name="j" type="fixed"><parent link="base"/><child link="wheel"/></joint>'


def test_collision_surfaces_are_ignored_with_one_warning_per_collision_and_element():
    spec = parse_robot(urdf(WHEEL_JOINT, root=SURFACES), "m")
    assert effective_link_friction(spec) == {}
    assert effective_link_contact(spec) == {}
    # a named collision by its name, an unnamed one by its index; <surface> twice: one warning
    assert [w.split(": <")[0] for w in spec.warnings] == [
        "link 'base' collision 'skid'", "link 'base' collision 1 (unnamed, counted from 0)",
        "link 'base' collision 1 (unnamed, counted from 0)"]
    assert [w.split(": <")[1].split(">")[0] for w in spec.warnings] == [
        "surface", "surface", "material"]
    for warning in spec.warnings:
        assert "mu = mu2 = 1 (SDF's default)" in warning
        assert 'use <gazebo reference="base"> with <mu1>/<mu2> (<kp>/<kd>) instead' in warning


def test_gazebo_mu_and_kp_kd_set_the_link_and_collision_surfaces_do_not():
    block = ('<gazebo reference="base"><mu1>0.9</mu1><mu2>0.8</mu2><kd>3</kd></gazebo>'
             '<gazebo reference="wheel"><mu1>0.7</mu1><kp>1e5</kp></gazebo>')
    spec = parse_robot(urdf(WHEEL_JOINT + block, root=SURFACES), "m")
    # a value missing from a pair is SDF's default: mu2 1, kp 1e12 N/m, kd 1 N s/m
    assert spec.link_friction == {"base": (0.9, 0.8), "wheel": (0.7, 1.0)}
    assert effective_link_friction(spec) == {"base": (0.9, 0.8), "wheel": (0.7, 1.0)}
    assert effective_link_contact(spec) == {"base": (1e12, 3.0), "wheel": (1e5, 1.0)}
    assert len(spec.warnings) == 3
    assert "this collision has the link's friction, mu1 = 0.9, mu2 = 0.8 (its <gazebo " \
           "reference>)" in spec.warnings[0]


def test_m2wr_has_gazebo_default_contact_springs(m2wr):
    assert effective_link_contact(m2wr) == {}           # every link: kp 1e12, kd 1


def test_a_bad_kp_is_refused_naming_the_link():
    block = '<gazebo reference="base"><kp>-5</kp></gazebo>'
    with pytest.raises(RobotDescriptionError, match=r'reference="base".*<kp> -5'):
        parse_robot(urdf(block), "m")
