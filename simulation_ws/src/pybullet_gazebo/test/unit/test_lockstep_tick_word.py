"""The simulator's word on the /clock ticks (lockstep/tick_word.py): HOLD once per connection
of an offered node, then a TICK word before every tick for the connection's life, naming the
tick's number and the counts of the connections open now (not those of an earlier process
under the same node name: the grader's next student on a reused world); holding() only once
the node's report counts the HOLD."""
from lockstep_msgs.msg import LockstepExpect

from pybullet_gazebo.ros.lockstep import EXPECT_TOPIC
from pybullet_gazebo.ros.lockstep.board import NodeReport
from pybullet_gazebo.ros.lockstep.tick_word import TickWord

SIM, NODE, SCAN = "/gazebo", "/follow_wall", "/m2wr/laser/scan"


class Connection:
    def __init__(self, node, port):
        self.endpoint_id, self.port, self.done = node, port, False


class Publisher:
    """The words' publisher: what publish() wrote to which connection."""

    def __init__(self, tracker):
        self.tracker = tracker
        self.connections = []
        self.sent = []
        impl = type("Impl", (), {})()
        impl.connections = self.connections
        self.publisher = type("Pub", (), {"impl": impl})()

    def publish(self, msg, share):
        for connection in self.connections:
            if share(connection):
                self.sent.append((connection, msg))
                self.tracker.wrote(EXPECT_TOPIC, connection.endpoint_id, connection.port)


class Tracker:
    def __init__(self):
        self.written = {}

    def wrote(self, topic, peer, port, n=1):
        key = (topic, peer, port)
        self.written[key] = self.written.get(key, 0) + n

    def written_to(self, peer):
        return {(t, port): n for (t, p, port), n in self.written.items() if p == peer}


class Board:
    def __init__(self):
        self.reports = {}

    def report_of(self, node):
        return self.reports.get(node)


def setup():
    tracker, board = Tracker(), Board()
    publisher = Publisher(tracker)
    live = set()
    word = TickWord(SIM, tracker, board, publisher=publisher, live_outbound=lambda: live,
                    port_of=lambda connection: connection.port)
    return word, tracker, board, publisher, live


def test_an_offered_node_is_told_hold_then_a_word_before_each_tick_with_live_counts():
    word, tracker, board, publisher, live = setup()
    clock, expect = Connection(NODE, 5001), Connection(NODE, 5002)
    publisher.connections.append(expect)
    tracker.wrote("/clock", NODE, 5001, 3)
    tracker.wrote(SCAN, NODE, 4000, 40)            # an earlier /follow_wall's connection
    tracker.wrote(SCAN, NODE, 5003, 2)
    live.update({("/clock", NODE, 5001), (SCAN, NODE, 5003), (EXPECT_TOPIC, NODE, 5002)})
    word.before_tick(clock)                          # not offered: nothing said
    assert publisher.sent == []
    word.offer({NODE})
    word.before_tick(clock)
    (_, hold), (_, tick) = publisher.sent
    assert (hold.kind, hold.clock_port, hold.clock_count) == (LockstepExpect.HOLD, 5001, 3)
    assert (tick.kind, tick.clock_port, tick.clock_count) == (LockstepExpect.TICK, 5001, 4)
    assert list(zip(tick.topics, tick.ports, tick.counts)) == [(SCAN, 5003, 2)]
    assert not word.holding(NODE)                  # no report counts the HOLD yet
    report = board.reports[NODE] = NodeReport()
    report.taken[(EXPECT_TOPIC, SIM, 5002)] = 1
    assert word.holding(NODE)
    word.offer(())                                   # no longer offered: still told
    tracker.wrote("/clock", NODE, 5001)
    word.before_tick(clock)
    assert [m.kind for _, m in publisher.sent] == [LockstepExpect.HOLD, LockstepExpect.TICK,
                                                   LockstepExpect.TICK]
    assert publisher.sent[-1][1].clock_count == 5


def test_the_next_process_under_the_same_name_is_told_hold_on_its_own_connection():
    word, tracker, board, publisher, live = setup()
    word.offer({NODE})
    first = Connection(NODE, 5002)
    publisher.connections.append(first)
    word.before_tick(Connection(NODE, 5001))
    first.done = True
    publisher.connections[:] = [Connection(NODE, 6002)]
    board.reports[NODE] = NodeReport()
    board.reports[NODE].taken[(EXPECT_TOPIC, SIM, 5002)] = 1     # the first one's count
    assert not word.holding(NODE)
    word.before_tick(Connection(NODE, 6001))
    connection, hold = publisher.sent[-2]
    assert connection.port == 6002 and hold.kind == LockstepExpect.HOLD
    assert hold.clock_port == 6001 and hold.clock_count == 0
