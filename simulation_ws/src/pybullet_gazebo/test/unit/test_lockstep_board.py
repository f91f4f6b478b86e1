"""The simulator's side of lockstep's handshake without ROS: whether the controllers' reports
say they are done with everything the simulator sent them (pybullet_gazebo/ros/lockstep/
board.py)."""
import threading
import time

from pybullet_gazebo.ros.lockstep.board import Board

SIM = "/gazebo"


class Own:
    """The simulator's own counts (its Tracker's)."""

    def __init__(self):
        self.taken, self.written = {}, {}

    def __call__(self):
        return dict(self.taken), dict(self.written)


def make(providers=None, inbound=None):
    own = Own()
    board = Board(SIM, own, service_provider=(providers or {}).get,
                  own_inbound=(lambda: inbound) if inbound is not None else None)
    return board, own


def test_busy_until_the_report_counts_every_message_sent():
    board, own = make()
    own.written[("/scan", "/ctl", 5)] = 3
    assert board.busy({"/ctl"}) == ("/ctl", "no report yet")
    board.take("/ctl", pid=1, seq=1, taken={("/scan", SIM, 5): 2}, written={})
    assert board.busy({"/ctl"})[0] == "/ctl"
    board.take("/ctl", pid=1, seq=2, taken={("/scan", SIM, 5): 3}, written={})
    assert board.busy({"/ctl"}) is None


def test_busy_until_the_simulator_has_read_every_command_reported():
    board, own = make(inbound={("/cmd_vel", "/ctl", 6)})
    board.take("/ctl", 1, 1, taken={}, written={("/cmd_vel", SIM, 6): 4})
    own.taken[("/cmd_vel", "/ctl", 6)] = 3
    assert "not read by the simulator" in board.busy({"/ctl"})[1]
    own.taken[("/cmd_vel", "/ctl", 6)] = 4
    assert board.busy({"/ctl"}) is None


def test_a_late_or_repeated_report_says_nothing_false():
    board, own = make()
    own.written[("/scan", "/ctl", 5)] = 3
    board.take("/ctl", 1, 9, taken={("/scan", SIM, 5): 3}, written={})
    board.take("/ctl", 1, 4, taken={("/scan", SIM, 5): 1}, written={})     # an old one
    board.take("/ctl", 1, 9, taken={("/scan", SIM, 5): 3}, written={})     # twice
    assert board.busy({"/ctl"}) is None


def test_a_restarted_node_starts_over():
    board, own = make()
    board.take("/ctl", 1, 50, taken={("/scan", SIM, 5): 50}, written={})
    own.written[("/scan", "/ctl", 7)] = 1                  # the new process's connection
    board.take("/ctl", 2, 1, taken={("/scan", SIM, 7): 1}, written={})
    assert board.report_of("/ctl").taken == {("/scan", SIM, 7): 1}
    assert board.busy({"/ctl"}) is None


def test_a_topic_between_two_controllers_must_be_taken_in():
    board, _ = make()
    board.take("/a", 1, 1, taken={}, written={("/plan", "/b", 8): 2})
    board.take("/b", 2, 1, taken={("/plan", "/a", 8): 1}, written={})
    assert board.busy({"/a", "/b"}) == ("/b", "/plan from /a not taken in")
    board.take("/b", 2, 2, taken={("/plan", "/a", 8): 2}, written={})
    assert board.busy({"/a", "/b"}) is None


def test_a_service_call_waits_for_its_server_in_either_order():
    providers = {"/go_to_point_switch": "/go_to_point"}
    board, _ = make(providers)
    nodes = {"/bug2", "/go_to_point"}
    board.take("/go_to_point", 1, 1, taken={}, written={})
    board.take("/bug2", 2, 1, taken={}, written={}, called=[("/go_to_point_switch", 9)])
    assert board.busy(nodes) == ("/bug2", "its call to /go_to_point_switch not yet answered "
                                           "by /go_to_point")
    board.take("/go_to_point", 1, 2, taken={}, written={},
               served=[("/go_to_point_switch", 9)])
    assert board.busy(nodes) is None
    # the server's report first, the client's after: matched all the same
    board.take("/go_to_point", 1, 3, taken={}, written={},
               served=[("/go_to_point_switch", 10)])
    board.take("/bug2", 2, 2, taken={}, written={}, called=[("/go_to_point_switch", 10)])
    assert board.busy(nodes) is None


