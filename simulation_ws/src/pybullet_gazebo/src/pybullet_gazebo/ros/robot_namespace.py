"""Where a robot's plugin topics and TF frames go, as gazebo_ros puts them for several robots.

- Topics: a plugin's own <robotNamespace> element wins when present and not empty; otherwise
  the spawn request's robot_namespace (spawn_model's -robot_namespace, by default the
  spawner's own namespace) is used, as gazebo_ros's spawn service fills the element in.
  Relative topic names (cmd_vel, odom) go under it; absolute ones (/m2wr/laser/scan) do not.
- Frames: the parameter `tf_prefix`, searched upwards from the plugin's namespace as
  roscpp's NodeHandle::searchParam does. The diff drive's odometryFrame and robotBaseFrame
  fall back to the namespace itself when no tf_prefix is set, so that two robots' odometry
  and TF never share frame names (the project's choice: Noetic's gazebo_ros_diff_drive uses
  tf_prefix only, and two robots without one publish the same `odom -> base` frames). The
  laser's frameName takes tf_prefix only, as gazebo_ros_laser does.
  A prefix is applied as tf::resolve applies it: a frame starting with '/' is taken as
  absolute (the slash dropped); otherwise `prefix/frame`, with the prefix's leading slash
  dropped.

Parameters read (once per robot, at spawn): `tf_prefix` in the plugin's namespace or any
namespace above it (a string; empty = none).
"""
import rospy

GLOBAL = "/"


def plugin_namespace(robot_namespace, own_namespace):
    """The namespace of a plugin's topics, always absolute ("/" at the top level).
    `own_namespace`: the plugin's <robotNamespace> text, None when absent."""
    chosen = own_namespace.strip() if own_namespace and own_namespace.strip() else robot_namespace
    chosen = (chosen or "").strip().strip("/")
    return "/" + chosen + "/" if chosen else GLOBAL


def topic_name(namespace, topic):
    """`topic` under `namespace` unless it is absolute."""
    topic = topic.strip()
    if topic.startswith("/"):
        return topic
    return namespace.rstrip("/") + "/" + topic


def resolve_frame(prefix, frame):
    """tf::resolve(prefix, frame): '/odom' -> 'odom'; ('a', 'odom') -> 'a/odom'."""
    frame = frame.strip()
    if frame.startswith("/"):
        return frame.lstrip("/")
    prefix = (prefix or "").strip().strip("/")
    return prefix + "/" + frame if prefix else frame


def search_param(namespace, key, has_param, get_param):
    """The value of `key` in `namespace` or the nearest namespace above it, None if none
    (NodeHandle::searchParam). has_param/get_param take absolute names."""
    parts = [part for part in namespace.strip("/").split("/") if part]
    for depth in range(len(parts), -1, -1):
        name = "/" + "/".join(parts[:depth] + [key])
        if has_param(name):
            return get_param(name)
    return None


def tf_prefix(namespace, fall_back_to_namespace,
              has_param=rospy.has_param, get_param=rospy.get_param):
    """The prefix for a plugin's frames in `namespace` (see the module's docstring)."""
    found = search_param(namespace, "tf_prefix", has_param, get_param)
    prefix = str(found).strip() if found is not None else ""
    if not prefix and fall_back_to_namespace:
        prefix = namespace
    return prefix.strip("/")
