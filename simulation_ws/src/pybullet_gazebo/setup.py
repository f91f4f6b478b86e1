# Installed by catkin (catkin_python_setup), never by pip directly.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(
    packages=["pybullet_gazebo", "pybullet_gazebo.engine", "pybullet_gazebo.ros",
              "pybullet_gazebo.ros.lockstep"],
    package_dir={"": "src"},
))
