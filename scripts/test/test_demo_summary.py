"""m2wr_tools.analysis.summary: the run summary's maths and text."""
import math

import pytest

from m2wr_tools.analysis import summary
from m2wr_tools.analysis.summary import Collision, RunSummary


def test_case_lines_are_recognised():
    assert summary.is_case("case 1 - nothing")
    assert summary.is_case("case 7 - front and fleft and fright")
    assert summary.is_case("unknown case")
    assert not summary.is_case("{'right': 10, 'fright': 0.8}")
    assert not summary.is_case("spawned 'm2wr'")


def test_each_case_lasts_until_the_next_line_and_the_last_until_the_end():
    events = [(1.0, "case 1 - nothing"), (1.05, "case 1 - nothing"), (3.0, "case 2 - front"),
              (3.5, "{'front': 0.9}"), (4.0, "case 1 - nothing")]
    assert summary.case_durations(events, start=0.0, end=10.0) == pytest.approx(
        {"case 1 - nothing": 2.0 + 6.0, "case 2 - front": 1.0})


def test_case_durations_are_clipped_to_the_run_and_sorted_by_case_number():
    events = [(12.0, "case 8 - fleft and fright"), (-1.0, "case 10 - made up"),
              (5.0, "unknown case"), (2.0, "case 2 - front")]
    result = summary.case_durations(events, start=0.0, end=10.0)
    assert list(result) == ["case 2 - front", "case 10 - made up", "unknown case"]
    assert result["case 10 - made up"] == pytest.approx(2.0)     # from -1, clipped at 0
    assert result["case 2 - front"] == pytest.approx(3.0)
    assert result["unknown case"] == pytest.approx(5.0)
    assert "case 8 - fleft and fright" not in result          # after the end


def test_case_order_is_numeric_not_alphabetical():
    events = [(0.0, "case 10 - x"), (1.0, "case 2 - front"), (2.0, "unknown case")]
    assert list(summary.case_durations(events, 0.0, 3.0)) == ["case 2 - front", "case 10 - x",
                                                            "unknown case"]


def test_collisions_count_onsets_not_contact_messages():
    updates = [(1.0, [("m2wr", "wall")]), (1.1, [("m2wr", "wall"), ("m2wr", "barrel")]),
               (1.5, []), (2.0, [("m2wr", "wall")])]
    onsets = summary.collision_onsets(updates)
    assert onsets == [Collision(1.0, "m2wr", "wall"), Collision(1.1, "m2wr", "barrel"),
                      Collision(2.0, "m2wr", "wall")]
    assert summary.collision_onsets([]) == []


def test_real_time_factor():
    assert summary.real_time_factor(120.0, 4.0) == pytest.approx(30.0)
    assert summary.real_time_factor(0.0, 4.0) == 0.0
    assert summary.real_time_factor(1.0, 0.0) == math.inf


def test_progress_line():
    line = summary.progress_line(30.0, 120.0, 9.87, "case 1 - nothing")
    assert line == "sim   30.0 / 120 s ( 25%)    9.9x real time  case 1 - nothing"
    assert summary.progress_line(0.0, 120.0, 0.0, "").endswith("(no case yet)")


def test_summary_text_and_dict():
    run = RunSummary(world="world02", start=(0.0, 8.0, math.pi / 2), sim_time=120.0,
                     wall_time=4.0, distance=25.5, min_clearance=0.4321,
                     min_clearance_model="jersey_barrier_3", min_clearance_time=45.1,
                     collisions=[Collision(50.0, "m2wr", "construction_barrel")],
                     cases={"case 1 - nothing": 90.0, "case 2 - front": 30.0},
                     picture="/out/demo_world02.png")
    text = run.text()
    assert "start (0.00, 8.00) m, yaw 90.0 deg" in text
    assert "real-time factor      30.0 x" in text
    assert "min clearance        0.432 m  (jersey_barrier_3, at 45.10 s)" in text
    assert "collisions               1" in text
    assert "m2wr touched construction_barrel" in text
    assert "75.0 %" in text and "25.0 %" in text
    data = run.as_dict()
    assert data["real_time_factor"] == pytest.approx(30.0)
    assert data["collisions"] == [{"sim_time_s": 50.0, "robot": "m2wr",
                                   "model": "construction_barrel"}]
    assert "n/a" in RunSummary("w", (0, 0, 0), 1.0, 1.0, 0.0).text()