def test_a_report_taken_twice_does_not_make_its_call_wait_again():
    # rospy sends a latched publisher's last message again to a new subscriber, after what
    # the connect hook sent it: bug 1's first report came twice, and the call it names was
    # waited for until lockstep_timeout (30 s in a graded run)
    board, _ = make({"/go_to_point_switch": "/go_to_point"})
    nodes = {"/bug1", "/go_to_point"}
    board.take("/go_to_point", 1, 1, taken={}, written={},
               served=[("/go_to_point_switch", 9)])
    first = dict(taken={}, written={}, called=[("/go_to_point_switch", 9)])
    board.take("/bug1", 2, 1, **first)
    board.take("/bug1", 2, 1, **first)
    assert board.busy(nodes) is None
    # out of order (two threads of one process report) is not twice: both count
    board.take("/bug1", 2, 3, taken={}, written={}, called=[("/go_to_point_switch", 11)])
    board.take("/bug1", 2, 2, taken={}, written={}, called=[("/go_to_point_switch", 10)])
    board.take("/go_to_point", 1, 2, taken={}, written={},
               served=[("/go_to_point_switch", 10)])
    assert board.busy(nodes) == ("/bug1", "its call to /go_to_point_switch not yet answered "
                                          "by /go_to_point")
    board.take("/go_to_point", 1, 3, taken={}, written={},
               served=[("/go_to_point_switch", 11)])
    assert board.busy(nodes) is None


def test_a_call_to_a_server_that_does_not_report_ended_with_its_answer():
    board, _ = make({"/gazebo/get_model_state": SIM})
    board.take("/ctl", 1, 1, taken={}, written={}, called=[("/gazebo/get_model_state", 9),
                                                          ("/nobody", 10)])
    assert board.busy({"/ctl"}) is None


def test_a_node_stepped_past_is_skipped_until_its_reports_add_up_again():
    board, own = make()
    own.written[("/scan", "/ctl", 5)] = 1
    board.take("/ctl", 1, 1, taken={}, written={})
    board.silent.add("/ctl")
    assert board.busy({"/ctl"}) is None
    board.take("/ctl", 1, 2, taken={}, written={})           # still behind: still skipped
    assert board.busy({"/ctl"}) is None and "/ctl" in board.silent
    board.take("/ctl", 1, 3, taken={("/scan", SIM, 5): 1}, written={})
    assert board.busy({"/ctl"}) is None and "/ctl" not in board.silent
    own.written[("/scan", "/ctl", 5)] = 2
    assert board.busy({"/ctl"}) is not None                  # waited for again


def test_a_report_cannot_make_the_simulator_wait_for_what_no_connection_brings():
    board, own = make(inbound={("/cmd_vel", "/ctl", 6)})
    board.take("/fake", 1, 1, taken={}, written={("/cmd_vel", SIM, 1): 10 ** 9})
    board.take("/ctl", 2, 1, taken={}, written={("/cmd_vel", SIM, 6): 1})
    own.taken[("/cmd_vel", "/ctl", 6)] = 1
    assert board.busy({"/fake", "/ctl"}) is None


def test_wait_returns_as_soon_as_the_report_comes():
    board, own = make()
    own.written[("/scan", "/ctl", 5)] = 1
    threading.Timer(0.05, board.take, args=("/ctl", 1, 1),
                    kwargs=dict(taken={("/scan", SIM, 5): 1}, written={})).start()
    start = time.monotonic()
    assert board.wait({"/ctl"}, start + 5.0) is None
    assert time.monotonic() - start < 0.5
    own.written[("/scan", "/ctl", 5)] = 2
    assert board.wait({"/ctl"}, time.monotonic() + 0.1) == \
        ("/ctl", "/scan not taken in: 1 of 2")


def test_a_tick_that_wakes_no_sleeper_is_not_waited_for():
    board, own = make()
    own.written[("/clock", "/ctl", 5)] = 4
    board.take("/ctl", 1, 1, taken={("/clock", SIM, 5): 3}, written={}, next_wake=0)
    board.sent_clock({"/ctl"}, 2000)
    assert board.busy({"/ctl"}) is None          # no thread sleeps on sim time
    board.take("/ctl", 1, 2, taken={("/clock", SIM, 5): 3}, written={}, next_wake=2050)
    assert board.busy({"/ctl"}) is None          # its loop sleeps until 2050: not yet
    board.sent_clock({"/ctl"}, 2050)
    assert board.busy({"/ctl"}) == ("/ctl", "/clock not taken in: 3 of 4")   # its tick
    board.take("/ctl", 1, 3, taken={("/clock", SIM, 5): 4}, written={}, next_wake=2100)
    assert board.busy({"/ctl"}) is None


