"""robot_namespace: where a robot's plugin topics and frames go with several robots (gazebo_ros's
rules: <robotNamespace> wins over the spawn's namespace; frames take tf_prefix, found upwards
from the namespace, and the diff drive's fall back to the namespace)."""
import pytest

from pybullet_gazebo.ros.robot_namespace import (plugin_namespace, resolve_frame, search_param,
                                                 tf_prefix, topic_name)


@pytest.mark.parametrize("robot_ns, own, expected", [
    ("/", None, "/"), ("", None, "/"), ("/a/", None, "/a/"), ("a", None, "/a/"),
    ("/a", "/own", "/own/"), ("/a", "own/deep", "/own/deep/"), ("/a", "  ", "/a/"),
    ("/", "", "/"),
])
def test_plugin_namespace(robot_ns, own, expected):
    assert plugin_namespace(robot_ns, own) == expected


def test_relative_topics_go_under_the_namespace_absolute_ones_do_not():
    assert topic_name("/a/", "cmd_vel") == "/a/cmd_vel"
    assert topic_name("/a/", "m2wr/laser/scan") == "/a/m2wr/laser/scan"
    assert topic_name("/a/", "/m2wr/laser/scan") == "/m2wr/laser/scan"
    assert topic_name("/", "odom") == "/odom"


@pytest.mark.parametrize("prefix, frame, expected", [
    ("", "odom", "odom"), ("a", "odom", "a/odom"), ("/a", "odom", "a/odom"),
    ("a/", "link_chassis", "a/link_chassis"), ("a", "/odom", "odom"), ("", "/map", "map"),
])
def test_resolve_frame_as_tf_resolve(prefix, frame, expected):
    assert resolve_frame(prefix, frame) == expected


def fake_params(values):
    return (lambda name: name in values), (lambda name: values[name])


def test_search_param_looks_upwards_from_the_namespace():
    has, get = fake_params({"/a/tf_prefix": "pa", "/tf_prefix": "top"})
    assert search_param("/a/b/", "tf_prefix", has, get) == "pa"
    assert search_param("/c/", "tf_prefix", has, get) == "top"
    has, get = fake_params({})
    assert search_param("/a/", "tf_prefix", has, get) is None


def test_tf_prefix_param_wins_and_the_namespace_is_the_fallback_only_when_asked():
    has, get = fake_params({"/r2/tf_prefix": "second"})
    assert tf_prefix("/r2/", True, has, get) == "second"
    assert tf_prefix("/r1/", True, has, get) == "r1"
    assert tf_prefix("/r1/", False, has, get) == ""
    assert tf_prefix("/", True, has, get) == ""
    has, get = fake_params({"/r3/tf_prefix": ""})          # empty: as if unset
    assert tf_prefix("/r3/", True, has, get) == "r3"
