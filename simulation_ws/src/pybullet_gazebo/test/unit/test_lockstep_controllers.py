"""How lockstep waits for each controller, as its connections come and go
(pybullet_gazebo/ros/lockstep/gate.py, sort_controllers): by its reports, in /proc, or not
at all when it is on its way out."""
from pybullet_gazebo.ros.lockstep.gate import sort_controllers


def sorted_after(*looks):
    """Feeds sort_controllers the (names, reporters) of each look in turn; the last answer."""
    reporting, leaving = set(), set()
    for names, reporters in looks:
        reporting, watched, leaving = sort_controllers(set(names), set(reporters),
                                                        reporting, leaving)
    return reporting, watched, leaving


def test_a_reporter_is_waited_for_by_its_reports_and_a_silent_node_in_proc():
    reporting, watched, leaving = sorted_after((["/a", "/cpp"], ["/a", "/sim_watcher"]))
    assert (reporting, watched, leaving) == ({"/a"}, {"/cpp"}, set())


def test_a_reporter_that_lost_only_its_report_connection_is_leaving_not_watched():
    # the simulator sees a dying node's report connection close before its scan connection
    # (it reads the first and only writes the second); it must not be taken for a node
    # without the handshake
    reporting, watched, leaving = sorted_after((["/a", "/b"], ["/a", "/b"]),
                                               (["/a", "/b"], ["/a"]))
    assert (reporting, watched, leaving) == ({"/a"}, set(), {"/b"})
    # still leaving at the next look (another connection of someone else changed) ...
    assert sorted_after((["/a", "/b"], ["/a", "/b"]), (["/a", "/b"], ["/a"]),
                        (["/a", "/b", "/c"], ["/a"]))[1:] == ({"/c"}, {"/b"})
    # ... and forgotten once its last connection is gone
    assert sorted_after((["/a", "/b"], ["/a", "/b"]), (["/a", "/b"], ["/a"]),
                        (["/a"], ["/a"]))[2] == set()


def test_a_new_process_under_a_leaving_name_is_waited_for_again():
    # the batch runner's next controller under the same name: once its report connection
    # opens it is a reporter again; before that, with the old one gone, it is watched
    looks = [(["/b"], ["/b"]), (["/b"], [])]
    assert sorted_after(*looks, (["/b"], ["/b"])) == ({"/b"}, set(), set())
    assert sorted_after(*looks, ([], []), (["/b"], [])) == (set(), {"/b"}, set())


def test_a_node_that_never_reported_is_watched_even_when_others_leave():
    reporting, watched, leaving = sorted_after((["/a", "/cpp"], ["/a"]), (["/a", "/cpp"], []))
    assert (reporting, watched, leaving) == (set(), {"/cpp"}, {"/a"})
