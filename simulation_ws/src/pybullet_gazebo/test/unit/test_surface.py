"""Contact surfaces as Gazebo has them (surface.py): the friction of a pair is Gazebo's
min(mu_a, mu_b), not Bullet's product; kp and kd reach Bullet; a URDF gives them only through
<gazebo reference> (robot_description). DIRECT mode, no ROS."""
import os

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import surface
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.wheel_contact import SUFFIX
from pybullet_gazebo.engine.world import World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
FIXTURES = os.path.join(SRC, "pybullet_gazebo", "test", "fixtures")
G = 9.8                  # [m/s^2] the worlds' gravity
STEP = 0.001             # [s]


def world_file(folder, mu_ground, mu_box, contact=""):
    text = """<?xml version="1.0"?><sdf version="1.6"><world name="slide">
<model name="ground"><static>true</static><link name="l"><collision name="c">
  <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
  <surface><friction><ode><mu>%g</mu><mu2>%g</mu2></ode></friction></surface></collision>
</link></model>
<model name="box"><pose>0 0 0.05 0 0 0</pose><link name="l">
  <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia>
  </inertial>
  <collision name="c"><geometry><box><size>0.2 0.2 0.1</size></box></geometry>
  <surface><friction><ode><mu>%g</mu><mu2>%g</mu2></ode></friction>%s</surface></collision>
</link></model></world></sdf>""" % (mu_ground, mu_ground, mu_box, mu_box, contact)
    path = os.path.join(str(folder), "slide.world")
    with open(path, "w") as out:
        out.write(text)
    return path


@pytest.fixture
def clients():
    made = []
    yield made
    for client in made:
        client.disconnect()


def slide(clients, folder, mu_ground, mu_box, contact=""):
    """The box, settled, is pushed at 3 m/s along x: (deceleration / g, settled height [m],
    the box's Bullet dynamics info)."""
    client = BulletClient(connection_mode=pybullet.DIRECT)
    clients.append(client)
    world = World(client, load_world(world_file(folder, mu_ground, mu_box, contact), []), STEP)
    for _ in range(200):
        world.step()
    body = world.entity("box").body_ids[0]
    z = client.getBasePositionAndOrientation(body)[0][2]
    world.set_model_state("box", Pose((0.0, 0.0, z)), linear=(3.0, 0.0, 0.0))
    speeds = []
    for _ in range(120):
        world.step()
        speeds.append(client.getBaseVelocity(body)[0][0])
    return (speeds[20] - speeds[119]) / (99 * STEP) / G, z, client.getDynamicsInfo(body, -1)


# --- the rules ----------------------------------------------------------------------------
@pytest.mark.parametrize("mu_a, mu_b", [(1, 100), (0, 100), (1, 1), (0.3, 100), (0.2, 1),
                                        (1, 50), (0.0, 0.0)])
def test_products_of_the_coefficients_are_gazebos_minimum_for_the_pairs_that_occur(mu_a, mu_b):
    """The tutorial's pairs: wheel 1 / caster 0 / barrels and barriers 1 against each other
    and the ground's 100, and any pair with a default (1) surface."""
    assert surface.exact_pair(mu_a, mu_b)
    assert surface.bullet_pair_friction(surface.bullet_friction(mu_a),
                                        surface.bullet_friction(mu_b)) == pytest.approx(
        min(mu_a, mu_b))


def test_pairs_of_two_non_default_surfaces_on_one_side_of_1_are_known_inexact():
    assert not surface.exact_pair(0.5, 0.5)         # 0.25 in Bullet
    assert not surface.exact_pair(2.0, 3.0)         # 1 in Bullet


@pytest.mark.parametrize("mu_wheel, mu_ground", [(1, 100), (2, 100), (0.5, 0.5), (0.8, 0.3),
                                                 (1, 0)])
def test_a_wheels_ground_contact_gets_gazebos_minimum_for_any_values(mu_wheel, mu_ground):
    sphere = surface.ground_contact_friction(mu_wheel, mu_ground)
    ground = surface.bullet_friction(mu_ground)
    assert surface.bullet_pair_friction(sphere, ground) == pytest.approx(min(mu_wheel, mu_ground))


def test_contact_springs_combine_in_series_and_dampers_add_up():
    pair = surface.combined_contact(surface.Contact(1e5, 10.0), surface.Contact(1e5, 5.0))
    assert pair == surface.Contact(pytest.approx(5e4), 15.0)


# --- what a user sees ---------------------------------------------------------------------
@pytest.mark.parametrize("mu_ground, mu_box", [(100, 1), (100, 0.3), (0.2, 1)])
def test_a_box_sliding_on_the_ground_decelerates_at_the_smaller_mu_times_g(
        clients, tmp_path, mu_ground, mu_box):
    """Gazebo (ODE) brakes a sliding box at min(mu_ground, mu_box) g. Bullet's own rule, the
    product clamped to 10, gave 10 g for the first two (the box stopped in 3 cm)."""
    deceleration, _, _ = slide(clients, tmp_path, mu_ground, mu_box)
    assert deceleration == pytest.approx(min(mu_ground, mu_box), rel=0.05)


