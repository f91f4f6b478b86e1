"""What the engine does for Gazebo's API, without ROS: SDF spawning, scheduled wrenches and
joint efforts, links and joints by Gazebo's names, gravity and time step changes."""
import math
import os

import numpy as np
import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import SpawnError, World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005   # [s]
BOX_SDF = """<?xml version="1.0"?>
<sdf version="1.6"><model name="crate"><link name="body">
  <inertial><mass>2.0</mass><inertia><ixx>0.1</ixx><iyy>0.2</iyy><izz>0.3</izz></inertia></inertial>
  <collision name="shell"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision>
  <collision name="knob"><pose>0 0 0.25 0 0 0</pose><geometry><sphere><radius>0.05</radius></sphere></geometry></collision>
  <visual name="v"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></visual>
</link></model></sdf>"""
TWO_LINKS_SDF = """<sdf version="1.6"><model name="pair">
  <link name="left"><collision name="c"><geometry><cylinder><radius>0.1</radius><length>0.2</length></cylinder></geometry></collision></link>
  <link name="right"><pose>1 0 0 0 0 0</pose><collision name="c"><geometry><mesh><uri>model://nowhere/a.dae</uri></mesh></geometry></collision>
    <collision name="d"><geometry><sphere><radius>0.1</radius></sphere></geometry></collision></link>
</model></sdf>"""
PENDULUM_URDF = """<robot name="pendulum">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="arm"><inertial><origin xyz="0 0 0"/><mass value="0.5"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/></joint>
  <link name="tag"><collision><geometry><sphere radius="0.02"/></geometry></collision></link>
  <joint name="tag_joint" type="fixed"><parent link="arm"/><child link="tag"/><origin xyz="0.1 0 0"/></joint>
</robot>"""


@pytest.fixture
def world():
    spec = load_world(os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world"),
                      model_path_from_env(os.path.join(SRC, "pybullet_gazebo", "models")))
    client = BulletClient(connection_mode=pybullet.DIRECT)
    warnings = []
    result = World(client, spec, STEP, warn=warnings.append)
    result.warnings = warnings
    yield result
    client.disconnect()


def run(world, seconds):
    for _ in range(int(round(seconds / STEP))):
        world.step()


def snapshot(world):
    return (world.client.getNumBodies(), world.model_names(),
            [world.model_pose(name) for name in world.model_names()])


# --- spawn_sdf ----------------------------------------------------------------------------
def test_sdf_box_spawns_where_asked_falls_and_rests_on_the_ground(world):
    world.spawn_sdf("crate_1", BOX_SDF, Pose.from_xyz_rpy(1, 2, 1.0, 0, 0, 0.5))
    assert world.model_names() == ["ground_plane", "crate_1"]
    run(world, 1.5)
    pose = world.model_pose("crate_1")
    assert pose.position == pytest.approx((1.0, 2.0, 0.2), abs=0.01)
    assert pose.rpy[2] == pytest.approx(0.5, abs=0.01)
    props = model_access.model_properties(world, "crate_1")
    assert props.body_names == ["body"] and props.geom_names == ["shell", "knob"]
    assert not props.is_static


def test_sdf_include_by_uri_as_spawn_model_database_sends_it(world):
    text = ("<sdf version='1.4'><world name='default'><include><uri>model://coke_can</uri>"
            "</include></world></sdf>")
    world.spawn_sdf("can", text, Pose.from_xyz_rpy(1, 1, 0.0),
                    model_path=[os.path.join(SRC, "pybullet_gazebo", "models")])
    run(world, 0.5)
    assert world.model_pose("can").position[:2] == pytest.approx((1.0, 1.0), abs=0.01)


def test_sdf_mesh_collisions_are_reported_and_the_rest_simulated(world):
    world.spawn_sdf("pair", TWO_LINKS_SDF, Pose.from_xyz_rpy(0, 0, 0.5))
    assert any("mesh" in w and "'pair'" in w for w in world.warnings)
    assert [ref.scoped for ref in model_access.links_of(world, "pair")] == \
        ["pair::left", "pair::right"]


