"""/gazebo/model_states and link_states as state_topics.py builds them (cached static rows,
resting bodies not recomputed, one reused message) carry exactly what a fresh computation
gives, at every message, while the robot drives, a barrel is pushed and a model is
teleported; the wall-time limit skips messages. World02 + m2wr, DIRECT mode; the publisher is
replaced by a recorder, so no master is needed."""
import os

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import model_access
from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World
from pybullet_gazebo.ros import state_topics

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005            # [s]


class Recorder:
    """Stands in for DirectPublisher: one subscriber, keeps a copy of each message."""

    def __init__(self, topic, data_class):
        self.topic = topic
        self.sent = []

    def get_num_connections(self):
        return 1

    def publish(self, msg):
        self.sent.append((msg.name[:],
                          [(p.position.x, p.position.y, p.position.z, p.orientation.x,
                            p.orientation.y, p.orientation.z, p.orientation.w)
                           for p in msg.pose],
                          [(t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y,
                            t.angular.z) for t in msg.twist]))

    def unregister(self):
        pass


@pytest.fixture
def world(monkeypatch):
    monkeypatch.setattr(state_topics, "DirectPublisher", Recorder)
    path = os.path.join(SRC, "my_worlds", "worlds", "world02.world")
    client = BulletClient(connection_mode=pybullet.DIRECT)
    world = World(client, load_world(path, model_path_from_env(
        os.path.join(SRC, "pybullet_gazebo", "models"))), STEP, warn=lambda m: None)
    urdf = xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf",
                                           "m2wr.xacro")).toxml()
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 8, 0.1))
    for drive in robot.parts_with(DiffDrive.KEY):
        drive.set_command(0.3, 0.4)
    yield world
    client.disconnect()


def fresh_model_rows(world):
    rows = []
    for name in world.model_names():
        pose, linear, angular = model_access.model_state(world, name)
        rows.append((name, tuple(map(float, (*pose.position, *pose.orientation))),
                     tuple(map(float, (*linear, *angular)))))
    return rows


def fresh_link_rows(world):
    rows = []
    for name in world.model_names():
        for ref in model_access.links_of(world, name):
            pose, linear, angular = model_access.link_state(world, ref)
            rows.append((ref.scoped, tuple(map(float, (*pose.position, *pose.orientation))),
                         tuple(map(float, (*linear, *angular)))))
    return rows


def as_rows(sent):
    names, poses, twists = sent
    return list(zip(names, poses, twists))


def test_every_message_equals_a_fresh_computation(world):
    topics = state_topics.StateTopics(world)
    moving = [n for n in world.model_names() if not world.entities[n].static]
    assert "m2wr" in moving and "construction_barrel" in moving
    for step in range(1, 1201):
        world.step()
        if step == 300:          # push a resting barrel: it wakes and slides
            pose = world.model_pose("construction_barrel")
            world.set_model_state("construction_barrel", pose, linear=(1.5, 0, 0))
        if step == 700:          # teleport the coke can (a new layout)
            world.set_model_state("coke_can", Pose.from_xyz_rpy(1, 1, 0.2))
        if step % 10 == 0:
            topics.publish()
            assert as_rows(topics.model_states.publisher.sent[-1]) == fresh_model_rows(world)
            assert as_rows(topics.link_states.publisher.sent[-1]) == fresh_link_rows(world)
    first, last = (as_rows(topics.model_states.publisher.sent[i]) for i in (0, -1))
    moved = {a[0] for a, b in zip(first, last) if a != b}
    assert {"m2wr", "construction_barrel", "coke_can"} <= moved


def test_the_wall_time_limit_skips_messages(world):
    topics = state_topics.StateTopics(world, wall_limit=30.0)
    for _ in range(200):                 # far faster than 30 per wall second
        world.step()
        topics.publish()
    sent = len(topics.model_states.publisher.sent)
    assert 1 <= sent < 200 and topics.skipped() >= 2 * (200 - sent)


def test_wanted_says_whether_a_due_message_would_go_out(world):
    # the loop steps past model_states' due steps while wanted() is false (faster than
    # real time, the limit would skip them): it must be false exactly then
    topics = state_topics.StateTopics(world, wall_limit=30.0)
    wall = [100.0]
    for message in (topics.model_states, topics.link_states):
        message.limit._clock = lambda: wall[0]
    answers = []
    for _ in range(40):                  # all at one wall instant: the burst, then none
        world.step()
        wanted = topics.wanted()
        before = len(topics.model_states.publisher.sent)
        topics.publish()
        assert (len(topics.model_states.publisher.sent) > before) == wanted
        answers.append(wanted)
    assert answers[0] and not answers[-1]
    wall[0] += 1.5 / 30.0                # over one message's worth of wall time later
    assert topics.wanted()
