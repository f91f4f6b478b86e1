"""The command lines of demo.sh and bench.sh (m2wr_tools.demo, m2wr_tools.bench.cli), and the
session's error text."""
import os

import pytest

from m2wr_tools.bench import cli as bench, loop as bench_loop
from m2wr_tools import demo
from m2wr_tools.running.session import _problem_lines


def test_demo_defaults_are_the_tutorials_episode_5():
    args = demo.parse_args([])
    assert (args.world, args.x, args.y, args.yaw) == ("world02", 0.0, 8.0, 0.0)
    assert args.duration == 120.0 and args.seed == 0
    assert not (args.gui or args.realtime or args.bag)
    assert args.clock_hz == 20.0


def test_demo_options():
    args = demo.parse_args(["--world", "world01", "--x", "1.5", "--y", "-2", "--yaw", "0.5",
                            "--duration", "30", "--seed", "7", "--gui", "--bag",
                            "--output", "/tmp/out"])
    assert (args.world, args.x, args.y, args.yaw, args.duration, args.seed) == \
        ("world01", 1.5, -2.0, 0.5, 30.0, 7)
    assert args.gui and args.bag and args.output == "/tmp/out"


@pytest.mark.parametrize("argv", [["--duration", "0"], ["--duration", "-5"], ["--x", "nan"],
                                  ["--y", "inf"], ["--clock-hz", "0"], ["--seed", "1.5"]])
def test_demo_refuses_bad_arguments(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        demo.parse_args(argv)
    assert exit_info.value.code == 2
    assert "demo.sh: error:" in capsys.readouterr().err


def test_world_label():
    assert demo.world_label("world02") == "world02"
    assert demo.world_label("/some/where/maze.world") == "maze"


def test_bench_options():
    args = bench.parse_args([])
    assert args.soak == 0.0 and args.seconds == 15.0 and args.clock_hz == 20.0
    assert bench.parse_args(["--soak", "10"]).soak == 10.0
    with pytest.raises(SystemExit):
        bench.parse_args(["--soak", "-1"])
    with pytest.raises(SystemExit):
        bench.parse_args(["--seconds", "0"])


def test_bench_loop_program_rounds_option_and_report():
    assert bench.parse_args(["--loop-program-only"]).loop_program_only == 3
    assert bench.parse_args(["--loop-program-only", "5"]).loop_program_only == 5
    with pytest.raises(SystemExit):
        bench.parse_args(["--loop-program-only", "-1"])
    with pytest.raises(SystemExit):
        bench.parse_args(["--loop-program-only", "2", "--listeners-only", "2"])

    def pair(loop, answering):
        return {"loop": {"x_real_time": loop}, "answering": {"x_real_time": answering},
                "load": "0.50"}
    figures = {"machine": {"load_before": "0.20"}, "loop_program_rounds": [
        {"/clock 20 Hz": pair(45.0, 50.0), "/clock 100 Hz": pair(20.0, 25.0)},
        {"/clock 20 Hz": pair(40.0, 50.0), "/clock 100 Hz": pair(24.0, 24.0)},
        {"/clock 20 Hz": pair(49.0, 50.0), "/clock 100 Hz": pair(None, 24.0)}]}
    lines = bench.loop_program_report(figures).splitlines()
    assert "  /clock 20 Hz, round 2: 40.0x / 50.0x = 0.80; load 0.50" in lines
    assert "  /clock 20 Hz: median 0.90, lowest 0.80" in lines
    assert "  /clock 100 Hz, round 3: n/a / 24.0x = n/a; load 0.50" in lines
    assert "  /clock 100 Hz: median 0.90, lowest 0.80" in lines


def test_problem_lines_pick_the_error_without_colour_codes():
    log = ("\x1b[1mstarted roslaunch server\x1b[0m\n"
           "gazebo_world: world 'world99' not found; pass world:=NAME with NAME one of world01, world02\n"
           "INFO: cannot create a symlink to latest log directory: exists\n"
           "\x1b[31m=====REQUIRED process [gazebo-1] has died!\n"
           "process has died [pid 1, exit code 1]\x1b[0m\n")
    text = _problem_lines(log)
    assert text.splitlines() == [
        "gazebo_world: world 'world99' not found; pass world:=NAME with NAME one of world01, world02",
        "REQUIRED process [gazebo-1] has died!",
        "process has died [pid 1, exit code 1]"]
    assert _problem_lines("all fine\n") == "all fine"


def test_bench_finds_error_lines(tmp_path):
    (tmp_path / "ros").mkdir()
    (tmp_path / "world.log").write_text("[INFO] ok\n[ERROR] [1.0]: bad thing\n")
    (tmp_path / "ros" / "node.log").write_text("Traceback (most recent call last):\n")
    (tmp_path / "notes.txt").write_text("ERROR but not a log\n")
    found = sorted(bench_loop.error_lines(str(tmp_path)))
    assert found == ["ros/node.log: Traceback (most recent call last):",
                     "world.log: [ERROR] [1.0]: bad thing"]


def test_bench_error_lines_skip_logs_of_earlier_runs(tmp_path):
    old = tmp_path / "ros" / "run1" / "master.log"
    old.parent.mkdir(parents=True)
    old.write_text("[ERROR] from an earlier run\n")
    os.utime(old, (1000.0, 1000.0))
    new = tmp_path / "ros" / "run2" / "master.log"
    new.parent.mkdir(parents=True)
    new.write_text("[ERROR] from this run\n")
    assert bench_loop.error_lines(str(tmp_path), since=2000.0) == [
        "ros/run2/master.log: [ERROR] from this run"]
