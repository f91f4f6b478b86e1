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


class DriveNames(NamedTuple):
    command_topic: str
    odometry_topic: str
    odometry_frame: str
    robot_base_frame: str


class LaserNames(NamedTuple):
    topic: str
    frame: str


def _text(params, tag, default):
    raw = params.get(tag)
    return default if raw is None else str(raw).strip()


def own_namespace(params: Mapping[str, str]) -> Optional[str]:
    raw = params.get("robotNamespace")
    return raw.strip() if raw is not None else None


def drive_names(params: Mapping[str, str]) -> DriveNames:
    return DriveNames(_text(params, "commandTopic", "cmd_vel"),
                      _text(params, "odometryTopic", "odom"),
                      _text(params, "odometryFrame", "odom"),
                      _text(params, "robotBaseFrame", "base_footprint"))


def laser_names(params: Mapping[str, str], link: str) -> LaserNames:
    return LaserNames(_text(params, "topicName", "/world"),
                      _text(params, "frameName", link).lstrip("/"))
