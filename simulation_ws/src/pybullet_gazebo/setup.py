# Installed by catkin (catkin_python_setup), never by pip directly.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(
    packages=["pybullet_gazebo", "pybullet_gazebo.engine", "pybullet_gazebo.gui",
              "pybullet_gazebo.ros", "pybullet_gazebo.ros.lockstep", "pybullet_gazebo.web"],
    package_dir={"": "src"},
    package_data={"pybullet_gazebo.web": ["static/*"]},
))
