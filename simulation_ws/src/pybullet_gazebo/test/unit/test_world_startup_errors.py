"""A bad world stops the world server before any ROS traffic: `gazebo_world WORLD` (what
`rosrun pybullet_gazebo gazebo_world WORLD` runs, and what launch_world.launch starts as node
/gazebo) exits 1 with one line on stderr that names the problem and what to do.

No ROS master runs here. ROS_MASTER_URI points at a listening socket that never answers (a
trap): had the node spoken to ROS first, the socket would hold a connection and the node would
hang in rospy.init_node. A good world is run once against the same trap to show that it would
notice. The process cases start together (~1 s of CPU each); content errors the same loader
reports are checked in-process.
"""
import os
import socket
import subprocess
import sys

import pytest

from pybullet_gazebo.engine.sdf_world import WorldFileError, load_world
from pybullet_gazebo.ros.testing import wait_until

PKG = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
NODE = os.path.join(PKG, "nodes", "gazebo_world")
MY_WORLDS = os.path.join(os.path.dirname(PKG), "my_worlds", "worlds")
FIXTURES = os.path.join(PKG, "test", "fixtures", "sdf_world", "worlds")
TIMEOUT = 20.0          # [s] wall; a refusal takes ~1 s

SDF = "<sdf version='1.6'><world name='w'>%s</world></sdf>"
BOX_MODEL = ("<model name='m'><pose>%s</pose><link name='l'><collision name='c'><geometry>"
             "<box><size>%s</size></box></geometry></collision></link></model>")

# Run as processes: name -> (world argument or file text, texts stderr must hold). "file:"
# entries are written to a temporary folder first; "{tmp}" is that folder.
CASES = {
    "missing_path": ("/nonexistent/dir/nowhere.world",
                     ["world '/nonexistent/dir/nowhere.world' not found", "world01, world02"]),
    "unknown_name": ("world99", ["world 'world99' not found", "world:=NAME"]),
    "malformed_xml": (os.path.join(FIXTURES, "malformed.world"),
                      ["malformed XML", "malformed.world", "line 5"]),
    "unknown_include": (os.path.join(FIXTURES, "unknown_include.world"),
                        ["unknown model 'model://no_such_model'", "GAZEBO_MODEL_PATH"]),
    "broken_included_model": ("file:" + SDF % "<include><uri>model://broken</uri></include>",
                              ["model://broken", "model.sdf", "malformed XML"]),
    "negative_box": ("file:" + SDF % BOX_MODEL % ("0 0 0 0 0 0", "-1 1 1"),
                     ["model 'm'", "box <size> -1 1 1", "must not be negative"]),
    "shell_text_as_name": ("$(touch {tmp}/pwned)", ["not found", "$(touch"]),
}

# Read in-process by the same loader (a process each would cost ~1 s): text -> message parts.
CONTENT_CASES = {
    "empty_file": ("", ["malformed XML", "no element found"]),
    "binary_file": ("\x00\x01\x02", ["malformed XML", "not well-formed"]),
    "not_sdf": ("<robot name='r'/>", ["no <sdf><world> element"]),
    "nan_pose": (SDF % BOX_MODEL % ("nan 0 0 0 0 0", "1 1 1"),
                 ["model 'm'", "non-finite", "nan 0 0 0 0 0"]),
    "negative_cylinder": (SDF % (
        "<model name='c'><link name='l'><collision name='k'><geometry><cylinder>"
        "<radius>0.3</radius><length>-2</length></cylinder></geometry></collision></link>"
        "</model>"), ["model 'c'", "cylinder <radius> <length> 0.3 -2", "must not be negative"]),
    "zero_plane_normal": (SDF % (
        "<model name='g'><static>true</static><link name='l'><collision name='c'><geometry>"
        "<plane><normal>0 0 0</normal></plane></geometry></collision></link></model>"),
        ["model 'g'", "<normal> 0 0 0", "not a direction"]),
    "external_entity": ("<?xml version='1.0'?><!DOCTYPE s [<!ENTITY x SYSTEM "
                        "'file:///etc/hostname'>]><sdf version='1.6'><world name='&x;'/></sdf>",
                        ["malformed XML", "external entity"]),
}


