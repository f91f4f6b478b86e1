"""m2wr_tools.bench.arithmetic: the benchmark's arithmetic and table."""
import math

import pytest

from m2wr_tools.bench import arithmetic


def test_rate_and_growth():
    assert arithmetic.rate(300, 10.0) == 30.0
    assert math.isnan(arithmetic.rate(1, 0.0))
    assert arithmetic.growth_percent(100.0, 103.0) == pytest.approx(3.0)
    assert math.isnan(arithmetic.growth_percent(0, 5))


def test_stamp_rate_uses_the_stamps_own_clock():
    stamps = [0.05 * i for i in range(101)]               # 5 s of sim time at 20 Hz
    assert arithmetic.stamp_rate(stamps + stamps[:3]) == pytest.approx(20.0)   # repeats ignored
    assert math.isnan(arithmetic.stamp_rate([1.0]))


def test_missing_periods_counts_the_holes():
    stamps = [0.05 * i for i in range(20)]
    assert arithmetic.missing_periods(stamps, 0.05) == 0
    holed = [s for i, s in enumerate(stamps) if i not in (5, 6, 12)]
    assert arithmetic.missing_periods(holed, 0.05) == 3


def test_lockstep_verdict():
    assert arithmetic.every_scan_handled(100, 100, 0)
    assert not arithmetic.every_scan_handled(100, 99, 0)
    # the bench missed 2 (a gap in the stamps) that the controller did handle
    assert arithmetic.every_scan_handled(98, 100, 2)
    assert not arithmetic.every_scan_handled(98, 98, 2)
    assert not arithmetic.every_scan_handled(0, 0, 0)
    # a loop program's count may gain or lose one tick at the window's paused edges
    assert arithmetic.every_scan_handled(100, 101, 0, edge=1)
    assert arithmetic.every_scan_handled(100, 99, 0, edge=1)
    assert not arithmetic.every_scan_handled(100, 102, 0, edge=1)
    assert arithmetic.lockstep_verdict(100, 100, 99, 0) == (
        "yes: 100 scans published (100 heard by the bench), 100 handled by the controller, "
        "99 cmd_vel answers")
    assert arithmetic.lockstep_verdict(100, 98, 98, 0).startswith("no:")
    assert arithmetic.lockstep_verdict(0, 0, 0, 0) == "no scans heard"


def test_table_aligns_columns():
    text = arithmetic.table(["a", "long header"], [("row", "1.0", "22.5"), ("other", "10.0", "3")],
                           first_width=8)
    lines = text.splitlines()
    assert len({len(line) for line in lines}) == 1
    assert lines[1].startswith("row     ") and lines[1].endswith("22.5")
    assert arithmetic.fmt(float("nan")) == "n/a" and arithmetic.fmt(None) == "n/a"
    assert arithmetic.fmt(3.14159, "%.2f") == "3.14"