@pytest.mark.parametrize("text, message", [
    ("<sdf><model name='x'><link name='a'>", "malformed XML at line 1"),
    ("<robot name='r'/>", "root element is <robot>"),
    ("<sdf version='1.6'><light name='sun'/></sdf>", "no <model>"),
    ("<sdf><model name='m'><link name='l'><visual name='v'/></link></model></sdf>",
     "no collision the stand-in can simulate"),
    ("<sdf><model name='m'><link name='l'><collision name='c'><geometry><box><size>1 x 1</size>"
     "</box></geometry></collision></link></model></sdf>", "must be 3 finite number"),
])
def test_bad_sdf_is_refused_and_the_world_untouched(world, text, message):
    before = snapshot(world)
    with pytest.raises(SpawnError, match=message):
        world.spawn_sdf("bad", text, Pose.from_xyz_rpy(0, 0, 1))
    assert snapshot(world) == before


def test_sdf_duplicate_name_and_nan_pose_are_refused(world):
    world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(0, 0, 1))
    before = snapshot(world)
    with pytest.raises(SpawnError, match="already exists"):
        world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(3, 0, 1))
    with pytest.raises(SpawnError, match="not finite"):
        world.spawn_sdf("other", BOX_SDF, Pose((math.nan, 0.0, 1.0)))
    assert snapshot(world) == before


def test_overlapping_sdf_spawn_warns_naming_both_and_spawns(world):
    world.spawn_sdf("a", BOX_SDF, Pose.from_xyz_rpy(0, 0, 0.2))
    world.spawn_sdf("b", BOX_SDF, Pose.from_xyz_rpy(0.1, 0, 0.2))
    assert "b" in world.model_names()
    assert any("'b' inside 'a'" in w for w in world.warnings)


# --- wrenches ------------------------------------------------------------------------------
def floating_crate(world):
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(0, 0, 2.0))
    return model_access.find_link(world, "crate::body")


def speed(world, name="crate"):
    return model_access.model_twist(world, name)


def test_a_wrench_pushes_for_its_duration_of_sim_time_then_stops(world):
    ref = floating_crate(world)
    world.wrenches.add_body_wrench(ref.scoped, ref.body_id, -1, (4.0, 0, 0), (0, 0, 0.3),
                                   start=0.0, duration=0.5, now=world.sim_time)
    run(world, 1.0)
    linear, angular = speed(world)
    # 4 N on 2 kg for 0.5 s (+ one step, Gazebo's window includes both ends): 1 m/s
    assert linear[0] == pytest.approx(1.0, abs=4.0 * STEP / 2.0 + 1e-6)
    # 0.3 N m about z on izz 0.3 kg m^2 for 0.5 s: 0.5 rad/s (Bullet's rigid-body integrator
    # gives about 5 % more: measured 0.523 for 100 steps of exactly 0.3 N m)
    assert angular[2] == pytest.approx(0.5, rel=0.07)
    assert world.wrenches.pending() == (0, 0)
    run(world, 0.5)
    assert speed(world)[0][0] == pytest.approx(linear[0], abs=1e-6)       # no more push


def test_a_wrench_waits_for_its_start_time_and_a_negative_duration_lasts_until_cleared(world):
    ref = floating_crate(world)
    world.wrenches.add_body_wrench(ref.scoped, ref.body_id, -1, (0, 2.0, 0), (0, 0, 0),
                                   start=0.5, duration=-1.0, now=world.sim_time)
    run(world, 0.495)
    assert speed(world)[0][1] == pytest.approx(0.0, abs=1e-9)
    run(world, 1.0)
    assert speed(world)[0][1] == pytest.approx(1.0, abs=0.01)             # 2 N / 2 kg, 1 s
    assert world.wrenches.clear_body_wrenches("crate::body") == 1
    before = speed(world)[0][1]
    run(world, 0.5)
    assert speed(world)[0][1] == pytest.approx(before, abs=1e-6)


def test_a_wrench_wakes_a_body_that_fell_asleep_at_rest(world):
    world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(0, 0, 0.2))
    run(world, 3.0)                                     # settled: Bullet puts it to sleep
    ref = model_access.find_link(world, "crate::body")
    world.wrenches.add_body_wrench(ref.scoped, ref.body_id, -1, (0, 0, 40.0), (0, 0, 0),
                                   start=0.0, duration=0.5, now=world.sim_time)
    run(world, 0.5)
    assert world.model_pose("crate").position[2] > 1.0


