"""Lockstep with misbehaving controllers (issue 26, bad input): beside obstacle_avoidance.py
driving m2wr, robot b's controllers publish 1000 times a wall second, answer every odometry
message twice, read m2wr's scans and never answer, spin in a busy loop while switched off,
stop answering for 3 s, die in the middle of a callback, or send lockstep reports of their own
making. Lockstep is not stalled by them, m2wr's
trajectory is the same to the last bit as without them, and the run summary says what each
sent and how long lockstep waited for whom. (scripts/test/fixtures/neighbours_run.py does
one run in a subprocess: its own master, everything stopped by PID at its end.)"""
import json
import os
import re
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
    beside = neighbours_run(tmp_path / "beside", "spam", "twice", "never", "spin", "stall",
                            "die", "fake")
    assert alone["sim_s"] == beside["sim_s"] >= SECONDS - 0.05
    assert alone["odom_messages"] == beside["odom_messages"]
    assert alone["m2wr"] == beside["m2wr"]            # the same pose, to the last bit
    assert alone["m2wr"][0] > 2.0                     # m2wr did drive (east from x 0)
    counts = per_node(beside, "commands received")
    dropped = per_node(beside, "commands dropped unread")
    assert counts["/bad_neighbour_spam"] > 500        # it was heard, not held off
    # two per odometry, the second often in the same read as the first: the drive's queue
    # of one keeps the newest (as Gazebo's), and lockstep counts the one it drops
    assert counts["/bad_neighbour_twice"] + dropped.get("/bad_neighbour_twice", 0) \
        >= 2 * 0.9 * SECONDS * 20
    assert counts["/reading_laser"] >= 0.9 * SECONDS * 20             # one per scan
    assert "/bad_neighbour_never" not in counts
    lockstep, = [line for line in beside["summary"] if "lockstep:" in line]
    assert "waited for:" in lockstep
    # every neighbour reports: waited for by handshake, the busy loop too (it only polls:
    # done), none by the /proc watch
    for node in ("/bad_neighbour_twice", "/bad_neighbour_never", "/bad_neighbour_spin",
                 "/reading_laser"):
        assert node in lockstep.split("by handshake (exact): ")[1], lockstep
    assert "watched in /proc" not in lockstep, lockstep
    # the stalled one is stepped past after lockstep_timeout, named with what it had not
    # taken in; the flood is waited for, if at all, only for the simulator to read its
    # commands, and named with them (the simulator's main thread reads commands as they
    # come, so it seldom is)
    stepped_past = lockstep.split("still at work: ", 1)[-1].split("; by handshake")[0]
    assert "node /bad_neighbour_stall (/m2wr/laser/scan not taken in" in stepped_past, \
        lockstep
    for why in re.findall(r"node /bad_neighbour_spam \(([^)]*)\)", lockstep):
        assert why.startswith("/b/cmd_vel not read"), lockstep


def per_node(result, heading):
    """{node: count} from a summary line `HEADING...: N from NODE, ...`, or {}."""
    lines = [line for line in result["summary"] if line.startswith(heading)]
    if not lines:
        return {}
    return {node: int(n) for n, node in re.findall(r"(\d+) from (/[\w/]+)", lines[0])}
