"""m2wr_tools.running.zygote: a forked child runs a script as `python SCRIPT ARGS` would (argv,
sys.path, environment, output to its log, exit status, signals), and commands it cannot run
warm are recognised."""
import os
import shutil
import signal
import sys
import tempfile

import pytest

from m2wr_tools.running import processes, zygote
from pybullet_gazebo.ros.testing import wait_until

SCRIPT = """#!/usr/bin/env python3
import os, sys, time
print("argv", sys.argv[1:])
print("path0", sys.path[0])
print("name", __name__, os.path.basename(__file__))
print("env", os.environ.get("ZYGOTE_TEST"))
print("rospy initialised", __import__("rospy").core.is_initialized())
sys.stdout.flush()
mode = sys.argv[1]
if mode == "exit":
    sys.exit(int(sys.argv[2]))
if mode == "raise":
    raise ValueError("broken on purpose")
if mode == "sleep":
    try:
        time.sleep(60)
    except KeyboardInterrupt:
        print("interrupted")
        sys.exit(5)
"""


@pytest.fixture
def warm(tmp_path):
    path = tmp_path / "controller.py"
    path.write_text(SCRIPT)
    path.chmod(0o755)
    env = dict(os.environ, ZYGOTE_TEST="from the run")
    z = zygote.Zygote(dict(os.environ), str(tmp_path / "zygote.log"))
    yield z, str(path), env, tmp_path
    z.close()
    assert not z.running()


def read(path):
    with open(path) as source:
        return source.read()


def start(z, path, env, tmp_path, *args):
    log = str(tmp_path / ("run-%s.log" % "-".join(args)))
    return z.start("controller", [path, *args], env, log), log


def test_the_child_runs_the_script_as_main_with_its_argv_env_and_exit_status(warm):
    z, path, env, tmp_path = warm
    child, log = start(z, path, env, tmp_path, "exit", "3")
    assert child.wait(20.0) == 3 and not child.running() and child.returncode == 3
    text = read(log)
    assert "argv ['exit', '3']" in text
    assert "path0 %s" % os.path.dirname(os.path.realpath(path)) in text
    assert "name __main__ controller.py" in text
    assert "env from the run" in text
    assert "rospy initialised False" in text
    assert child.pid != os.getpid() and child.pid != z.process.pid


def test_an_uncaught_exception_prints_its_traceback_and_exits_1(warm):
    z, path, env, tmp_path = warm
    child, log = start(z, path, env, tmp_path, "raise")
    assert child.wait(20.0) == 1
    text = read(log)
    assert "Traceback" in text and "ValueError: broken on purpose" in text


def test_sigint_to_its_group_reaches_the_script_and_stop_reports_its_exit(warm):
    z, path, env, tmp_path = warm
    child, log = start(z, path, env, tmp_path, "sleep")
    wait_until(lambda: "rospy initialised" in read(log), 20.0, "the script's 'rospy initialised'",
               interval=0.05)
    assert child.running()
    assert os.getpgid(child.pid) == child.pid        # a process group of its own
    outcome = processes.stop([child], sigint_timeout=10.0)
    assert outcome == {"controller": "exit 5"}
    assert "interrupted" in read(log)


def test_several_children_run_side_by_side_and_a_killed_one_reports_its_signal(warm):
    z, path, env, tmp_path = warm
    first, _ = start(z, path, env, tmp_path, "sleep")
    second, _ = start(z, path, env, tmp_path, "exit", "0")
    assert second.wait(20.0) == 0
    assert first.running()
    first.signal_group(signal.SIGKILL)
    assert first.wait(10.0) == -signal.SIGKILL


def test_only_python_scripts_of_this_interpreter_run_warm(tmp_path):
    path_env = os.environ["PATH"]
    script = tmp_path / "a.py"
    script.write_text("#!/usr/bin/env python3\n")
    script.chmod(0o755)
    assert zygote.warm_script([str(script), "x"], path_env) == (str(script), ["x"])
    assert zygote.warm_script([sys.executable, str(script)], path_env) == (str(script), [])
    flags = tmp_path / "b.py"
    flags.write_text("#!/usr/bin/env python3 -u\n")
    flags.chmod(0o755)
    assert zygote.warm_script([str(flags)], path_env) is None
    other = tmp_path / "c.py"
    other.write_text("#!/usr/bin/python2\n")
    other.chmod(0o755)
    assert zygote.warm_script([str(other)], path_env) is None
    shell = tmp_path / "d.sh"
    shell.write_text("#!/bin/bash\n")
    shell.chmod(0o755)
    assert zygote.warm_script([str(shell)], path_env) is None
    assert zygote.warm_script(["roslaunch", "pkg", "x.launch"], path_env) is None
    assert zygote.warm_script([], path_env) is None


CONFINED = """#!/usr/bin/env python3
import os, resource
print("cwd", os.getcwd())
print("ids", os.getuid(), os.geteuid(), os.getgid(), os.getgroups())
print("cpu", resource.getrlimit(resource.RLIMIT_CPU))
print("fsize", resource.getrlimit(resource.RLIMIT_FSIZE))
try:
    os.setuid(0)
    print("back to root")
except PermissionError:
    print("no way back")
"""


def test_a_graded_child_starts_with_its_folder_limits_and_user(warm):
    """What the grader asks of a warm start: the run's folder, the spec's limits and, as
    root, the run's unprivileged user (here `nobody`), with no way back to root."""
    z, _, env, tmp_path = warm
    user = 65534 if os.geteuid() == 0 else None            # nobody
    folder = tempfile.mkdtemp(prefix="m2wr-zygote-test-")   # pytest's tmp is root's only
    try:
        script = os.path.join(folder, "confined.py")
        with open(script, "w") as out:
            out.write(CONFINED)
        os.chmod(script, 0o755)
        if user is not None:
            os.chown(folder, user, user)
            os.chmod(folder, 0o700)
        log = str(tmp_path / "confined.log")
        child = z.start("controller", [script], env, log, cwd=folder, user=user, group=user,
                        rlimits=[("RLIMIT_CPU", 7), ("RLIMIT_FSIZE", 1 << 20)])
        assert child.wait(20.0) == 0, read(log)
        out = read(log)
        assert "cwd %s" % folder in out
        assert "cpu (7, 7)" in out and "fsize (1048576, 1048576)" in out
        if user is not None:
            assert "ids 65534 65534 65534 []" in out and "no way back" in out
    finally:
        shutil.rmtree(folder)


def test_roslaunch_command_lines_a_warm_launch_takes():
    """roslaunch's own command line, package and file or a file, with name:=value arguments
    and --screen; its other options (another master, --wait, --nodes ...) run as roslaunch."""
    from m2wr_tools.running import warm_launch
    assert warm_launch.accepts(["roslaunch", "motion_plan", "bug2.launch", "des_x:=1"])
    assert warm_launch.accepts(["roslaunch", "--screen", "/w/bug2.launch"])
    assert warm_launch.accepts(["/opt/ros/bin/roslaunch", "motion_plan", "bug2.launch"])
    assert not warm_launch.accepts(["roslaunch", "-p", "11312", "motion_plan", "bug2.launch"])
    assert not warm_launch.accepts(["roslaunch", "--wait", "motion_plan", "bug2.launch"])
    assert not warm_launch.accepts(["roslaunch"])
    assert not warm_launch.accepts(["roslaunch", "a", "b", "c"])
    assert not warm_launch.accepts(["rosrun", "motion_plan", "bug2.py"])
