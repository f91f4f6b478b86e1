"""The simulator's side of the ticks sent with word of what they follow
(lockstep/tick_word.py): an offered node is told HOLD once per connection, with the /clock
ticks written before it; from then on each tick goes there, not on /clock, for the
connection's life, with the counts of the connections open now (not those of an earlier
process under the same node name: the grader's next student on a reused world)."""
import rospy
from lockstep_msgs.msg import LockstepExpect

from pybullet_gazebo.ros.lockstep import EXPECT_TOPIC
from pybullet_gazebo.ros.lockstep.tick_word import TickWord

NODE, SCAN = "/follow_wall", "/m2wr/laser/scan"


class Connection:
    def __init__(self, node, port):
        self.endpoint_id, self.port, self.done = node, port, False


class Publisher:
    """The ticks' publisher: what publish() wrote to which connection."""

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


def setup():
    tracker = Tracker()
    publisher = Publisher(tracker)
    live = set()
    word = TickWord(tracker, publisher=publisher, live_outbound=lambda: live,
                    port_of=lambda connection: connection.port)
    return word, tracker, publisher, live


def test_an_offered_node_is_told_hold_then_gets_its_ticks_with_the_live_counts():
    word, tracker, publisher, live = setup()
    clock, expect = Connection(NODE, 5001), Connection(NODE, 5002)
    publisher.connections.append(expect)
    tracker.wrote("/clock", NODE, 5001, 3)
    tracker.wrote(SCAN, NODE, 4000, 40)            # an earlier /follow_wall's connection
    tracker.wrote(SCAN, NODE, 5003, 2)
    live.update({("/clock", NODE, 5001), (SCAN, NODE, 5003), (EXPECT_TOPIC, NODE, 5002)})
    assert not word.tick(clock, rospy.Time(1, 0))    # not offered: it goes on /clock
    assert publisher.sent == [] and not word.holding(NODE)
    word.offer({NODE})
    assert word.tick(clock, rospy.Time(1, 50000000))
    (_, hold), (_, tick) = publisher.sent
    assert (hold.kind, hold.clock_port, hold.clock_count) == (LockstepExpect.HOLD, 5001, 3)
    assert tick.kind == LockstepExpect.TICK and tick.clock == rospy.Time(1, 50000000)
    assert list(zip(tick.topics, tick.ports, tick.counts)) == [(SCAN, 5003, 2)]
    assert word.holding(NODE)
    word.offer(())                                   # no longer offered: still told
    assert word.tick(clock, rospy.Time(1, 100000000))
    assert [m.kind for _, m in publisher.sent] == [LockstepExpect.HOLD, LockstepExpect.TICK,
                                                   LockstepExpect.TICK]


def test_the_next_process_under_the_same_name_is_told_hold_on_its_own_connection():
    word, tracker, publisher, live = setup()
    word.offer({NODE})
    first = Connection(NODE, 5002)
    publisher.connections.append(first)
    assert word.tick(Connection(NODE, 5001), rospy.Time(1, 0))
    first.done = True
    assert not word.holding(NODE)
    publisher.connections[:] = [Connection(NODE, 6002)]
    assert word.tick(Connection(NODE, 6001), rospy.Time(2, 0))
    connection, hold = publisher.sent[-2]
    assert connection.port == 6002 and hold.kind == LockstepExpect.HOLD
    assert hold.clock_port == 6001 and hold.clock_count == 0


def test_a_hold_that_finds_the_socket_full_is_tried_again_and_the_tick_goes_on_clock():
    word, tracker, publisher, live = setup()
    word.offer({NODE})
    expect = Connection(NODE, 5002)
    publisher.connections.append(expect)
    publisher.publish = lambda msg, share: None      # the socket is full: nothing written
    assert not word.tick(Connection(NODE, 5001), rospy.Time(1, 0))
    assert not word.holding(NODE)