def trap():
    """A listening socket that never answers: the stand-in for a master that must not be
    contacted. Returns (socket, ROS_MASTER_URI)."""
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.bind(("127.0.0.1", 0))
    listener.listen(16)
    listener.setblocking(False)
    return listener, "http://127.0.0.1:%d/" % listener.getsockname()[1]


def contacted(listener):
    """Whether anybody connected to the trap (a connection waits in its backlog)."""
    try:
        connection, _ = listener.accept()
    except BlockingIOError:
        return False
    connection.close()
    return True


def start(world, master_uri, tmp):
    env = dict(os.environ, ROS_MASTER_URI=master_uri,
               GAZEBO_MODEL_PATH=os.path.join(tmp, "models"),
               PYTHONPATH=os.pathsep.join([os.path.join(PKG, "src"),
                                           os.environ.get("PYTHONPATH", "")]))
    return subprocess.Popen([sys.executable, NODE, world, "--worlds-dir", MY_WORLDS],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    """name -> (exit code, stdout, stderr, trap contacted); every case runs at once."""
    tmp = str(tmp_path_factory.mktemp("worlds"))
    broken = os.path.join(tmp, "models", "broken")
    os.makedirs(broken)
    with open(os.path.join(broken, "model.config"), "w") as out:
        out.write("<model><name>broken</name><sdf version='1.6'>model.sdf</sdf></model>")
    with open(os.path.join(broken, "model.sdf"), "w") as out:
        out.write("<sdf version='1.6'><model name='broken'><link name='l'></model></sdf>")
    running = {}
    for name, (world, _) in CASES.items():
        if world.startswith("file:"):
            path = os.path.join(tmp, name + ".world")
            with open(path, "w") as out:
                out.write(world[len("file:"):])
            world = path
        listener, uri = trap()
        running[name] = (start(world.format(tmp=tmp), uri, tmp), listener)
    results = {}
    for name, (process, listener) in running.items():
        try:
            stdout, stderr = process.communicate(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            process.kill()
            stdout, stderr = process.communicate()
            stderr += "\n(still running after %.0f s: it went on to ROS)" % TIMEOUT
        results[name] = (process.returncode, stdout, stderr, contacted(listener))
        listener.close()
    results["tmp"] = tmp
    return results


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_world_exits_1_before_ros_naming_the_problem(outcomes, name):
    code, stdout, stderr, talked_to_master = outcomes[name]
    assert code == 1, stderr
    assert not talked_to_master, "contacted ROS_MASTER_URI before refusing the world"
    assert stdout == ""
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("gazebo_world: "), stderr   # no traceback
    for text in CASES[name][1]:
        assert text.format(tmp=outcomes["tmp"]) in stderr


def test_world_arguments_are_never_run_by_a_shell(outcomes):
    assert not os.path.exists(os.path.join(outcomes["tmp"], "pwned"))


@pytest.mark.parametrize("name", sorted(CONTENT_CASES))
def test_bad_world_content_is_named(tmp_path, name):
    text, expected = CONTENT_CASES[name]
    path = tmp_path / (name + ".world")
    path.write_text(text)
    with pytest.raises(WorldFileError) as error:
        load_world(str(path), [os.path.join(PKG, "models")])
    assert str(path) in str(error.value)
    for part in expected:
        assert part in str(error.value)


def test_external_entities_are_not_read(tmp_path):
    path = tmp_path / "entity.world"
    path.write_text(CONTENT_CASES["external_entity"][0])
    with open("/etc/hostname") as source:
        hostname = source.read().strip()
    with pytest.raises(WorldFileError) as error:
        load_world(str(path), [])
    assert hostname not in str(error.value)


def test_the_trap_notices_a_node_that_goes_on_to_ros(tmp_path):
    """Control: with a good world the node does contact the master (and waits there)."""
    listener, uri = trap()
    process = start("world01", uri, str(tmp_path))
    try:

        def contacted_while_running():
            assert process.poll() is None, process.communicate()[1]
            return contacted(listener)
        wait_until(contacted_while_running, TIMEOUT, "world01's call to the master",
                   interval=0.05)
    finally:
        process.kill()
        process.communicate()
        listener.close()
