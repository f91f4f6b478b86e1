"""Helpers of the batch runner's integration tests: running scripts/evaluate.sh, a real Dask
scheduler and workers as separate processes on 127.0.0.1 (stopped by PID), and checks of a
results file against world02's geometry."""
import json
import math
import os
import subprocess
import types

import pytest

from m2wr_tools.running import processes
from m2wr_tools.paths import ROOT
from m2wr_tools.batch.scenarios import FREE_MARGIN, obstacle_distance
from pybullet_gazebo.ros.testing import wait_until

EVALUATE = os.path.join(ROOT, "scripts", "evaluate.sh")
FIXTURES = os.path.join(ROOT, "scripts", "test", "fixtures")
DURATION = 20.0              # [s] of sim time a run: short, the suite stays fast
WORLD02_BOUNDS = (-10.5, -10.5, 10.5, 10.5)   # [m] world02's walls enclose this square


def evaluate(args, output, timeout=420):
    """Runs scripts/evaluate.sh with `args`; returns (exit status, output text, results)."""
    command = ["bash", EVALUATE, "--output", str(output), "--no-progress",
               "--duration", "%g" % DURATION] + list(args)
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=timeout, stdin=subprocess.DEVNULL)
    path = os.path.join(str(output), "results.json")
    data = {"runs": []}
    if os.path.exists(path):
        with open(path) as source:
            data = json.load(source)
    return done.returncode, done.stdout, data


class DaskProcesses:
    """`dask scheduler` and `dask worker` processes, each in its own process group."""

    def __init__(self, log_dir):
        self.log_dir = str(log_dir)
        self.children = []
        self.port = processes.free_port()
        self.address = "tcp://127.0.0.1:%d" % self.port

    def start_scheduler(self):
        self._start("scheduler", ["dask", "scheduler", "--host", "127.0.0.1", "--port",
                                  str(self.port), "--no-dashboard", "--no-show"])

    def start_worker(self, name):
        self._start(name, ["dask", "worker", self.address, "--nthreads", "1", "--nworkers", "1",
                           "--host", "127.0.0.1", "--no-dashboard", "--name", name,
                           "--no-nanny"])

    def _start(self, name, argv):
        env = dict(os.environ)
        self.children.append(processes.Child(name, argv, env,
                                             os.path.join(self.log_dir, name + ".log")))

    def wait_for_workers(self, count, timeout=90.0):
        """Until the scheduler's log shows `count` workers registered."""
        scheduler = self.children[0]

        def registered():
            for child in self.children:
                if not child.running():
                    raise AssertionError("%s exited (%s):\n%s" % (child.name, child.returncode,
                                                                   child.log_tail()))
            return scheduler.log_tail(400).count("Register worker") >= count
        wait_until(registered, timeout, "%d workers registered with the scheduler (its log: %s)"
                   % (count, os.path.join(self.log_dir, "scheduler.log")), interval=0.5)

    def stop(self):
        """Workers first (they stop their simulators), then the scheduler."""
        workers = [c for c in self.children if c.name != "scheduler"]
        outcome = processes.stop(workers, sigint_timeout=30.0, sigterm_timeout=5.0)
        outcome.update(processes.stop([c for c in self.children if c.name == "scheduler"],
                                      sigint_timeout=10.0))
        self.children = []
        return outcome


@pytest.fixture
def dask_cluster(tmp_path):
    cluster = DaskProcesses(tmp_path / "dask")
    try:
        cluster.start_scheduler()
        cluster.start_worker("worker-1")
        cluster.start_worker("worker-2")
        cluster.wait_for_workers(2)
        yield cluster
    finally:
        cluster.stop()


def batch_tag(data):
    return data.get("batch", {}).get("options", {}).get("batch", "")


def assert_no_process_left(data):
    """No process of the batch (tagged M2WR_BATCH) is alive; kills any found, by PID."""
    tag = batch_tag(data)
    assert tag, "results.json names no batch tag"
    try:
        wait_until(lambda: not processes.tagged("M2WR_BATCH", tag), 10.0,
                   "the batch's processes to end", interval=0.2)
    finally:
        left = processes.kill_tagged("M2WR_BATCH", tag)     # by PID, whatever happened
    assert not left, "processes of the batch still running:\n%s" % left


@pytest.fixture
def run_evaluate():
    """evaluate(args, output) -> (exit status, output text, results.json's content)."""
    return evaluate


@pytest.fixture
def no_process_left():
    return assert_no_process_left


def check_sane(data, outlines, count):
    """What every run of a batch of the tutorial's controller in world02 must look like: all
    `count` runs there, free starts, sane metrics (shared by the cluster tests)."""
    runs = data["runs"]
    assert len(runs) == count and len({r["run_id"] for r in runs}) == count
    for r in runs:
        assert "reason" in r and r["reason"], r
        # a run that failed has no metrics: its reason says why
        assert "sim_time_s" in r, "run %s on %s failed: %s" % (
            r["run_id"], r.get("worker"), r["reason"])
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


@pytest.fixture
def batch_kit():
    """What a test module needs from here besides fixtures (pytest's importlib import mode,
    which scripts/test.sh uses, lets no test module import conftest by name)."""
    return types.SimpleNamespace(EVALUATE=EVALUATE, DURATION=DURATION,
                                 DaskProcesses=DaskProcesses, check_sane=check_sane)
