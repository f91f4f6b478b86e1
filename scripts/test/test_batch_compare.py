"""The comparison table of two controllers' batches: figures from the runs, and a refusal
to compare batches of different scenarios."""
import pytest

from m2wr_tools.batch import compare, results


def run(run_id, x, distance, contacts=0, clearance=0.5, stuck=0.0, world="world02"):
    return {"run_id": run_id, "world": world, "x": x, "y": 8.0, "yaw": 0.0, "seed": 0,
            "scenario": {"duration": 120.0}, "distance_m": distance, "contact_events": contacts,
            "min_clearance_m": clearance, "time_stuck_s": stuck}


def write(folder, runs):
    folder.mkdir()
    results.write(str(folder), runs, {"controller": "x"})
    return str(folder)


def test_figures_per_controller(tmp_path):
    a = write(tmp_path / "a", [run("r1", 0.0, 50.0), run("r2", 1.0, 60.0, contacts=2,
                                                                  clearance=0.0, stuck=4.0),
                               run("r3", 2.0, 70.0, clearance=0.3)])
    b = write(tmp_path / "b", [run("r1", 0.0, 10.0), run("r2", 1.0, 20.0),
                               dict(run("r3", 2.0, None), distance_m=None, reason="crashed")])
    lines = compare.table([("learned", a), ("tutorial", b)])
    assert lines[2] == "| learned | 2/3 (67 %) | 60.0 | 60.0 | 0.30 | 0.00 | 0.0 | 0 |"
    assert lines[3] == "| tutorial | 2/3 (67 %) | 15.0 | 15.0 | 0.50 | 0.50 | 0.0 | 1 |"


def test_batches_of_different_starts_are_refused(tmp_path):
    a = write(tmp_path / "a", [run("r1", 0.0, 50.0)])
    b = write(tmp_path / "b", [run("r1", 3.0, 50.0)])
    with pytest.raises(ValueError, match="other scenarios"):
        compare.table([("a", a), ("b", b)])
    with pytest.raises(ValueError, match="no results.json"):
        compare.table([("a", a), ("missing", str(tmp_path / "nowhere"))])
    assert compare.main(["a=" + a, "b=" + b]) == 2
