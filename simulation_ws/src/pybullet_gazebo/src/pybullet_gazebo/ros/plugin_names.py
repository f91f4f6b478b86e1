"""The ROS names a robot part's Gazebo plugin gives in its parameters (the <plugin>'s tags as
written, `Part.plugin_params`), with the defaults of ROS Noetic's gazebo_ros plugins. The
ROS adapter reads them (bindings.py); the engine never does.

  libgazebo_ros_diff_drive.so   commandTopic (cmd_vel), odometryTopic (odom), odometryFrame
                                (odom), robotBaseFrame (base_footprint)
  libgazebo_ros_laser.so        topicName (/world), frameName (the sensor's link; a leading
                                "/" is dropped, as tf does)
  either                        robotNamespace: its text, None when absent (the spawn's
                                namespace is used then: robot_namespace.plugin_namespace)
"""
from typing import Mapping, NamedTuple, Optional

from pybullet_gazebo.engine.parameters import ParameterReader


class DriveNames(NamedTuple):
    command_topic: str
    odometry_topic: str
    odometry_frame: str
    robot_base_frame: str


class LaserNames(NamedTuple):
    topic: str
    frame: str


def own_namespace(params: Mapping[str, str]) -> Optional[str]:
    return ParameterReader(params, "plugin").text("robotNamespace", None)


def drive_names(params: Mapping[str, str]) -> DriveNames:
    text = ParameterReader(params, "diff drive plugin").text
    return DriveNames(text("commandTopic", "cmd_vel"), text("odometryTopic", "odom"),
                      text("odometryFrame", "odom"), text("robotBaseFrame", "base_footprint"))


def laser_names(params: Mapping[str, str], link: str) -> LaserNames:
    text = ParameterReader(params, "laser plugin").text
    return LaserNames(text("topicName", "/world"), text("frameName", link).lstrip("/"))
