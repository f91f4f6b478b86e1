"""m2wr_tools.batch.scenarios: combinations, stable run ids, and start poses in free space
(fixture outlines: a 10 m x 10 m square of walls with a round pillar in the middle)."""
import math

import pytest

from m2wr_tools.analysis.metrics import Task
from m2wr_tools.analysis.scene import Outline
from m2wr_tools.batch.scenarios import (Scenario, check_starts, combinations, grid_starts,
                                  is_free, obstacle_distance, random_starts)


def wall(x0, y0, x1, y1):
    return Outline("wall", "polygon", points=((x0, y0), (x1, y0), (x1, y1), (x0, y1)))


OUTLINES = [wall(-5.2, -5.2, 5.2, -5.0), wall(-5.2, 5.0, 5.2, 5.2), wall(-5.2, -5.0, -5.0, 5.0),
            wall(5.0, -5.0, 5.2, 5.0), Outline("pillar", "circle", center=(0.0, 0.0), radius=1.0)]


def test_obstacle_distance():
    assert obstacle_distance(OUTLINES, 3.0, 0.0) == pytest.approx(2.0)     # pillar and east wall
    assert obstacle_distance(OUTLINES, 0.0, 0.5) == 0.0                    # inside the pillar
    assert obstacle_distance(OUTLINES, 0.0, 4.0) == pytest.approx(1.0)     # north wall
    assert obstacle_distance(OUTLINES, 5.1, 0.0) == 0.0                    # inside a wall
    assert not is_free(OUTLINES, 0.0, 1.3) and is_free(OUTLINES, 0.0, 2.0)
    assert not is_free(OUTLINES, 8.0, 0.0)                                 # outside the world


def test_grid_starts_are_free_and_on_the_grid():
    starts = grid_starts(OUTLINES, 1.0)
    assert (2.0, 2.0, 0.0) in starts and (0.0, 0.0, 0.0) not in starts
    assert (4.0, 0.0, 0.0) in starts and (5.0, 0.0, 0.0) not in starts
    assert all(obstacle_distance(OUTLINES, x, y) >= 0.6 for x, y, _ in starts)
    # 9 x 9 points inside the walls (1 m from them at +-4), less the pillar's 3 x 3 (within
    # 1.6 m of its centre; (2, 0) is 1 m from its surface and free)
    assert len(starts) == 81 - 9


def test_random_starts_are_free_and_repeatable():
    a = random_starts(OUTLINES, 25, seed=4)
    assert a == random_starts(OUTLINES, 25, seed=4)
    assert a != random_starts(OUTLINES, 25, seed=5)
    assert len(set(a)) == 25
    for x, y, yaw in a:
        assert is_free(OUTLINES, x, y) and -math.pi <= yaw < math.pi
    with pytest.raises(ValueError, match="found only"):
        random_starts(OUTLINES, 5, seed=0, margin=6.0)


def test_check_starts_names_the_bad_one():
    check_starts(OUTLINES, [(2.0, 2.0, 0.0)])
    with pytest.raises(ValueError, match=r"start \(0\.5, 0\) is not free: 0\.00 m"):
        check_starts(OUTLINES, [(2.0, 2.0, 0.0), (0.5, 0.0, 1.0)])


def test_combinations_and_ids():
    runs = combinations(["world02", "world01"], lambda w: [(0, 8, 0), (1, 2, 3)], [0, 7], 60,
                        ("rosrun", "motion_plan", "obstacle_avoidance.py"), Task())
    assert len(runs) == 8
    assert [(r.world, r.seed) for r in runs[:4]] == [("world02", 0)] * 2 + [("world02", 7)] * 2
    assert len({r.run_id for r in runs}) == 8
    first = runs[0]
    assert first.run_id.startswith("world02_x+0.00_y+8.00_yaw+0.00_s0_")
    assert Scenario.from_dict(first.as_dict()) == first
    assert Scenario.from_dict(first.as_dict()).run_id == first.run_id
    longer = Scenario(**{**first.__dict__, "duration": 120.0})
    assert longer.run_id != first.run_id
