# Installed by catkin (catkin_python_setup), never by pip directly.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(
    packages=["m2wr_gym"],
    package_dir={"": "src"},
))
