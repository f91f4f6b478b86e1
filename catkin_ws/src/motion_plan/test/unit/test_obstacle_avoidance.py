"""Unit tests of the tutorial's obstacle_avoidance.py (episode 5): the region dictionary built
from a scan, each of the eight cases and the unknown case of take_action (state description,
log lines, published Twist), and the node's wiring. No ROS master: a fake publisher stands in
for the module's global `pub`.
"""
import pytest
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

NEAR = 0.5  # [m] below the tutorial's 1 m threshold
FAR = 2.0   # [m] above it

# (front, fleft, fright) -> the tutorial's (state_description, linear_x, angular_z)
CASES = [
    ((FAR, FAR, FAR), "case 1 - nothing", 0.6, 0),
    ((NEAR, FAR, FAR), "case 2 - front", 0, -0.3),
    ((FAR, FAR, NEAR), "case 3 - fright", 0, -0.3),
    ((FAR, NEAR, FAR), "case 4 - fleft", 0, 0.3),
    ((NEAR, FAR, NEAR), "case 5 - front and fright", 0, -0.3),
    ((NEAR, NEAR, FAR), "case 6 - front and fleft", 0, 0.3),
    ((NEAR, NEAR, NEAR), "case 7 - front and fleft and fright", 0, -0.3),
    ((FAR, NEAR, NEAR), "case 8 - fleft and fright", 0, -0.3),
]


class FakePublisher:
    def __init__(self):
        self.published = []

    def publish(self, msg):
        self.published.append(msg)


@pytest.fixture
def node(load_script, monkeypatch):
    """The script as a fresh module with a fake publisher in its global `pub`."""
    module = load_script("obstacle_avoidance.py")
    monkeypatch.setattr(module, "pub", FakePublisher())
    return module


def regions_for(front, fleft, fright):
    # right and left are near on purpose: take_action ignores them, as the tutorial says.
    return {"right": 0.2, "fright": fright, "front": front, "fleft": fleft, "left": 0.2}


def assert_twist(msg, linear_x, angular_z):
    assert isinstance(msg, Twist)
    assert (msg.linear.x, msg.linear.y, msg.linear.z) == (linear_x, 0, 0)
    assert (msg.angular.x, msg.angular.y, msg.angular.z) == (0, 0, angular_z)


def refuse(*args, **kwargs):
    raise AssertionError("the script touched ROS at import time")


def test_import_has_no_side_effects(monkeypatch, load_script):
    for name in ("init_node", "Subscriber", "Publisher", "spin"):
        monkeypatch.setattr(rospy, name, refuse)
    module = load_script("obstacle_avoidance.py")
    assert module.pub is None


def test_main_uses_the_tutorials_node_name_and_topics(monkeypatch, load_script):
    module = load_script("obstacle_avoidance.py")
    calls = []
    publisher = FakePublisher()

    def make_publisher(*args, **kwargs):
        calls.append(("Publisher", args, kwargs))
        return publisher

    monkeypatch.setattr(rospy, "init_node", lambda *a, **k: calls.append(("init_node", a, k)))
    monkeypatch.setattr(rospy, "Publisher", make_publisher)
    monkeypatch.setattr(rospy, "Subscriber", lambda *a, **k: calls.append(("Subscriber", a, k)))
    monkeypatch.setattr(rospy, "spin", lambda: calls.append(("spin", (), {})))
    module.main()
    assert calls == [
        ("init_node", ("reading_laser",), {}),  # sic: the tutorial reuses episode 4's name
        ("Publisher", ("/cmd_vel", Twist), {"queue_size": 1}),
        ("Subscriber", ("/m2wr/laser/scan", LaserScan, module.clbk_laser), {}),
        ("spin", (), {}),
    ]
    assert module.pub is publisher


@pytest.mark.parametrize("near_far, description, linear_x, angular_z", CASES,
                         ids=[case[1] for case in CASES])
def test_each_case_logs_and_publishes_the_tutorials_command(
        node, logged, near_far, description, linear_x, angular_z):
    node.take_action(regions_for(*near_far))
    assert logged == [description]
    assert len(node.pub.published) == 1
    assert_twist(node.pub.published[0], linear_x, angular_z)


@pytest.mark.parametrize("exactly_one", ["front", "fleft", "fright"])
def test_a_region_at_exactly_1_m_is_the_unknown_case(node, logged, exactly_one):
    regions = regions_for(FAR, FAR, FAR)
    regions[exactly_one] = 1
    node.take_action(regions)
    assert logged == [regions, "unknown case"]  # the regions first, then the description
    assert len(node.pub.published) == 1
    assert_twist(node.pub.published[0], 0, 0)


def test_clbk_laser_builds_the_region_dict_and_calls_take_action(node, monkeypatch, make_scan):
    received = []
    monkeypatch.setattr(node, "take_action", received.append)
    scan = make_scan({50: 3.5, 143: 0.1, 200: 2.25, 300: 0.75, 500: 1.5, 712: 6.0})
    node.clbk_laser(scan)
    # beam 143 is skipped by the tutorial's slices: right is 3.5, not 0.1
    assert received == [{"right": 3.5, "fright": 2.25, "front": 0.75, "fleft": 1.5, "left": 6.0}]


def test_open_space_gives_integer_10_regions_and_drives_ahead(node, monkeypatch, make_scan, logged):
    received = []
    real_take_action = node.take_action
    monkeypatch.setattr(node, "take_action",
                        lambda regions: (received.append(regions), real_take_action(regions)))
    node.clbk_laser(make_scan())
    assert received == [dict.fromkeys(["right", "fright", "front", "fleft", "left"], 10)]
    assert all(type(value) is int for value in received[0].values())
    assert logged == ["case 1 - nothing"]
    assert_twist(node.pub.published[0], 0.6, 0)


def test_an_obstacle_ahead_stops_and_turns_with_negative_angular_z(node, logged, make_scan):
    node.clbk_laser(make_scan({360: 0.8}))  # straight ahead: beam 360 is at +0.125 deg
    assert logged == ["case 2 - front"]
    assert_twist(node.pub.published[0], 0, -0.3)
