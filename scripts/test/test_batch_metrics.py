"""m2wr_tools.analysis.metrics: a batch run's figures from recorded data, and the task verdicts."""
import math

import numpy as np
import pytest

from m2wr_tools.analysis import metrics
from m2wr_tools.analysis.metrics import Task


def straight_track(speed=0.5, duration=10.0, rate=20.0):
    t = np.arange(0.0, duration + 1e-9, 1.0 / rate)
    return np.stack([t, speed * t, np.zeros_like(t), np.zeros_like(t)], axis=1)


def test_clip_and_decimate():
    track = straight_track(duration=12.0)
    clipped = metrics.clip_track(track, 10.0)
    assert clipped[0, 0] == 0.0 and clipped[-1, 0] == pytest.approx(10.0)
    sampled = metrics.decimate(clipped, 0.5)
    assert np.allclose(np.diff(sampled[:, 0]), 0.5)
    assert metrics.distance_travelled(sampled[:, 1:3]) == pytest.approx(5.0)


def test_contact_events_and_time_in_contact():
    updates = [(1.0, [("m2wr", "wall")]), (1.5, []), (3.0, [("m2wr", "wall"), ("m2wr", "can")]),
               (3.2, [("m2wr", "can")]), (4.0, []), (12.0, [("m2wr", "wall")])]
    events, seconds = metrics.contact_figures(updates, duration=10.0)
    assert events == 3                    # wall, then wall and can again; 12 s is past the end
    assert seconds == pytest.approx(0.5 + 0.2 + 0.8)
    # still touching at the end: counted to the duration
    assert metrics.contact_figures([(9.0, [("m2wr", "wall")])], 10.0) == (1, pytest.approx(1.0))


def test_stuck_time_counts_rocking_in_place_not_driving():
    moving = straight_track(duration=20.0)
    assert metrics.stuck_time(moving) == 0.0
    t = np.arange(0.0, 20.0 + 1e-9, 0.05)
    # drives 5 s at 0.5 m/s, then rocks +-5 cm about (2.5, 0) for 15 s
    x = np.where(t < 5.0, 0.5 * t, 2.5 + 0.05 * np.sin(3.0 * t))
    track = np.stack([t, x, np.zeros_like(t)], axis=1)
    # stuck once the last 5 s all lie within 0.2 m: 5 s after the robot came within 0.2 m of
    # where it rocks (its last 0.4 s of driving, at 4.6 s), so from 9.6 s to 20 s
    assert metrics.stuck_time(track, window=5.0, radius=0.2) == pytest.approx(10.4, abs=0.15)


def test_time_to_goal():
    track = straight_track(duration=10.0)        # x = 0.5 t
    assert metrics.time_to_goal(track, (3.0, 0.0), 0.3) == pytest.approx(5.4, abs=0.05)
    assert metrics.time_to_goal(track, (3.0, 2.0), 0.3) is None


def test_judge_each_task():
    assert metrics.judge(Task(), 5.0, 0, None, 0.0) == (True, "no contact, 5.00 m travelled")
    ok, reason = metrics.judge(Task(), 5.0, 2, None, 0.0)
    assert not ok and "touched an obstacle (2 contact events)" in reason
    ok, reason = metrics.judge(Task(), 0.2, 0, None, 0.0)
    assert not ok and "travelled 0.20 m" in reason
    goal = Task(kind="goal", goal=(1.0, 2.0))
    assert metrics.judge(goal, 3.0, 0, 7.5, 0.0) == (True, "reached the goal at 7.50 s")
    assert not metrics.judge(goal, 3.0, 0, None, 0.0)[0]
    wall = Task(kind="wall")
    assert metrics.judge(wall, 5.0, 0, None, 0.8)[0]
    assert "near a wall" in metrics.judge(wall, 5.0, 0, None, 0.2)[1]
    assert metrics.fraction_within([0.1, 0.5, 1.0, 2.0], 0.2, 1.5) == 0.5


@pytest.mark.parametrize("kwargs, message", [
    (dict(kind="fly"), "task 'fly' is unknown"),
    (dict(kind="goal"), "needs a goal"),
    (dict(tolerance=0.0), "tolerance > 0"),
])
def test_bad_tasks_are_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Task(**kwargs)


def test_task_round_trip():
    task = Task(kind="goal", goal=(1.5, -2.0), tolerance=0.4)
    assert Task.from_dict(task.as_dict()) == task
    assert not math.isnan(task.tolerance)


def test_distance_travelled_is_the_polyline_length():
    assert metrics.distance_travelled([(0, 0), (3, 4), (3, 4), (3, 0)]) == pytest.approx(9.0)
    assert metrics.distance_travelled([(1, 1)]) == 0.0
    assert metrics.distance_travelled([]) == 0.0
