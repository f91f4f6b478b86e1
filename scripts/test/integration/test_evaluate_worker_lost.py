"""A Dask worker that dies mid-batch (kill -9 of a `dask worker` process while it runs one
of the batch's runs): the scheduler gives its runs to the other worker, the batch finishes
with every run present and done (none lost to the dead worker), and no process of the
batch is left - the dead worker's simulator, master and controller included."""
import glob
import json
import os
import signal
import socket
import subprocess

from m2wr_tools.analysis.scene import SCAN_HEIGHT, Scene
from pybullet_gazebo.ros.testing import wait_until

RUNS = 6


def test_a_killed_worker_has_its_runs_done_by_the_other(tmp_path, run_evaluate,
                                                        no_process_left, batch_kit):
    cluster = batch_kit.DaskProcesses(tmp_path / "dask")
    output = tmp_path / "batch"
    batch = None
    try:
        cluster.start_scheduler()
        cluster.start_worker("worker-1")
        cluster.start_worker("worker-2")
        cluster.wait_for_workers(2)
        victim = cluster.children[2]
        with open(tmp_path / "evaluate.log", "wb") as log:
            batch = subprocess.Popen(
                ["bash", batch_kit.EVALUATE, "--output", str(output), "--no-progress",
                 "--duration", "%g" % batch_kit.DURATION, "--random", str(RUNS), "--pose-seed", "3", "--scheduler",
                 cluster.address], stdout=log, stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL)
            # the victim is inside a run once its rig forked a controller (zygote.log)
            its_logs = os.path.join(str(output), "logs", "worker-%s-%d" % (
                socket.gethostname(), victim.pid))

            def victim_in_a_run():
                assert batch.poll() is None, "the batch ended before the kill"
                return glob.glob(os.path.join(its_logs, "zygote.log"))
            wait_until(victim_in_a_run, 240.0, "worker-2 to start a run", interval=0.2)
            os.kill(victim.pid, signal.SIGKILL)
            assert victim.wait(10.0) == -signal.SIGKILL
            status = batch.wait(timeout=420)
        with open(tmp_path / "evaluate.log") as log:
            text = log.read()
        assert status == 0, text
    finally:
        if batch is not None and batch.poll() is None:
            batch.kill()
        cluster.stop()
    with open(output / "results.json") as source:
        data = json.load(source)
    lost = [r["reason"] for r in data["runs"] if "failed on the cluster" in r.get("reason", "")]
    assert not lost, lost
    scene = Scene.of_world("world02")
    try:
        outlines = scene.outlines(SCAN_HEIGHT)
    finally:
        scene.close()
    batch_kit.check_sane(data, outlines, RUNS)        # every run present, done, with sane metrics
    assert "runs 6, success" in text
    by_victim = [r for r in data["runs"] if r["worker"].endswith(":%d" % victim.pid)]
    assert len(by_victim) < RUNS            # it died before the end: the others were redone
    no_process_left(data)
