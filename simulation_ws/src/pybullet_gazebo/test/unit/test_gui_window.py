"""The GUI's simulator side (gui/window.py) without a display: a stand-in viewer process
records what it is sent, and the test checks that it is what a window would need to show
the world: the world, the robot, frames with the robot where the engine has it, and laser
beams only for sensors whose <visualize> is true (unless gui_rays says otherwise). Also:
a display that cannot be opened gives a warning and no window, and the appearance facts."""
import os
import pickle
import sys
import time

import numpy as np
import pybullet
import pytest
import xacro
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine import appearance
from pybullet_gazebo.engine.diff_drive import DiffDrive
from pybullet_gazebo.engine.robot_description import parse_robot
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.transforms import Pose
from pybullet_gazebo.engine.world import World
from pybullet_gazebo.gui import window as gui_window
from pybullet_gazebo.ros.testing import wait_until

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STEP = 0.005
RECORDER = """
import shutil, sys
with open(sys.argv[1], "wb") as out:        # the bytes as they come; unpickled by the test
    while True:
        chunk = sys.stdin.buffer.read1(65536)
        if not chunk:
            break
        out.write(chunk)
        out.flush()
"""


@pytest.fixture(scope="module")
def m2wr_urdf():
    return xacro.process_file(os.path.join(SRC, "m2wr_description", "urdf", "m2wr.xacro")).toxml()


@pytest.fixture
def world02():
    client = BulletClient(connection_mode=pybullet.DIRECT)
    path = os.path.join(SRC, "my_worlds", "worlds", "world02.world")
    yield World(client, load_world(path, model_path_from_env(
        os.path.join(SRC, "pybullet_gazebo", "models"))), STEP, warn=lambda m: None)
    client.disconnect()


def recorded(path):
    messages = []
    with open(path, "rb") as source:
        while True:
            try:
                messages.append(pickle.load(source))
            except (EOFError, pickle.UnpicklingError):
                # the end, or a message cut short: close() ends the viewer at once
                return messages


def run_window(tmp_path, world, urdf, rays, seconds=1.0):
    record = str(tmp_path / "sent.pickle")
    notes = []
    window = gui_window.GuiWindow(world, 20.0, rays, False, notes.append, notes.append,
                                  viewer=[sys.executable, "-c", RECORDER, record])
    # 20 s: the viewer's interpreter starts slowly on a busy machine
    wait_until(lambda: os.path.exists(record), 20.0, "the viewer's first write", interval=0.05)
    time.sleep(0.2)
    robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(0, 8, 0.5))
    world.step()                # the first scan loads the compiled ray caster (seconds)
    window.add_robot(robot, urdf)
    next(p for p in robot.parts if isinstance(p, DiffDrive)).set_command(0.5, 0.0)
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        # 2 s of sim time at most (1 m of driving, still in the corridor), however fast the
        # machine steps; frames keep coming at the window's own wall-clock rate
        if world.sim_time < 2.0:
            window.after_step(world.step())
        else:
            time.sleep(0.005)
            window.after_step([])
    time.sleep(0.3)                       # the writer thread's last frame
    window.close()
    return recorded(record), notes


def test_the_viewer_gets_the_world_the_robot_and_frames_where_the_robot_is(tmp_path, world02,
                                                                            m2wr_urdf):
    messages, notes = run_window(tmp_path, world02, m2wr_urdf, rays="sdf")
    assert notes == []
    kinds = [m[0] for m in messages]
    assert kinds[:2] == ["world", "robot"]
    assert messages[0][1].name == world02.spec.name
    frames = [m for m in messages if m[0] == "frame"]
    assert 3 <= len(frames) <= 21                      # at most 20 per wall second
    _, sim_time, rtf, moving, robots, beams = frames[-1]
    assert sim_time > 0 and rtf >= 0
    assert "coke_can" in moving and "jersey_barrier" not in moving     # static ones: once
    root, joints = robots["m2wr"]
    assert root.position[1] == pytest.approx(8.0, abs=0.05)
    assert set(joints) >= {"joint_left_wheel", "joint_right_wheel"}
    assert beams == []               # m2wr's laser says <visualize>false, as Gazebo: none drawn


def test_beams_are_sent_when_asked_and_end_at_the_returns(tmp_path, world02, m2wr_urdf):
    messages, _ = run_window(tmp_path, world02, m2wr_urdf, rays="true")
    frames = [m for m in messages if m[0] == "frame" and m[5]]
    assert frames
    origin, ends, hits = frames[-1][5][0]
    lengths = np.linalg.norm(ends - origin, axis=1)
    assert len(ends) == 240 and hits.any()
    assert lengths.max() <= 10.0 + 1e-6 and lengths[hits].min() >= 0.1 - 1e-6
    assert origin[2] == pytest.approx(0.15, abs=0.02)        # the laser's height on m2wr


def test_gui_rays_sdf_draws_a_laser_whose_description_says_visualize_true(tmp_path, world02,
                                                                         m2wr_urdf):
    urdf = m2wr_urdf.replace("<visualize>false</visualize>", "<visualize>true</visualize>")
    assert urdf != m2wr_urdf
    messages, _ = run_window(tmp_path, world02, urdf, rays="sdf")
    assert [m for m in messages if m[0] == "frame" and m[5]]


def test_a_display_that_cannot_be_opened_gives_a_warning_and_no_window(monkeypatch, world02):
    monkeypatch.setenv("DISPLAY", ":4321")
    warnings = []
    assert gui_window.open_window(world02, warn=warnings.append) is None
    assert len(warnings) == 1 and "DISPLAY=:4321 cannot be opened" in warnings[0]
    assert "headless" in warnings[0]


def test_gazebo_and_urdf_colours(m2wr_urdf):
    description = parse_robot(m2wr_urdf, "m2wr")
    colours = appearance.urdf_link_colours(description.urdf)
    assert colours["link_chassis"] == appearance.GAZEBO_MATERIALS["Gazebo/Orange"]
    assert colours["link_left_wheel"] == (0.0, 0.0, 1.0, 1.0)        # Gazebo/Blue wins
    assert {s.name: s.visualize for s in description.sensors} == {"head_hokuyo_sensor": False}
    path = os.path.join(SRC, "my_worlds", "worlds", "world02.world")
    spec = load_world(path, model_path_from_env(os.path.join(SRC, "pybullet_gazebo", "models")))
    by_name = {m.name: m.links[0].colour for m in spec.models}
    assert by_name["jersey_barrier"] == (0.7, 0.7, 0.7, 1.0)
    assert by_name["construction_barrel"] == (1.0, 0.5088, 0.0468, 1.0)
    assert by_name["coke_can"] == (1.0, 0.0, 0.0, 1.0)