def test_m2wr_meets_world02_with_gazebos_friction(clients):
    """The wheels' ground contacts get min(1, 100) = 1 (it was 10: 1 x 100, clamped), a wheel
    against a barrier min(1, 1) = 1, and the caster min(1, 100) = 1, as in Gazebo: the xacro's
    mu 0 sits in a <surface> inside the URDF <collision>, which Gazebo never reads (the
    stand-in gave it 0 before). One warning at spawn says so."""
    client = BulletClient(connection_mode=pybullet.DIRECT)
    clients.append(client)
    spec = load_world(os.path.join(SRC, "my_worlds", "worlds", "world02.world"),
                      model_path_from_env(os.path.join(SRC, "pybullet_gazebo", "models")))
    warnings = []
    world = World(client, spec, 0.005, warn=warnings.append)
    urdf = xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf",
                                           "m2wr.xacro")).toxml()
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 8, 0.5))

    def coefficient(body, link=-1):
        return client.getDynamicsInfo(body, link)[1]

    ground = coefficient(world.entity("ground_plane").body_ids[0])
    barrier = coefficient(world.entity(next(n for n in world.model_names()
                                            if "jersey_barrier" in n)).body_ids[0])
    links = robot.links
    for wheel in ("link_left_wheel", "link_right_wheel"):
        contact = coefficient(robot.body_id, links[wheel + SUFFIX])
        assert surface.bullet_pair_friction(contact, ground) == pytest.approx(1.0)
        assert surface.bullet_pair_friction(coefficient(robot.body_id, links[wheel]),
                                            barrier) == pytest.approx(1.0)
    # link_chassis (Bullet's base, -1) holds the chassis box and the caster sphere
    assert surface.bullet_pair_friction(coefficient(robot.body_id, -1), ground) == \
        surface.gazebo_friction(surface.DEFAULT_MU, 100.0) == 1.0
    about_caster = [w for w in warnings if "caster_front_collision" in w]
    assert about_caster == [
        "model 'm2wr': link 'link_chassis' collision 'caster_front_collision': <surface> is "
        "ignored, as in Gazebo: a URDF <collision> is read for its name, <origin> and "
        "<geometry> only, so this collision has the link's friction, mu = mu2 = 1 (SDF's "
        "default). To set friction or contact values, use <gazebo reference=\"link_chassis\"> "
        "with <mu1>/<mu2> (<kp>/<kd>) instead"]


def test_gazebo_reference_friction_and_contact_reach_bullet(clients, tmp_path):
    """fixtures/urdf/gazebo_reference_friction.urdf: <gazebo reference="base"> mu1 0.3 (its
    collision's <surface> mu 0 is ignored), <gazebo reference="pad"> mu1 0, kp 1e5, kd 20;
    on a ground of mu 100 the pairs get Gazebo's min: 0.3 and 0."""
    client = BulletClient(connection_mode=pybullet.DIRECT)
    clients.append(client)
    warnings = []
    world = World(client, load_world(world_file(tmp_path, 100, 1), []), STEP,
                  warn=warnings.append)
    with open(os.path.join(FIXTURES, "urdf", "gazebo_reference_friction.urdf")) as source:
        robot = world.spawn_urdf("fx", source.read(), Pose.from_xyz_rpy(2, 0, 0.2))
    ground = client.getDynamicsInfo(world.entity("ground").body_ids[0], -1)[1]
    base = client.getDynamicsInfo(robot.body_id, robot.links["base"])
    pad = client.getDynamicsInfo(robot.body_id, robot.links["pad"])
    assert base[1] == pytest.approx(0.3)
    assert surface.bullet_pair_friction(base[1], ground) == pytest.approx(
        surface.gazebo_friction(0.3, 100.0))
    assert pad[1] == 0.0
    assert surface.bullet_pair_friction(pad[1], ground) == 0.0
    assert (pad[9], pad[8]) == pytest.approx((1e5, 20.0))       # contact stiffness, damping
    assert len(warnings) == 1
    assert warnings[0].startswith("model 'fx': link 'base' collision 'skid': <surface> is "
                                  "ignored, as in Gazebo")
    assert "mu1 = 0.3, mu2 = 0.4 (its <gazebo reference>)" in warnings[0]


def test_kp_and_kd_of_a_surface_reach_bullet_and_a_softer_spring_sinks_deeper(clients,
                                                                               tmp_path):
    soft = "<contact><ode><kp>1e4</kp><kd>100</kd></ode></contact>"
    # (pybullet's getDynamicsInfo reports no stiffness for a maximal body: what it does shows)
    _, z_soft, _ = slide(clients, tmp_path, 100, 1, soft)
    _, z_stiff, _ = slide(clients, tmp_path, 100, 1)          # SDF's defaults: rigid
    assert z_stiff == pytest.approx(0.05, abs=2e-4)
    assert z_soft < z_stiff - 3e-4                           # 0.5 mm against 0.01 mm
