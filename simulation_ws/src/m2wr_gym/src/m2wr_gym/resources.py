"""Where the environments find the tutorial's files, without a ROS master: the worlds of
`my_worlds`, the models of `pybullet_gazebo` (for `model://` includes), and m2wr's URDF,
expanded from `m2wr_description/urdf/m2wr.xacro` with the PyPI xacro of the venv once per
process (and cached on disk under ~/.cache/m2wr_gym, keyed by the xacro files' contents).

Packages are found with rospkg (ROS_PACKAGE_PATH, set by `source scripts/env.sh`), else
beside this package in the source tree (simulation_ws/src).
"""
import functools
import hashlib
import os
import subprocess
import sys

from pybullet_gazebo.engine.sdf_world import (WorldFileError, find_world, load_world,
                                               model_path_from_env)

_SRC = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
CACHE_DIR = os.path.join(os.path.expanduser("~"), ".cache", "m2wr_gym")


def package_path(name):
    """Directory of a catkin package of this workspace."""
    try:
        import rospkg
        return rospkg.RosPack().get_path(name)
    except Exception:                # no ROS_PACKAGE_PATH or rospkg: the source tree
        path = os.path.join(_SRC, name)
        if os.path.isdir(path):
            return path
        raise FileNotFoundError("package '%s' not found (ROS_PACKAGE_PATH and %s); run "
                                "'source scripts/env.sh' first" % (name, _SRC))


def worlds_dir():
    return os.path.join(package_path("my_worlds"), "worlds")


def world_names():
    return sorted(f[:-len(".world")] for f in os.listdir(worlds_dir()) if f.endswith(".world"))


def resolve_world(world):
    """Absolute path of `world`: a name of my_worlds (world01, world02) or a .world file path.
    ValueError naming the input and the known worlds otherwise."""
    try:
        return find_world(str(world), worlds_dir())
    except WorldFileError as err:
        raise ValueError("option world=%r: %s" % (world, err)) from None


@functools.lru_cache(maxsize=8)
def world_spec(path):
    """The WorldSpec of a world file (cached per process)."""
    models = os.path.join(package_path("pybullet_gazebo"), "models")
    try:
        return load_world(path, model_path_from_env(models))
    except WorldFileError as err:
        raise ValueError("option world=%r: %s" % (path, err)) from None


@functools.lru_cache(maxsize=1)
def robot_urdf():
    """m2wr's URDF as spawn.launch gives it to the simulator (xacro output)."""
    urdf_dir = os.path.join(package_path("m2wr_description"), "urdf")
    digest = hashlib.sha256()
    for name in sorted(os.listdir(urdf_dir)):
        if name.endswith((".xacro", ".gazebo")):
            with open(os.path.join(urdf_dir, name), "rb") as f:
                digest.update(name.encode() + b"\0" + f.read())
    cached = os.path.join(CACHE_DIR, "m2wr-%s.urdf" % digest.hexdigest()[:16])
    if os.path.isfile(cached):
        with open(cached) as f:
            return f.read()
    xacro = os.path.join(os.path.dirname(sys.executable), "xacro")
    command = [xacro] if os.path.isfile(xacro) else [sys.executable, "-m", "xacro"]
    text = subprocess.run(command + [os.path.join(urdf_dir, "m2wr.xacro")], check=True,
                          capture_output=True, text=True).stdout
    os.makedirs(CACHE_DIR, exist_ok=True)
    temporary = "%s.%d" % (cached, os.getpid())      # several processes may race to write it
    with open(temporary, "w") as f:
        f.write(text)
    os.replace(temporary, cached)
    return text
