"""Fixtures for the unit tests of motion_plan's scripts (pytest, no ROS master).

The scripts live in ../../scripts and are not a Python package: they are loaded by path
through m2wr_tools.tutorial_scripts (found with rospkg, as rosrun finds them), a fresh
module object per test (obstacle_avoidance keeps its publisher in a module global).
`rospy.loginfo` is replaced to capture what the scripts log.
"""
import math

import pytest
import rospy
from m2wr_tools import tutorial_scripts
from sensor_msgs.msg import LaserScan

BEAMS = 720  # m2wr's laser: 720 samples from -90 to +90 deg, index 0 on the right


@pytest.fixture
def load_script():
    """Returns load(file_name): the script executed as a fresh module, not registered in
    sys.modules, and without running its main()."""
    return tutorial_scripts.load


@pytest.fixture
def logged(monkeypatch):
    """The objects passed to rospy.loginfo, in call order."""
    lines = []
    monkeypatch.setattr(rospy, "loginfo", lambda msg, *args, **kwargs: lines.append(msg))
    return lines


@pytest.fixture
def make_scan():
    """Returns scan(close={index: range}): a 720-beam LaserScan, +inf (no return, REP 117)
    everywhere except the given beams."""
    def scan(close=None):
        ranges = [math.inf] * BEAMS
        for index, value in (close or {}).items():
            ranges[index] = value
        return LaserScan(angle_min=-1.570796, angle_max=1.570796,
                         angle_increment=2 * 1.570796 / (BEAMS - 1),
                         range_min=0.10, range_max=10.0, ranges=ranges)
    return scan
