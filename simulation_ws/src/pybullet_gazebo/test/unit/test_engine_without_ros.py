"""The engine core knows nothing of ROS: every engine module imports, and a world steps, in a
Python where rospy and the message packages cannot be imported at all."""
import os
import subprocess
import sys

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "src"))
WORLDS = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "worlds"))

GUARDED_RUN = r"""
import importlib, pkgutil, sys
for name in ("rospy", "genpy", "roslib", "std_msgs", "sensor_msgs", "geometry_msgs",
             "nav_msgs", "gazebo_msgs", "tf2_ros", "rosgraph"):
    sys.modules[name] = None            # any import of them now raises ImportError
import pybullet_gazebo.engine as engine
for module in pkgutil.iter_modules(engine.__path__):
    importlib.import_module("pybullet_gazebo.engine." + module.name)
import pybullet
from pybullet_utils.bullet_client import BulletClient
from pybullet_gazebo.engine.sdf_world import load_world, model_path_from_env
from pybullet_gazebo.engine.world import World
spec = load_world(sys.argv[1], model_path_from_env(sys.argv[2]))
world = World(BulletClient(connection_mode=pybullet.DIRECT), spec, 0.005)
for _ in range(10):
    world.step()
print("stepped to", world.sim_time)
"""


def test_engine_imports_and_steps_without_ros():
    env = dict(os.environ, PYTHONPATH=SRC)
    result = subprocess.run(
        [sys.executable, "-c", GUARDED_RUN, os.path.join(WORLDS, "empty.world"),
         os.path.join(os.path.dirname(SRC), "models")],
        capture_output=True, text=True, env=env, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "stepped to 0.05" in result.stdout
