"""The simulator's word on the /clock ticks it sends a controller (lockstep_msgs/LockstepExpect
on /lockstep/expect; the controller's side is tick_hold.py).

A rospy.Rate loop must get its tick only after the readings of that time went through its
callbacks. Without word, the simulator waits for the controller's report of the readings and
then sends the tick: two round trips per tick, against one for a program that answers in its
scan callback. With word, it sends the readings, then a TICK word naming the counts the
process must have taken in, then the tick, all at once; the process sets the tick when the
counts are reached. The program sees the same readings at the same sim time.

Who gets word: a lone loop node that reports (`offer`), where it spares the round trip. Once
a connection has been told HOLD, every tick to its process comes with word for as long as the
connection lives, whoever the loop nodes are then: the process holds each tick until its word
comes. `holding(node)`: the node's report counts the HOLD, so its ticks wait for their word;
until then the simulator hands ticks on as before (after the readings' report).
"""
from lockstep_msgs.msg import LockstepExpect

from pybullet_gazebo.ros.direct_publisher import DirectPublisher
from pybullet_gazebo.ros.lockstep import EXPECT_TOPIC, rospy_hooks

CLOCK = "/clock"
_NOT_NAMED = (CLOCK, EXPECT_TOPIC)       # topics a word's counts leave out


class _Told:
    """A word connection told HOLD: the /clock connection it is about and the words written on
    it up to the HOLD, which the node's report must count."""

    def __init__(self, connection, clock_port, hold_number):
        self.connection = connection
        self.clock_port = clock_port
        self.hold_number = hold_number


class TickWord:
    def __init__(self, own_name, tracker, board, publisher=None,
                 live_outbound=rospy_hooks.outbound_connections, port_of=rospy_hooks.peer_port):
        """`tracker`: the simulator's own Tracker (what it wrote to whom); `board`: the
        controllers' reports (board.py); `publisher`: of the words (a DirectPublisher on
        /lockstep/expect by default); `live_outbound()`: {(topic, subscriber, port)} of the
        simulator's publisher connections open now; `port_of(connection)`: the port of its
        subscriber's end."""
        self.publisher = publisher or DirectPublisher(EXPECT_TOPIC, LockstepExpect)
        self._live_outbound = live_outbound
        self._port_of = port_of
        self.offered = frozenset()          # nodes that get word from their next tick on
        self._own = own_name
        self._tracker = tracker
        self._board = board
        self._told = {}                     # node -> _Told

    def offer(self, nodes):
        """From now on, `nodes` are told HOLD at their next tick (see the module docstring)."""
        self.offered = frozenset(nodes)

    def before_tick(self, clock_connection):
        """A /clock tick is about to be written on `clock_connection`: its word first, if its
        node has been told HOLD or is offered it."""
        node = clock_connection.endpoint_id
        told = self._told.get(node)
        if told is not None and told.connection.done:
            del self._told[node]                # (its process left, or the simulator's end)
            told = None
        if told is None and node not in self.offered:
            return
        connection = self._connection_to(node)
        if connection is None:
            return
        clock_port = self._port_of(clock_connection)
        written = self._tracker.written_to(node)
        if told is None or told.connection is not connection or told.clock_port != clock_port:
            self._write(connection, LockstepExpect(
                kind=LockstepExpect.HOLD, clock_port=clock_port,
                clock_count=written.get((CLOCK, clock_port), 0)))
            port = self._port_of(connection)
            told = self._told[node] = _Told(connection, clock_port,
                                            self._tracker.written_to(node).get(
                                                (EXPECT_TOPIC, port), 0))
        word = LockstepExpect(kind=LockstepExpect.TICK, clock_port=clock_port,
                              clock_count=written.get((CLOCK, clock_port), 0) + 1)
        # only the connections open now: the simulator's counts keep those of an earlier
        # process under the same node name (the grader's next student on a reused world),
        # which this process will never take anything in on
        live = self._live_outbound()
        for (topic, port), count in written.items():
            if topic not in _NOT_NAMED and (topic, node, port) in live:
                word.topics.append(topic)
                word.ports.append(port)
                word.counts.append(count)
        self._write(connection, word)

    def holding(self, node):
        """Whether `node`'s process holds its ticks for their word: its report counts the
        HOLD it was told on a connection that is still open."""
        told = self._told.get(node)
        if told is None or told.connection.done:
            return False
        report = self._board.report_of(node)
        if report is None:
            return False
        port = self._port_of(told.connection)
        return report.taken.get((EXPECT_TOPIC, self._own, port), 0) >= told.hold_number

    def _connection_to(self, node):
        impl = self.publisher.publisher.impl
        if impl is None:
            return None
        for connection in list(impl.connections):
            if connection.endpoint_id == node:
                return connection
        return None

    def _write(self, connection, msg):
        self.publisher.publish(msg, lambda c: c is connection)

    def close(self):
        self.publisher.publisher.unregister()
