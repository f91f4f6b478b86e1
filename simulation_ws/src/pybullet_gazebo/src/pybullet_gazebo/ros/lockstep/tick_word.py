"""The simulator's side of the ticks it sends a controller with word of what they follow
(lockstep_msgs/LockstepExpect on /lockstep/expect; the controller's side is tick_hold.py).

A rospy.Rate loop must get its tick only after the readings of that time went through its
callbacks. Sent on /clock, the tick had to wait for the controller's report of the readings:
two round trips per tick, against one for a program that answers in its scan callback. Sent
here, with the counts of what the simulator wrote to the process so far, it goes out with the
readings: the process sets the time once those counts are taken in, and the program sees the
same readings at the same sim time.

Who: a lone loop node that reports (`offer`). One that answers in its callbacks has no loop
to wake, but its tick sent on /clock would still wait for its report of the readings, and
physics would go step by step meanwhile. A node is told HOLD once on its connection (`tick`); from then on every tick to its
process goes here, none on /clock, for as long as the connection lives, whoever the loop nodes
are then. `holding(node)`: its ticks go here, so one may go out with the readings.
"""
from lockstep_msgs.msg import LockstepExpect

from pybullet_gazebo.ros.direct_publisher import DirectPublisher
from pybullet_gazebo.ros.lockstep import CLOCK_TOPIC as CLOCK, EXPECT_TOPIC, rospy_hooks

_NOT_NAMED = (CLOCK, EXPECT_TOPIC)       # topics a tick's counts leave out


class TickWord:
    def __init__(self, tracker, publisher=None,
                 live_outbound=rospy_hooks.outbound_connections, port_of=rospy_hooks.peer_port):
        """`tracker`: the simulator's own Tracker (what it wrote to whom); `publisher`: of the
        ticks (a DirectPublisher on /lockstep/expect by default); `live_outbound()`:
        {(topic, subscriber, port)} of the simulator's publisher connections open now;
        `port_of(connection)`: the port of its subscriber's end."""
        self.publisher = publisher or DirectPublisher(EXPECT_TOPIC, LockstepExpect)
        self.offered = frozenset()          # nodes told HOLD at their next tick
        self._tracker = tracker
        self._live_outbound = live_outbound
        self._port_of = port_of
        self._told = {}                     # node -> its connection here, told HOLD

    def offer(self, nodes):
        """From now on, `nodes` are told HOLD at their next tick (see the module docstring)."""
        self.offered = frozenset(nodes)

    def tick(self, clock_connection, stamp):
        """The tick at `stamp` (rospy Time) is due on `clock_connection`, a /clock subscriber:
        True when it went here instead (its node has been told HOLD, now or before)."""
        node = clock_connection.endpoint_id
        connection = self._told.get(node)
        if connection is not None and connection.done:
            del self._told[node]                # (its process left, or the simulator's end)
            connection = None
        if connection is None:
            if node not in self.offered:
                return False
            connection = self._connection_to(node)
            if connection is None or not self._hold(node, connection, clock_connection):
                return False
        word = LockstepExpect(kind=LockstepExpect.TICK, clock=stamp)
        # only the connections open now: the simulator's counts keep those of an earlier
        # process under the same node name (the grader's next student on a reused world),
        # which this process will never take anything in on
        live = self._live_outbound()
        for (topic, port), count in self._tracker.written_to(node).items():
            if topic not in _NOT_NAMED and (topic, node, port) in live:
                word.topics.append(topic)
                word.ports.append(port)
                word.counts.append(count)
        self._write(connection, word)
        return True

    def _hold(self, node, connection, clock_connection):
        """Tells `node` HOLD; True once written (a full socket skips it: tried again)."""
        clock_port = self._port_of(clock_connection)
        key = (EXPECT_TOPIC, self._port_of(connection))
        before = self._tracker.written_to(node)
        self._write(connection, LockstepExpect(kind=LockstepExpect.HOLD, clock_port=clock_port,
                                               clock_count=before.get((CLOCK, clock_port), 0)))
        if self._tracker.written_to(node).get(key, 0) <= before.get(key, 0):
            return False
        self._told[node] = connection
        return True

    def holding(self, node):
        """Whether `node`'s ticks go here (so one may go out with the readings)."""
        connection = self._told.get(node)
        return connection is not None and not connection.done

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
