"""m2wr_tools.batch.results: results.json/results.csv round trip, the deterministic view, the
summary table."""
import csv
import json

from m2wr_tools.batch import results


def record(run_id, success, distance, reason="no contact", world="world02"):
    return {"run_id": run_id, "world": world, "x": 0.0, "y": 8.0, "yaw": 0.0, "seed": 0,
            "task": "wander", "success": success, "reason": reason, "distance_m": distance,
            "min_clearance_m": 0.4, "contact_events": 0 if success else 2,
            "time_in_contact_s": 0.0 if success else 0.3, "time_stuck_s": 1.0,
            "wall_time_s": 3.2, "real_time_factor": 18.0, "worker": "host:1", "reused": True,
            "path": [[0.0, 0.0, 8.0], [0.5, 0.3, 8.0]], "controller_exit": "exit 0"}


def test_write_then_load(tmp_path):
    runs = [record("b", True, 10.0), record("a", False, 3.0, "touched an obstacle (2 contact events)")]
    results.write(str(tmp_path), runs, {"runs": 2})
    loaded = results.load(str(tmp_path))
    assert sorted(loaded) == ["a", "b"] and loaded["b"]["distance_m"] == 10.0
    with open(tmp_path / "results.csv") as source:
        rows = list(csv.DictReader(source))
    assert [r["run_id"] for r in rows] == ["a", "b"]
    assert json.loads(rows[1]["path"]) == [[0.0, 0.0, 8.0], [0.5, 0.3, 8.0]]
    assert rows[0]["success"] == "False" and rows[1]["distance_m"] == "10"
    assert results.load(str(tmp_path / "nothing")) == {}


def test_deterministic_view_drops_machine_fields():
    view = results.deterministic_view(record("a", True, 1.0))
    assert "wall_time_s" not in view and "worker" not in view and "real_time_factor" not in view
    assert view["distance_m"] == 1.0 and view["path"]


def test_summary_table():
    runs = [record("a", True, 10.0), record("b", True, 12.0),
            record("c", False, 3.0, "touched an obstacle (2 contact events)", world="world01"),
            record("d", False, 4.0, "touched an obstacle (1 contact events)", world="world01")]
    text = results.summary_table(runs, title="obstacle_avoidance.py")
    lines = text.splitlines()
    assert lines[0] == "obstacle_avoidance.py"
    assert lines[1] == "runs 4, success 2 (50 %), failed 2"
    assert "  world world01        0/2   succeeded (0 %)" in lines
    assert "  failed:   2 x touched an obstacle" in lines
    assert any(l.startswith("  distance") and "median 7.00" in l for l in lines)
    assert results.summary_table([]) == "no runs"