def test_a_twist_set_on_a_sleeping_body_moves_it(world):
    world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(0, 0, 0.2))
    run(world, 3.0)                                     # settled: Bullet puts it to sleep
    world.set_model_state("crate", world.model_pose("crate"), linear=(0, 0, 3.0))
    run(world, 0.2)
    assert world.model_pose("crate").position[2] > 0.5


def test_deleting_a_model_drops_its_jobs(world):
    ref = floating_crate(world)
    world.wrenches.add_body_wrench(ref.scoped, ref.body_id, -1, (1, 0, 0), (0, 0, 0),
                                   start=0.0, duration=-1.0, now=0.0)
    world.delete_model("crate")
    assert world.wrenches.pending() == (0, 0)
    run(world, 0.1)


def test_a_joint_effort_turns_a_free_joint_and_its_reaction_turns_the_base(world):
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn_urdf("pendulum", PENDULUM_URDF, Pose.from_xyz_rpy(0, 0, 2.0))
    joint = model_access.find_joint(world, "hinge")
    world.wrenches.add_joint_effort(joint.scoped, joint.body_id, joint.index, 0.1,
                                    start=0.0, duration=0.5, now=world.sim_time)
    run(world, 0.6)
    rate = model_access.joint_properties(world, joint).rate
    assert rate > 1.0                                           # the arm spun up ...
    base_spin = model_access.model_twist(world, "pendulum")[1][2]
    assert base_spin < 0.0                                      # ... and the base the other way


# --- names, states, properties ---------------------------------------------------------------
def test_urdf_links_and_joints_are_named_as_gazebo_merges_them(world):
    world.spawn_urdf("pendulum", PENDULUM_URDF, Pose.from_xyz_rpy(0, 0, 1.0))
    props = model_access.model_properties(world, "pendulum")
    assert props.body_names == ["base", "arm"]                  # 'tag' merged into 'arm'
    assert props.joint_names == ["hinge"]
    assert props.geom_names == ["base_collision", "arm_collision",
                                "arm_fixed_joint_lump__tag_collision_1"]
    assert model_access.find_link(world, "arm").scoped == "pendulum::arm"
    with pytest.raises(LookupError, match="link 'pendulum::tag' does not exist"):
        model_access.find_link(world, "pendulum::tag")
    with pytest.raises(LookupError, match="joint 'tag_joint' does not exist; joints are "
                                          "pendulum::hinge"):
        model_access.find_joint(world, "tag_joint")
    joint = model_access.joint_properties(world, model_access.find_joint(world, "pendulum::hinge"))
    assert joint.kind == "continuous"


def test_m2wr_as_gazebo_lists_it(world):
    urdf = xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()
    world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    props = model_access.model_properties(world, "m2wr")
    assert props.body_names == ["link_chassis", "link_right_wheel", "link_left_wheel"]
    assert sorted(props.joint_names) == ["joint_left_wheel", "joint_right_wheel"]


def test_link_state_is_the_link_frame_and_its_origin_velocity(world):
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn_urdf("pendulum", PENDULUM_URDF, Pose.from_xyz_rpy(1, 2, 1.0, 0, 0, math.pi / 2))
    arm = model_access.find_link(world, "pendulum::arm")
    pose, linear, angular = model_access.link_state(world, arm)
    assert pose.position == pytest.approx((1.0, 2.0, 1.3), abs=1e-6)
    assert pose.rpy[2] == pytest.approx(math.pi / 2, abs=1e-6)
    world.set_model_state("pendulum", Pose.from_xyz_rpy(1, 2, 1.0), angular=(0, 0, 2.0))
    _, linear, angular = model_access.link_state(world, arm)
    assert angular[2] == pytest.approx(2.0, abs=1e-6)
    assert np.linalg.norm(linear) == pytest.approx(0.0, abs=1e-6)    # on the spin axis


