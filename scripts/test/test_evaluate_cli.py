"""The command line of evaluate.sh (m2wr_tools.batch.evaluate): defaults, options, bad input."""
import sys

import pytest

from m2wr_tools.batch import evaluate


def test_defaults_are_the_tutorials_program_in_world02():
    args = evaluate.parse_args([])
    assert args.world == ["world02"] and args.task == "wander" and args.duration == 60.0
    assert args.seeds == [0] and args.scheduler is None and not args.no_reuse
    assert evaluate.controller_argv(args.controller) == ("rosrun", "motion_plan",
                                                         "obstacle_avoidance.py")


def test_options():
    args = evaluate.parse_args(["--world", "world01", "--world", "world02", "--random", "40",
                                "--pose-seed", "2", "--seeds", "0", "1", "--duration", "30",
                                "--scheduler", "tcp://127.0.0.1:8786", "--task", "goal",
                                "--goal", "2", "-3"])
    assert args.world == ["world01", "world02"] and args.random == 40 and args.seeds == [0, 1]
    assert args.goal == [2.0, -3.0] and args.scheduler == "tcp://127.0.0.1:8786"


def test_a_script_path_runs_with_this_python(tmp_path):
    script = tmp_path / "mine.py"
    script.write_text("print('hi')\n")
    assert evaluate.controller_argv(str(script)) == (sys.executable, str(script))
    assert evaluate.controller_argv("roslaunch my_pkg my.launch x:=1") == (
        "roslaunch", "my_pkg", "my.launch", "x:=1")
    with pytest.raises(ValueError, match="--controller is empty"):
        evaluate.controller_argv("  ")


@pytest.mark.parametrize("argv, message", [
    (["--duration", "0"], "--duration must be > 0"),
    (["--workers", "0"], "--workers must be >= 1"),
    (["--grid", "1", "--random", "3"], "pass one of --start, --grid, --random"),
    (["--task", "goal"], "--task goal needs --goal"),
    (["--scheduler", "localhost:8786"], "--scheduler must be an address like tcp://"),
    (["--task", "dance"], "invalid choice"),
])
def test_bad_arguments_are_named(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        evaluate.parse_args(argv)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err


def test_the_memory_bench_defaults_to_200_short_runs():
    args = evaluate.parse_args(["--bench-memory"])
    assert args.bench_runs == 200 and args.duration == 5.0
    args = evaluate.parse_args(["--bench"])
    assert args.bench_runs == 20 and args.duration == 60.0 and not args.cold_start


def test_the_memory_table_reports_rss_at_the_marks_and_its_slope():
    # a worker that grows 0.05 MiB a run, a simulator that stays flat after a warm-up
    runs = [{"worker_rss_mib": 300.0 + 0.05 * i,
             "simulator_rss_mib": 500.0 if i >= 10 else 400.0 + 10 * i,
             "zygote_rss_mib": None} for i in range(200)]
    table = evaluate.memory_table(runs)
    assert table["marks"] == [1, 50, 100, 150, 200]
    assert abs(table["slopes_mib_per_100_runs"]["worker"] - 5.0) < 1e-6
    assert abs(table["slopes_mib_per_100_runs"]["simulator"]) < 1e-6
    assert "zygote" not in table["slopes_mib_per_100_runs"]
    lines = table["text"].splitlines()
    assert "run 1" in lines[0] and "run 200" in lines[0]
    assert lines[1].split()[:3] == ["worker", "300.0", "302.4"]
    assert "+5.00 MiB per 100 runs" in lines[1]
    short = evaluate.memory_table(runs[:30])
    assert short["marks"] == [1, 30]


@pytest.mark.parametrize("argv, message", [
    (["--world", "world99"], "--world world99: world 'world99' not found; pass --world NAME "
                             "with NAME one of world01, world02, world03"),
    (["--controller", "/no/such/file.py"], "--controller /no/such/file.py: no such file; "
                                           "pass the path of an existing script"),
    (["--controller", "rosrun motion_plan nope.py"], "has no file 'nope.py'"),
    (["--controller", "rosrun no_such_pkg x.py"], "package 'no_such_pkg' not found on "
                                                  "ROS_PACKAGE_PATH"),
    (["--controller", "roslaunch motion_plan no.launch"], "has no launch file 'no.launch'"),
    (["--controller", "no_such_program --flag"], "no program 'no_such_program' on PATH"),
])
def test_a_bad_world_or_controller_stops_before_any_run_with_its_name(argv, message, capsys,
                                                                      tmp_path):
    status = evaluate.main(argv + ["--output", str(tmp_path), "--no-progress"])
    err = capsys.readouterr().err
    assert status == 2 and message in err and "Traceback" not in err
    assert not (tmp_path / "results.json").exists()


def test_a_script_that_is_not_executable_is_named_with_the_fix(tmp_path):
    from m2wr_tools.running import commands
    package = tmp_path / "pkg"
    (package / "scripts").mkdir(parents=True)
    (package / "package.xml").write_text("<package format='2'><name>pkg</name>"
                                         "<version>0.0.0</version></package>")
    (package / "scripts" / "go.py").write_text("print('hi')\n")
    env = dict(PATH="/usr/bin:/bin", ROS_PACKAGE_PATH=str(tmp_path))
    with pytest.raises(ValueError, match="go.py is not executable; chmod \\+x it"):
        commands.check(("rosrun", "pkg", "go.py"), env)
    (package / "scripts" / "go.py").chmod(0o755)
    assert commands.check(("rosrun", "pkg", "go.py"), env) is None
