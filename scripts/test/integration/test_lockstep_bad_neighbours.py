"""Lockstep with misbehaving controllers (issue 26, bad input): beside obstacle_avoidance.py
driving m2wr, robot b's controllers publish 1000 times a wall second, answer every odometry
message twice, read m2wr's scans and never answer, or spin in a busy loop while switched off
(taken for a busy loop and not waited for). Lockstep is not stalled by them, m2wr's
trajectory is the same to the last bit as without them, and the run summary says what each
sent and how long lockstep waited for whom. (scripts/test/fixtures/neighbours_run.py does
one run in a subprocess: its own master, everything stopped by PID at its end.)"""
import json
import os
import subprocess
import sys

from m2wr_tools.paths import ROOT

RUN = os.path.join(ROOT, "scripts", "test", "fixtures", "neighbours_run.py")
SECONDS = 15.0               # [s] sim


def neighbours_run(log_dir, *modes):
    done = subprocess.run([sys.executable, RUN, str(log_dir), "--seconds", str(SECONDS)]
                          + list(modes), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=300, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_misbehaving_neighbours_do_not_change_m2wr_s_run(tmp_path):
    alone = neighbours_run(tmp_path / "alone")
    beside = neighbours_run(tmp_path / "beside", "spam", "twice", "never", "spin")
    assert alone["sim_s"] == beside["sim_s"] >= SECONDS - 0.05
    assert alone["odom_messages"] == beside["odom_messages"]
    assert alone["m2wr"] == beside["m2wr"]            # the same pose, to the last bit
    assert alone["m2wr"][0] > 2.0                     # m2wr did drive (east from x 0)
    commands, = [line for line in beside["summary"] if line.startswith("commands received")]
    counts = {node: int(n) for n, _, node in (part.split(" ", 2) for part in
                                               commands[len("commands received: "):].split(", "))}
    assert counts["/bad_neighbour_spam"] > 500        # it was heard, not held off
    assert counts["/bad_neighbour_twice"] >= 2 * 0.9 * SECONDS * 20   # two per odometry
    assert counts["/reading_laser"] >= 0.9 * SECONDS * 20             # one per scan
    assert "/bad_neighbour_never" not in counts
    lockstep, = [line for line in beside["summary"] if "lockstep:" in line]
    assert "0 time-outs" in lockstep and "waited for:" in lockstep
    spinning, = [line for line in beside["summary"] if line.startswith("busy loops")]
    assert "node /bad_neighbour_spin (pid " in spinning, spinning
