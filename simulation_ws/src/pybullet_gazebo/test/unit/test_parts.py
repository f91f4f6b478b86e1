"""The parts contract: the World builds a robot's parts from the registry and calls every
hook of the contract, in order, without probing a part for what it can do. A new part kind is
one Part subclass in the registry (and, for ROS, one binding)."""
import os

import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import registry
from pybullet_gazebo.engine.contacts import ContactTracker
from pybullet_gazebo.engine.part import Part
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
MODELS = os.path.join(SRC, "pybullet_gazebo", "models")
EMPTY = os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world")
STEP = 0.005    # [s]

COUNTER_PLUGIN = """
  <gazebo><plugin name="counter" filename="libtest_step_counter.so">
    <rate>10</rate></plugin></gazebo>
</robot>"""


class StepCounter(Part):
    """A part that only counts: readings at <rate> Hz of sim time, the number of steps."""
    KEY = "libtest_step_counter.so"

    def __init__(self, rate):
        self.period = 1.0 / rate
        self.calls = []
        self.steps = 0
        self.last = None

    @classmethod
    def build(cls, context, plugin):
        return cls(float(plugin.params["rate"]))

    def before_step(self, now, dt):
        self.calls.append(("before", round(now, 6), dt))

    def after_step(self, now):
        self.steps += 1
        self.calls.append(("after", round(now, 6)))

    def due(self, now):
        return self.last is None or now - self.last >= self.period - 1e-9

    def measure(self, now):
        self.last = now
        return self.steps

    def reset(self):
        self.steps, self.last = 0, None


@pytest.fixture
def world(monkeypatch):
    monkeypatch.setitem(registry.PLUGIN_PARTS, StepCounter.KEY, StepCounter)
    client = BulletClient(connection_mode=pybullet.DIRECT)
    warnings = []
    world = World(client, load_world(EMPTY, model_path_from_env(MODELS)), STEP,
                  warn=warnings.append)
    world.warnings = warnings
    yield world
    client.disconnect()


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


def test_a_new_part_kind_is_one_class_in_the_registry(world, m2wr_urdf):
    urdf = m2wr_urdf.replace("</robot>", COUNTER_PLUGIN)
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    counter = next(p for p in robot.parts if isinstance(p, StepCounter))
    readings = []
    for _ in range(60):                       # 0.3 s of sim time
        readings += [r for r in world.step() if r.part is counter]
    assert counter.calls[:4] == [("before", 0.0, STEP), ("after", 0.005),
                                 ("before", 0.005, STEP), ("after", 0.01)]
    # due at 0.005 (first), then every 0.1 s: 0.105, 0.205
    assert [r.data for r in readings] == [1, 21, 41]
    assert not any("libtest_step_counter" in w for w in world.warnings)
    world.reset_world()
    assert counter.steps == 0


def test_parts_without_a_drive_leave_lockstep_and_turning_alone(world, m2wr_urdf):
    """Every part answers the whole contract: the defaults say 'no command, no turning'."""
    robot = world.spawn_urdf("m2wr", m2wr_urdf.replace("</robot>", COUNTER_PLUGIN),
                             Pose.from_xyz_rpy(0, 0, 0.5))
    counter = next(p for p in robot.parts if isinstance(p, StepCounter))
    assert counter.next_command_time() is None and counter.positive_turn_direction() is None
    assert world.positive_turn_direction(robot) == "clockwise"       # from the diff drive
    assert world.next_command_time() == 0.0


def test_an_unknown_plugin_is_reported_by_name(world, m2wr_urdf):
    urdf = m2wr_urdf.replace("</robot>", COUNTER_PLUGIN.replace("libtest_step_counter.so",
                                                                "libnot_here.so"))
    world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.5))
    assert any("plugin 'counter' (libnot_here.so) is not simulated" in w
               for w in world.warnings)


def test_contact_history_is_bounded_but_counted():
    tracker = ContactTracker(max_events=3)

    class Client:
        def __init__(self):
            self.touch = False

        def getContactPoints(self, bodyA):
            return [(0, bodyA, 7)] if self.touch else []

    client = Client()
    for step in range(10):                   # touch, let go, touch, ...: 5 onsets
        client.touch = step % 2 == 0
        tracker.update(client, step * 0.1, [("robot", 1)], {7: "wall"}, grounds=set())
    assert tracker.event_count == 5
    assert [round(e.sim_time, 1) for e in tracker.events] == [0.4, 0.6, 0.8]
    assert tracker.touching() == []
