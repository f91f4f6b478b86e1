"""World.step(collect=...): a caller that reads only some readings (the Gymnasium environment
observes one scan per control step) gets exactly the readings it would have got had every
part measured at every due time: skipped parts keep their schedules and noise streams."""
import os

import numpy as np
import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.ray_sensor import RaySensor
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
MODELS = os.path.join(SRC, "pybullet_gazebo", "models")
EMPTY = os.path.join(SRC, "pybullet_gazebo", "worlds", "empty.world")
STEP = 0.005    # [s]
BOX = """<sdf version="1.6"><model name="box"><static>true</static><link name="link">
  <collision name="c"><geometry><box><size>0.5 3 1</size></box></geometry></collision>
</link></model></sdf>"""


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


def make_world(urdf):
    """m2wr (noisy laser, 20 Hz; odometry and joint states at 20 Hz) driving towards a box."""
    client = BulletClient(connection_mode=pybullet.DIRECT)
    world = World(client, load_world(EMPTY, model_path_from_env(MODELS)), STEP, seed=7,
                  warn=lambda message: None)
    world.spawn_sdf("box", BOX, Pose.from_xyz_rpy(2.0, 0.0, 0.5))
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 0, 0.1))
    [drive] = robot.parts_with(DiffDrive.KEY)
    [laser] = robot.parts_with(RaySensor.KEY)
    drive.set_command(0.4, 0.3)
    return client, world, laser


def test_skipped_scans_leave_the_observed_ones_bit_identical(m2wr_urdf):
    client_a, every, laser_a = make_world(m2wr_urdf)
    client_b, some, laser_b = make_world(m2wr_urdf)
    assert laser_a.spec.noise_stddev > 0.0          # the noise stream is part of the test
    scans_a, scans_b, kinds_b = {}, {}, set()
    for k in range(300):                            # 1.5 s: 31 scans, the box in view
        for r in every.step():
            if r.part is laser_a:
                scans_a[r.data.stamp] = r.data.ranges
        wanted = (laser_b,) if k % 7 == 0 else ()   # an irregular choice of scans
        readings = some.step(collect=wanted)
        kinds_b |= {type(r.part).__name__ for r in readings}
        for r in readings:
            scans_b[r.data.stamp] = r.data.ranges
    assert kinds_b == {"RaySensor"}                 # nothing else was measured
    assert 3 <= len(scans_b) < len(scans_a)
    for stamp, ranges in scans_b.items():           # same times, same noise draws
        assert np.array_equal(ranges, scans_a[stamp]), stamp
    hits = np.isfinite(next(iter(scans_b.values())))
    assert hits.any() and not hits.all()            # the box is seen, the rest is open
    assert every.model_pose("m2wr").position == some.model_pose("m2wr").position
    client_a.disconnect()
    client_b.disconnect()


def test_scans_at_foretells_when_the_laser_is_due(m2wr_urdf):
    client, world, laser = make_world(m2wr_urdf)
    world.step()                                    # first scan at 0.005 s
    for steps in (20, 7, 13, 1, 30):
        foretold = laser.scans_at([world.time_after(k) for k in range(1, steps + 1)])
        seen = [k for k in range(steps)
                if any(r.part is laser for r in world.step(collect=(laser,)))]
        assert foretold == seen
    assert world.time_after(0) == world.sim_time
    client.disconnect()


def test_collect_true_still_returns_every_due_reading(m2wr_urdf):
    client, world, laser = make_world(m2wr_urdf)
    kinds = set()
    for _ in range(10):
        kinds |= {type(r.part).__name__ for r in world.step()}
    assert kinds == {"RaySensor", "DiffDrive", "JointStatePublisher"}
    client.disconnect()