def test_set_link_state_moves_a_world_link_alone_and_refuses_a_robot_child_link(world):
    world.spawn_sdf("pair", TWO_LINKS_SDF, Pose.from_xyz_rpy(0, 0, 0.5))
    right = model_access.find_link(world, "pair::right")
    model_access.set_link_state(world, right, Pose.from_xyz_rpy(3, 3, 0.5), (0, 0, 0), (0, 0, 0))
    assert model_access.link_state(world, right)[0].position == pytest.approx((3, 3, 0.5))
    assert world.model_pose("pair").position == pytest.approx((0, 0, 0.5))
    world.spawn_urdf("pendulum", PENDULUM_URDF, Pose.from_xyz_rpy(5, 0, 1.0))
    with pytest.raises(ValueError, match="root link only"):
        model_access.set_link_state(world, model_access.find_link(world, "pendulum::arm"),
                                    Pose(), (0, 0, 0), (0, 0, 0))


def test_link_properties_are_the_description_s_and_mass_and_gravity_mode_can_change(world):
    world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(0, 0, 1.0))
    ref = model_access.find_link(world, "crate::body")
    props = model_access.link_properties(world, ref)
    assert props.mass == 2.0 and props.inertia == (0.1, 0.2, 0.3) and props.gravity_mode
    world.spawn_urdf("pendulum", PENDULUM_URDF, Pose.from_xyz_rpy(3, 0, 2.0))
    base = model_access.find_link(world, "pendulum::base")
    assert model_access.link_properties(world, base).mass == pytest.approx(1.0)
    arm = model_access.find_link(world, "pendulum::arm")
    for link in (base, arm):
        current = model_access.link_properties(world, link)
        model_access.set_link_properties(world, link, current.mass, current.com,
                                         current.inertia, (0, 0, 0), gravity_mode=False)
    run(world, 0.5)
    assert world.model_pose("pendulum").position[2] == pytest.approx(2.0, abs=1e-3)   # floats
    with pytest.raises(ValueError, match="products of inertia"):
        model_access.set_link_properties(world, base, 1.0, Pose(), (1, 1, 1), (0.1, 0, 0), True)
    with pytest.raises(ValueError, match="centre of mass"):
        model_access.set_link_properties(world, base, 1.0, Pose((0.5, 0, 0)), (1, 1, 1),
                                         (0, 0, 0), True)


def test_set_model_configuration_sets_joints_and_refuses_unknown_ones_untouched(world):
    world.spawn_urdf("pendulum", PENDULUM_URDF, Pose.from_xyz_rpy(0, 0, 1.0))
    model_access.set_model_configuration(world, "pendulum", ["hinge"], [1.2])
    joint = model_access.find_joint(world, "hinge")
    assert model_access.joint_properties(world, joint).position == pytest.approx(1.2)
    with pytest.raises(LookupError, match="no joint 'elbow'"):
        model_access.set_model_configuration(world, "pendulum", ["hinge", "elbow"], [0.0, 1.0])
    with pytest.raises(ValueError, match="2 joint names but 1 positions"):
        model_access.set_model_configuration(world, "pendulum", ["hinge", "hinge"], [0.0])
    assert model_access.joint_properties(world, joint).position == pytest.approx(1.2)


# --- physics -----------------------------------------------------------------------------------
def test_time_step_change_keeps_sim_time_running_on(world):
    run(world, 1.0)
    world.set_step_size(0.001)
    for _ in range(500):
        world.step()
    assert world.sim_time == pytest.approx(1.5, abs=1e-9)
    assert world.sim_time_ns() == 1500000000            # the stamps: exact, no drift
    with pytest.raises(ValueError, match="time_step"):
        world.set_step_size(0.0)
    assert world.step_size == 0.001


def test_gravity_change_acts_on_resting_bodies(world):
    world.spawn_sdf("crate", BOX_SDF, Pose.from_xyz_rpy(0, 0, 0.2))
    run(world, 1.0)                             # settled (and asleep)
    world.set_gravity((0.0, 0.0, 9.8))
    run(world, 0.5)
    assert world.model_pose("crate").position[2] > 1.0
    with pytest.raises(ValueError, match="gravity"):
        world.set_gravity((0.0, math.nan, 0.0))
