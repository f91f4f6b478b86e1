"""Unit tests of the tutorial's reading_laser.py (episode 4): the five regions it logs for
synthetic 720-beam scans, including the quirks kept from the tutorial (skipped beams, the
integer 10 for open regions, min over NaN). No ROS master: clbk_laser is called directly.
"""
import math

import pytest
import rospy
from sensor_msgs.msg import LaserScan

# The tutorial's slices, region by region (right to left), as index ranges.
SLICES = [range(0, 143), range(144, 287), range(288, 431), range(432, 575), range(576, 713)]
SKIPPED_BEAMS = [143, 287, 431, 575] + list(range(713, 720))


@pytest.fixture
def reading_laser(load_script):
    return load_script("reading_laser.py")


def refuse(*args, **kwargs):
    raise AssertionError("the script touched ROS at import time")


def test_import_has_no_side_effects(monkeypatch, load_script):
    for name in ("init_node", "Subscriber", "Publisher", "spin"):
        monkeypatch.setattr(rospy, name, refuse)
    module = load_script("reading_laser.py")
    assert callable(module.clbk_laser) and callable(module.main)


def test_main_uses_the_tutorials_node_name_and_topic(monkeypatch, reading_laser):
    calls = []
    monkeypatch.setattr(rospy, "init_node", lambda *a, **k: calls.append(("init_node", a, k)))
    monkeypatch.setattr(rospy, "Subscriber", lambda *a, **k: calls.append(("Subscriber", a, k)))
    monkeypatch.setattr(rospy, "spin", lambda: calls.append(("spin", (), {})))
    reading_laser.main()
    assert calls == [
        ("init_node", ("reading_laser",), {}),
        ("Subscriber", ("/m2wr/laser/scan", LaserScan, reading_laser.clbk_laser), {}),
        ("spin", (), {}),
    ]


def test_open_space_logs_the_integer_10_in_every_region(reading_laser, logged, make_scan):
    reading_laser.clbk_laser(make_scan())
    assert len(logged) == 1
    assert logged[0] == [10, 10, 10, 10, 10]
    assert all(type(region) is int for region in logged[0])
    assert str(logged[0]) == "[10, 10, 10, 10, 10]"  # the line a user sees


def test_each_region_is_the_true_minimum_of_its_slice(reading_laser, logged, make_scan):
    scan = make_scan({
        0: 3.0, 50: 2.5, 142: 2.75,      # right: first and last beam of 0:143 included
        144: 1.25, 200: 1.5,             # fright
        288: 0.9, 430: 0.5,              # front: 430 is the last beam of 288:431
        432: 4.0, 574: 4.5,              # fleft
        576: 9.75, 712: 9.5,             # left: 712 is the last beam of 576:713
    })
    reading_laser.clbk_laser(scan)
    assert logged == [[2.5, 1.25, 0.5, 4.0, 9.5]]


def test_a_finite_range_beyond_10_is_capped_at_the_integer_10(reading_laser, logged, make_scan):
    reading_laser.clbk_laser(make_scan({300: 12.0}))
    assert logged == [[10, 10, 10, 10, 10]]
    assert type(logged[0][2]) is int


@pytest.mark.parametrize("region, beams", enumerate(SLICES))
def test_first_and_last_beam_of_each_slice_count(reading_laser, logged, make_scan, region, beams):
    for beam in (beams[0], beams[-1]):
        logged.clear()
        reading_laser.clbk_laser(make_scan({beam: 0.3}))
        expected = [10] * 5
        expected[region] = 0.3
        assert logged == [expected], f"beam {beam}"


@pytest.mark.parametrize("beam", SKIPPED_BEAMS)
def test_the_skipped_beams_are_ignored(reading_laser, logged, make_scan, beam):
    reading_laser.clbk_laser(make_scan({beam: 0.2}))
    assert logged == [[10, 10, 10, 10, 10]]


def test_min_over_nan_depends_on_where_the_nan_is(reading_laser, logged, make_scan):
    # Python's min() keeps its first item when every comparison with it is False.
    ranges = [1.0] * 720
    ranges[0] = math.nan            # first beam of the right region
    ranges[150] = math.nan          # inside the fright region
    reading_laser.clbk_laser(LaserScan(ranges=ranges))
    right, fright, front, fleft, left = logged[0]
    assert math.isnan(right)
    assert fright == 1.0 and front == 1.0 and fleft == 1.0 and left == 1.0
