"""Our gazebo_msgs must be wire-compatible with ROS Noetic's: a client built against Gazebo's
gazebo_msgs only talks to a topic or service whose md5sum matches. noetic_md5sums.txt holds
the md5sum of every message and service of Noetic's gazebo_msgs (computed once with genmsg
from gazebo_ros_pkgs' noetic-devel definitions); every type must be here and match."""
import importlib
import os

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.dirname(os.path.dirname(HERE))


def noetic_md5sums():
    table = {}
    with open(os.path.join(HERE, "noetic_md5sums.txt")) as source:
        for line in source:
            if line.strip() and not line.startswith("#"):
                kind, md5sum = line.split()
                table[kind] = md5sum
    return table


NOETIC = noetic_md5sums()


def test_the_table_lists_every_type_of_noetic_gazebo_msgs():
    assert len(NOETIC) == 34          # 11 messages, 23 services
    assert sum(k.startswith("msg/") for k in NOETIC) == 11


def test_the_package_defines_exactly_noetic_types():
    ours = {"%s/%s" % (folder, name.rsplit(".", 1)[0])
            for folder in ("msg", "srv") for name in os.listdir(os.path.join(PACKAGE, folder))}
    assert ours == set(NOETIC)


@pytest.mark.parametrize("kind", sorted(NOETIC))
def test_md5sum_matches_noetic(kind):
    folder, name = kind.split("/")
    module = importlib.import_module("gazebo_msgs.%s" % folder)
    generated = getattr(module, name)
    assert generated._md5sum == NOETIC[kind]
    assert generated._type == "gazebo_msgs/" + name
