"""Lockstep by handshake (issue 36): the controllers' processes say when they are done, so a
run is the same to the bit whatever else the machine does, for a program that answers scans
and for rospy.Rate and rospy.Timer loops; a controller the simulator cannot see as a local
process (another PID namespace, as on another machine) is waited for exactly all the same;
one that cannot report (LOCKSTEP_HANDSHAKE=off) is watched in /proc, and the run summary says
which way each was waited for. Each run is scripts/test/fixtures/neighbours_run.py: its own
master, everything stopped by PID at its end."""
import json
import os
import subprocess
import sys

import pytest

from m2wr_tools.paths import ROOT

RUN = os.path.join(ROOT, "scripts", "test", "fixtures", "neighbours_run.py")
SECONDS = 8.0                # [s] sim


def run(log_dir, *options):
    # a loaded machine may hold a starting controller past the default 1 s: stepped past,
    # it would make the two runs differ (the batch runner waits 30 s too)
    done = subprocess.run([sys.executable, RUN, str(log_dir), "--seconds", str(SECONDS),
                           "--lockstep-timeout", "30"] + list(options),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=300, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout
    return json.loads(done.stdout.strip().splitlines()[-1])


def lockstep_line(result):
    line, = [line for line in result["summary"] if "lockstep:" in line]
    return line


@pytest.fixture(scope="module")
def tutorial_on_an_idle_machine(tmp_path_factory):
    """The tutorial's run with nothing else to do: the baseline of two tests."""
    return run(tmp_path_factory.mktemp("tutorial_idle"))


@pytest.mark.parametrize("controller", ["tutorial", "loop10", "loop50", "timer20"])
def test_the_same_run_to_the_bit_with_both_cores_busy(tmp_path, controller, request):
    idle = request.getfixturevalue("tutorial_on_an_idle_machine") if controller == "tutorial" \
        else run(tmp_path / "idle", "--controller", controller)
    loaded = run(tmp_path / "loaded", "--controller", controller, "--busy-cores", "2")
    assert idle["m2wr"][0] > 1.0                        # m2wr drove east from x 0
    assert idle["track_sha256"] == loaded["track_sha256"], (idle["m2wr"], loaded["m2wr"])
    for result in (idle, loaded):
        line = lockstep_line(result)
        assert "0 time-outs" in line, line
        assert "by handshake (exact): " in line and "/reading_laser" in line, line
        assert "watched in /proc" not in line, line


def ticks_and_scans(log_dir):
    """tick_reader.py's notes: [(sim time of a turn, stamp of the latest scan it had)] [ns]."""
    with open(os.path.join(str(log_dir), "ticks.txt")) as notes:
        return [tuple(map(int, line.split())) for line in notes if line.strip()]


@pytest.mark.parametrize("busy_cores", [0, 2])
def test_a_lone_loop_gets_its_tick_with_the_readings_and_acts_on_the_scan_of_its_time(
        tmp_path, busy_cores):
    """A lone loop node's tick goes out with the readings, with word of what it follows
    (lockstep/tick_word.py): its process sets the tick only once the scan of that time has
    gone through its callback, so every turn of a rospy.Rate(20) loop sees the scan stamped
    with its own sim time, with both cores busy too, and a neighbour sending ticks of its
    own making changes nothing. With `rostopic hz` reading the scan
    beside it, each tick waits for the readings' report instead: the same track, to the bit."""
    # bad_neighbour.py's ticks: ticks of its own making, which must change nothing
    lone = run(tmp_path / "lone", "--controller", "ticks", "--busy-cores", str(busy_cores),
               "ticks")
    notes = ticks_and_scans(tmp_path / "lone")
    assert len(notes) > 100, notes
    late = [(now, scan) for now, scan in notes[1:] if now != scan]
    assert not late, "turns that did not see the scan of their time: %s" % late[:5]
    assert "sent with the readings" in lockstep_line(lone)
    if busy_cores:
        return
    beside = run(tmp_path / "beside", "--controller", "ticks", "--scan-reader")
    assert lone["track_sha256"] == beside["track_sha256"], (lone["m2wr"], beside["m2wr"])
    line = lockstep_line(beside)
    assert "sent with the readings" not in line and "0 time-outs" in line, line


def test_a_callback_that_naps_in_sim_time_is_not_waited_for(tmp_path):
    """A scan callback that calls rospy.sleep(0.1) every tenth scan (napping_reader.py): the
    simulator does not wait for it (it would wait for the callback and the callback for its
    tick: the run stood still until lockstep_timeout at every nap), the nap lasts its 0.1 s
    of sim time, and the scans that came meanwhile are handled once it is over."""
    result = run(tmp_path, "--controller", "naps", "--clock-hz", "20")
    line = lockstep_line(result)
    assert "0 time-outs" in line and "still at work" not in line, line
    with open(tmp_path / "naps.txt") as notes:
        handled = [tuple(map(int, note.split())) for note in notes if note.strip()]
    # every scan of the run handled in turn, none lost to the naps (20 Hz, SECONDS of sim)
    stamps = [scan for _, scan in handled]
    assert stamps == sorted(stamps) and len(stamps) >= 20 * SECONDS - 2, stamps
    assert all(b - a == 50000000 for a, b in zip(stamps, stamps[1:])), stamps
    naps = handled[9::10]
    assert len(naps) >= 14, handled
    for index in range(9, len(handled) - 1, 10):
        (napped_at, _), (next_at, _) = handled[index], handled[index + 1]
        assert next_at >= napped_at + 100000000, (handled[index], handled[index + 1])
    commands = [s for s in result["summary"] if s.startswith("commands received")]
    assert commands and int(commands[0].split()[2]) >= len(handled) - 1, result["summary"]


def test_a_controller_in_another_pid_namespace_is_waited_for_exactly(
        tmp_path, tutorial_on_an_idle_machine):
    here = tutorial_on_an_idle_machine
    isolated = run(tmp_path / "isolated", "--isolated")
    assert here["track_sha256"] == isolated["track_sha256"]
    line = lockstep_line(isolated)
    assert "by handshake (exact): " in line and "/reading_laser" in line and \
        "0 time-outs" in line, line


def test_an_uninstrumented_controller_falls_back_to_the_proc_watch_named(tmp_path):
    result = run(tmp_path / "watched", "--no-handshake")
    assert result["m2wr"][0] > 1.0
    line = lockstep_line(result)
    assert "watched in /proc (no handshake): /reading_laser" in line, line
