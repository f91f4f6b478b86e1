"""Which processes lockstep watches: the loop nodes found through the master, and the master
itself (their service calls and parameter reads go through it)."""
from pybullet_gazebo.ros.lockstep.node_processes import MASTER, NodeProcesses


def finder(uris, pids):
    return NodeProcesses("/sim", lookup=lambda name: uris[name], get_pid=lambda uri: pids[uri])


def test_the_master_is_watched_beside_the_loop_nodes():
    uris = {"/a": "http://localhost:1/", "/b": "http://vm-other:2/", MASTER: "http://localhost:11311/"}
    pids = {"http://localhost:1/": 100, "http://localhost:11311/": 7}
    processes = finder(uris, pids)
    processes._local = {"localhost"}
    assert processes.find({"/a", "/b"}) == {100, 7}
    assert processes.names_of(7) == [MASTER]
    assert processes.pid_of("/b") == "on another machine"


def test_no_loop_node_no_master():
    processes = finder({MASTER: "http://localhost:11311/"}, {"http://localhost:11311/": 7})
    assert processes.find(set()) == set()
