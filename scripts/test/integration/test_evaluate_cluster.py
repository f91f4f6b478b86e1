"""scripts/evaluate.sh on a real Dask cluster (`dask scheduler` and two `dask worker`
processes on 127.0.0.1) and on the embedded LocalCluster: a 6-run batch of the tutorial's
obstacle_avoidance.py in world02 (random free starts, 20 s of sim time each, lockstep)
gives every run, sane metrics, and the same metrics on both clusters, whichever worker ran
which run in which order."""
import os

from m2wr_tools.batch import results
from m2wr_tools.analysis.scene import SCAN_HEIGHT, Scene

RUNS = 6
ARGS = ["--random", str(RUNS), "--pose-seed", "3"]


def test_same_batch_on_dask_workers_and_local_cluster(tmp_path, dask_cluster, run_evaluate,
                                                      no_process_left, batch_kit):
    scene = Scene.of_world("world02")
    try:
        outlines = scene.outlines(SCAN_HEIGHT)
    finally:
        scene.close()
    status, text, remote = run_evaluate(ARGS + ["--scheduler", dask_cluster.address],
                                        tmp_path / "remote")
    assert status == 0, text
    batch_kit.check_sane(remote, outlines, RUNS)
    assert len({r["worker"] for r in remote["runs"]}) == 2, "both workers should have run"
    assert "runs 6, success" in text
    assert os.path.exists(tmp_path / "remote" / "trajectories_world02.png")
    assert os.path.exists(tmp_path / "remote" / "results.csv")
    dask_cluster.stop()
    no_process_left(remote)

    status, text, local = run_evaluate(ARGS + ["--workers", "2"], tmp_path / "local")
    assert status == 0, text
    batch_kit.check_sane(local, outlines, RUNS)
    no_process_left(local)
    by_id = {r["run_id"]: results.deterministic_view(r) for r in local["runs"]}
    for r in remote["runs"]:
        assert results.deterministic_view(r) == by_id[r["run_id"]], r["run_id"]
