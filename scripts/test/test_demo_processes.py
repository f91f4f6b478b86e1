"""m2wr_tools.running.processes: free port, stopping process groups by escalation, finding
leftovers.
The children here are `sleep` and `bash`, each in a session of its own, and are always
stopped by the test that starts them."""
import os
import signal
import socket
import uuid

import pytest

from m2wr_tools.running import processes
from m2wr_tools.running.processes import Child
from pybullet_gazebo.ros.testing import wait_until


@pytest.fixture
def run_env():
    """An environment with a ROS_MASTER_URI no other process has."""
    uri = "http://localhost:1/%s" % uuid.uuid4().hex
    return uri, dict(os.environ, ROS_MASTER_URI=uri)


def test_free_port_can_be_bound():
    port = processes.free_port()
    assert 1024 <= port <= 65535
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", port))
        sock.listen(1)
        assert processes.port_in_use(port)


def exec_done(pid, program):
    try:
        with open("/proc/%d/cmdline" % pid, "rb") as cmdline:
            return cmdline.read().startswith(program)
    except OSError:
        return False


def test_sigint_ends_a_well_behaved_child(tmp_path, run_env):
    uri, env = run_env
    # A child inherits an ignored SIGINT (a test run started in the background by a
    # non-interactive shell has SIGINT ignored, and Python then keeps it so), but a handled
    # one is back to the default after exec: the tools handle it (raise_on_signals)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        child = Child("sleeper", ["sleep", "30"], env, str(tmp_path / "sleeper.log"))
    finally:
        signal.signal(signal.SIGINT, previous)
    assert child.running()
    # Between fork and exec the child still has this process's environment (so leftovers
    # cannot know it yet), and a SIGINT then is swallowed by the forked Python's handler; a
    # real child has long exec'd when the demo looks for it or stops it, so wait for that.
    wait_until(lambda: exec_done(child.pid, b"sleep"), 5.0, "the child's exec of sleep",
               interval=0.01)
    assert processes.leftovers(uri) == [child.pid]
    outcome = processes.stop([child], sigint_timeout=5.0, sigterm_timeout=1.0)
    assert outcome == {"sleeper": "exit -2"}
    assert processes.leftovers(uri) == []


def test_escalates_to_sigterm_then_sigkill(tmp_path, run_env):
    uri, env = run_env
    deaf = Child("deaf", ["bash", "-c", "trap '' INT; echo ready; sleep 30 & wait"], env,
                 str(tmp_path / "deaf.log"))
    deafer = Child("deafer", ["bash", "-c", "trap '' INT TERM; echo ready; while :; do sleep 0.1; done"],
                   env, str(tmp_path / "deafer.log"))
    wait_until(lambda: all("ready" in c.log_tail() for c in (deaf, deafer)), 5.0,
               "'ready' from both children", interval=0.05)
    outcome = processes.stop([deaf, deafer], sigint_timeout=0.5, sigterm_timeout=0.5)
    assert outcome == {"deaf": "SIGTERM", "deafer": "SIGKILL"}
    # the whole group went: deaf's `sleep` child too
    wait_until(lambda: not processes.leftovers(uri), 2.0, "no process of the group left",
               interval=0.05)


def test_kill_leftovers_finds_orphans_by_environment(tmp_path, run_env):
    uri, env = run_env
    # bash starts sleep in a session of its own (as roslaunch starts nodes) and exits
    parent = Child("parent", ["bash", "-c", "setsid sleep 30 & echo $!"], env,
                   str(tmp_path / "parent.log"))
    assert parent.wait(5.0) == 0
    orphan = int(parent.log_tail().split()[-1])
    parent.close()
    # while it execs, its /proc entry is in flux
    wait_until(lambda: exec_done(orphan, b"sleep"), 5.0, "the orphan's exec of sleep",
               interval=0.01)
    assert processes.leftovers(uri) == [orphan]
    text = processes.kill_leftovers(uri)
    assert str(orphan) in text and "sleep 30" in text
    assert processes.leftovers(uri) == []


def test_start_failure_names_the_command(tmp_path):
    with pytest.raises(RuntimeError, match="cannot start nothing"):
        Child("nothing", ["/nonexistent/program"], dict(os.environ), str(tmp_path / "n.log"))


def test_process_figures_of_this_process():
    assert processes.peak_rss_kib(os.getpid()) >= processes.rss_kib(os.getpid()) > 1000
    assert processes.cpu_seconds(os.getpid()) > 0.0
    assert "PATH" in processes.environment_of(os.getpid())
    assert processes.peak_rss_kib(2 ** 22 + 12345) is None
    assert processes.environment_of(2 ** 22 + 12345) == {}