def test_a_call_the_simulator_answered_waits_for_its_clients_word():
    """The Gym environment publishes a command, then calls /gazebo/unpause_physics: the
    simulator steps on only once the client's report says it got the answer, and so counts
    the command written before."""
    answered = [("/gazebo/unpause_physics", 7, "/env")]
    own = Own()
    board = Board(SIM, own, own_inbound=lambda: {("/cmd_vel", "/env", 6)},
                  own_answered=lambda: [answered.pop()] if answered else [])
    board.take("/env", 1, 1, taken={}, written={})
    assert board.pending_calls({"/env"})
    assert board.busy({"/env"})[0] == "/env"
    board.take("/env", 1, 2, taken={}, written={("/cmd_vel", SIM, 6): 1},
               called=[("/gazebo/unpause_physics", 7)])
    assert board.busy({"/env"}) == ("/env", "/cmd_vel not read by the simulator yet")
    own.taken[("/cmd_vel", "/env", 6)] = 1
    assert board.busy({"/env"}) is None and not board.pending_calls({"/env"})


def test_a_closed_connection_is_not_waited_for():
    """The batch runner's next controller, under the same node name on a reused simulator:
    the scans its predecessor's connection got are not asked of it."""
    live = {("/scan", "/ctl", 9)}
    own = Own()
    board = Board(SIM, own, own_outbound=lambda: live)
    own.written[("/scan", "/ctl", 5)] = 101                  # the ended process's connection
    own.written[("/scan", "/ctl", 9)] = 1
    board.take("/ctl", 2, 1, taken={("/scan", SIM, 9): 1}, written={})
    assert board.busy({"/ctl"}) is None


def test_a_watchers_calls_are_not_waited_for():
    answered = [("/gazebo/get_model_state", 7, "/recorder")]
    board = Board(SIM, Own(), own_answered=lambda: [answered.pop()] if answered else [])
    board.take("/recorder", 1, 1, taken={}, written={}, watcher=True)
    assert not board.pending_calls({"/recorder"})
    assert board.busy({"/recorder"}) is None


def test_what_a_controller_sends_a_watcher_is_not_waited_for():
    # a watcher reports no more once it has said so (rospy_hooks.watch_only): its counts of
    # what a controller sent it (the bench's own /cmd_vel counter) never catch up
    board, _ = make()
    board.take("/bench", 1, 1, taken={}, written={}, watcher=True)
    board.take("/ctl", 2, 1, taken={}, written={("/cmd_vel", "/bench", 8): 5})
    assert board.busy({"/ctl", "/bench"}) is None


def test_a_call_reported_before_the_simulator_noted_its_answer_is_not_waited_for_again():
    """The simulator notes that it answered a call once its handler has returned, after the
    reply is written: the client may get the answer and report the call before that, and the
    board may be asked in between. The call is then matched when the note comes, and the
    client, whose word on it is in, is not waited for (it was, until lockstep_timeout: 30 s
    in series_runs, whose node spawns m2wr)."""
    noted = []
    own = Own()
    board = Board(SIM, own, service_provider={"/gazebo/spawn_urdf_model": SIM}.get,
                  own_answered=lambda: [noted.pop()] if noted else [])
    board.take("/tool", 1, 1, taken={}, written={},
               called=[("/gazebo/spawn_urdf_model", 7)])
    assert board.busy({"/tool"}) is None                  # asked before the note
    noted.append(("/gazebo/spawn_urdf_model", 7, "/tool"))
    assert board.busy({"/tool"}) is None                  # the note matches the word
    assert not board.pending_calls({"/tool"})


def test_a_parked_connection_is_not_waited_for_until_a_report_says_it_is_read_again():
    """A controller asleep in its scan callback parks that connection: the scans written
    meanwhile wait in its socket, and the simulator does not wait for them."""
    board, own = make()
    own.written[("/scan", "/ctl", 5)] = 3
    board.take("/ctl", 1, 1, taken={("/scan", SIM, 5): 2}, written={},
               parked=[("/scan", SIM, 5)])
    assert board.busy({"/ctl"}) is None
    board.take("/ctl", 1, 2, taken={}, written={})                 # back at work, then done
    assert board.busy({"/ctl"})[0] == "/ctl"
    board.take("/ctl", 1, 3, taken={("/scan", SIM, 5): 3}, written={})
    assert board.busy({"/ctl"}) is None
