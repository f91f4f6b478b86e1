"""Where things are: the project's root (output/ goes under it by default), the world files
and Gazebo-style model folders the simulator loads (found through rospkg, as roslaunch
finds them), and the robot's URDF made by xacro."""
import os

# scripts/m2wr_tools/paths.py -> the checkout's root (the package is installed editable)
ROOT = os.environ.get("M2WR_ROOT") or os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))


def package_path(name):
    import rospkg
    return rospkg.RosPack().get_path(name)


def world_path(world):
    """The .world file of `world` (world01, world02 or a path), as the simulator finds it;
    ValueError naming the worlds when there is none."""
    from pybullet_gazebo.engine.sdf_world import find_world
    return find_world(world, os.path.join(package_path("my_worlds"), "worlds"))


def model_path():
    """The folders Gazebo-style `model://` URIs are looked up in (GAZEBO_MODEL_PATH and
    pybullet_gazebo's models)."""
    from pybullet_gazebo.engine.sdf_world import model_path_from_env
    return model_path_from_env(os.path.join(package_path("pybullet_gazebo"), "models"))


def robot_urdf():
    """m2wr's URDF (m2wr_description/urdf/m2wr.xacro through xacro), as spawn.launch makes it."""
    import xacro
    return xacro.process_file(os.path.join(package_path("m2wr_description"), "urdf",
                                           "m2wr.xacro")).toxml()
