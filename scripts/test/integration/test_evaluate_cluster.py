"""scripts/evaluate.sh on a real Dask cluster (`dask scheduler` and two `dask worker`
processes on 127.0.0.1) and on the embedded LocalCluster: a 6-run batch of the tutorial's
obstacle_avoidance.py in world02 (random free starts, 20 s of sim time each, lockstep)
gives every run, sane metrics, and the same metrics on both clusters, whichever worker ran
which run in which order."""
import math
import os

from m2wr_tools import results
from m2wr_tools.scene import SCAN_HEIGHT, Scene
from m2wr_tools.scenarios import FREE_MARGIN, obstacle_distance

RUNS = 6
DURATION = 20.0              # [s] sim
ARGS = ["--random", str(RUNS), "--pose-seed", "3"]


def check_sane(data, outlines):
    runs = data["runs"]
    assert len(runs) == RUNS and len({r["run_id"] for r in runs}) == RUNS
    for r in runs:
        assert "reason" in r and r["reason"], r
        assert r["sim_time_s"] >= DURATION - 0.1, r["reason"]
        assert r["cmd_vel_messages"] > 0
        # the start is free and the path starts there
        assert obstacle_distance(outlines, r["x"], r["y"]) >= FREE_MARGIN - 1e-6
        t0, x0, y0 = r["path"][0]
        assert t0 < 0.1 and math.hypot(x0 - r["x"], y0 - r["y"]) < 0.05
        # it drove (0.6 m/s at most), and never left world02's walls
        assert 0.5 < r["distance_m"] <= 0.6 * DURATION * 1.05
        for _, x, y in r["path"]:
            assert -10.0 < x < 10.0 and -10.0 < y < 10.0
        assert -0.05 <= r["min_clearance_m"] <= obstacle_distance(outlines, r["x"], r["y"]) + 0.05
        assert (r["contact_events"] == 0) == (r["time_in_contact_s"] == 0.0)
        assert 0.0 <= r["time_stuck_s"] <= DURATION
        assert r["success"] == (r["contact_events"] == 0 and r["distance_m"] >= 1.0)
        assert os.path.exists(r["controller_log"])
        assert r["controller_exit"] is not None
        assert r["wall_time_s"] > 0 and r["real_time_factor"] > 0


def test_same_batch_on_dask_workers_and_local_cluster(tmp_path, dask_cluster, run_evaluate,
                                                      no_process_left):
    scene = Scene.of_world("world02")
    try:
        outlines = scene.outlines(SCAN_HEIGHT)
    finally:
        scene.close()
    status, text, remote = run_evaluate(ARGS + ["--scheduler", dask_cluster.address],
                                        tmp_path / "remote")
    assert status == 0, text
    check_sane(remote, outlines)
    assert len({r["worker"] for r in remote["runs"]}) == 2, "both workers should have run"
    assert "runs 6, success" in text
    assert os.path.exists(tmp_path / "remote" / "trajectories_world02.png")
    assert os.path.exists(tmp_path / "remote" / "results.csv")
    dask_cluster.stop()
    no_process_left(remote)

    status, text, local = run_evaluate(ARGS + ["--workers", "2"], tmp_path / "local")
    assert status == 0, text
    check_sane(local, outlines)
    no_process_left(local)
    by_id = {r["run_id"]: results.deterministic_view(r) for r in local["runs"]}
    for r in remote["runs"]:
        assert results.deterministic_view(r) == by_id[r["run_id"]], r["run_id"]
