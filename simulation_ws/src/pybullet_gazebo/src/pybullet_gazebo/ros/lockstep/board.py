"""The simulator's side of the handshake: the latest word of each controller, and whether
they are all done with what the simulator sent them.

A controller's process reports each time it becomes done (tracker.py), with what it has taken
in and written out per connection, totals since the connection opened. Its report is about
everything the simulator sent it once it counts, on every connection from the simulator, as
many messages as the simulator wrote there; the simulator has read all it wrote once its own
counts reach the report's. Between two controllers that both report, the same holds for their
topics, and for a service call: a call one reports made (named by the call's connection) is
done with once its server has reported it answered, since the server may have changed its
mind (bug 2 switching go to point on) and its loop must look again first. A call to a server
that does not report (a roscpp node) ended when its answer came. A call to the simulator's own
services (unpause, set_model_state, a state read) is done with once its client has reported
it got the answer: whatever the client did meanwhile (a command published before the
unpause) is in that report.

All counts, so a report that comes late, twice or out of order never says too much: a
controller is done exactly when its latest report is about everything, whatever the machine's
load. The simulator's own counts come from its own Tracker (rospy_hooks.install(report=False)).
"""
import collections
import threading
import time

from pybullet_gazebo.ros.lockstep import CLOCK_TOPIC as CLOCK, EXPECT_TOPIC

KEEP_CALLS = 4096          # unmatched service-call records kept (a client or server that died)
KEEP_SEQS = 4096           # report numbers remembered per process, to know one sent twice


class NodeReport:
    def __init__(self):
        self.pid = 0
        self.seq = 0
        self.reports = 0
        self.taken = {}              # (topic, publisher, port) -> count
        self.written = {}            # (topic, subscriber, port) -> count
        self.next_wake = 0           # [ns sim] its earliest sleeper's wake-up, 0: none
        self.watcher = False         # it said it only watches: never waited for
        self.parked = frozenset()    # (topic, publisher, port) read by a thread asleep in a
                                     # callback: not waited for (tracker.py)
        self._seqs = collections.deque(maxlen=KEEP_SEQS)     # the latest report numbers
        self._seen = set()

    def merge(self, pid, seq, taken, written, next_wake=0, watcher=False, parked=()):
        """Totals only grow: a report older than one already merged changes nothing. False
        for a report already taken (the same process and number): its service calls,
        which are news once, were counted the first time."""
        if pid != self.pid:          # a new process under the node's name: start over
            self.pid, self.seq, self.taken, self.written = pid, 0, {}, {}
            self.parked = frozenset()
            self._seqs.clear()
            self._seen.clear()
        if seq in self._seen:
            return False
        if len(self._seqs) == self._seqs.maxlen:
            self._seen.discard(self._seqs[0])
        self._seqs.append(seq)
        self._seen.add(seq)
        if seq >= self.seq:
            self.next_wake = next_wake
            self.parked = frozenset(parked)
        self.watcher = self.watcher or watcher
        self.seq = max(self.seq, seq)
        self.reports += 1
        for key, count in taken.items():
            if count > self.taken.get(key, 0):
                self.taken[key] = count
        for key, count in written.items():
            if count > self.written.get(key, 0):
                self.written[key] = count
        return True


class Board:
    def __init__(self, own_name, own_counts, service_provider=lambda service: None,
                 own_inbound=None, own_answered=lambda: (), own_outbound=None, inbox=None):
        """`own_name`: the simulator's node name; `own_counts()`: (taken, written) of the
        simulator's own connections, keyed as in a report; `service_provider(name)`: the
        node that offers a service, or None; `own_inbound()`: the keys of the simulator's
        subscriber connections now (default: those it has taken something from); `inbox`:
        the Inbox (inbox.py) through which the waiting thread reads reports and commands
        itself (None: they come from rospy's threads, which notify)."""
        self.own_name = own_name
        self.inbox = inbox
        self.own_counts = own_counts
        self.own_inbound = own_inbound or (lambda: set(own_counts()[0]))
        # the connections it writes to now: a closed one (a controller that ended, the batch
        # runner's next one under the same name) is not waited for
        self.own_outbound = own_outbound or (lambda: set(own_counts()[1]))
        self.own_answered = own_answered     # () -> [(service, port, client)] answered since
        self._answered = collections.OrderedDict()     # (service, port) -> its client
        self.service_provider = service_provider
        self._reports = {}                             # node -> NodeReport
        self._called = collections.OrderedDict()       # (service, port) -> client node
        self._served = collections.OrderedDict()       # (service, port) -> server node
        self._changed = threading.Condition()
        self._version = 0            # counts changes, so that a wait misses none
        self.silent = set()          # nodes stepped past at a time-out, until they add up
        self.clock_sent = {}         # node -> [ns sim] the last /clock tick sent to it

    # --- what comes in ----------------------------------------------------------------------
    def take(self, node, pid, seq, taken, written, served=(), called=(), next_wake=0,
             watcher=False, parked=()):
        """A report from `node` (its connection's callerid, never a field of the report)."""
        with self._changed:
            if not self._reports.setdefault(node, NodeReport()).merge(
                    pid, seq, taken, written, next_wake, watcher, parked):
                return              # sent twice: a call it names would be waited for again
            for key in served:
                if self._called.pop(key, None) is None:
                    self._remember(self._served, key, node)
            for key in called:
                if self._served.pop(key, None) is None and \
                        self._answered.pop(key, None) is None:
                    self._remember(self._called, key, node)
            self._version += 1
            self._changed.notify_all()
        if self.inbox is not None:
            self.inbox.wake()

    @staticmethod
    def _remember(records, key, node):
        records[key] = node
        while len(records) > KEEP_CALLS:
            records.popitem(last=False)

    def sent_clock(self, nodes, stamp_ns):
        """The simulator sent `nodes` the /clock tick of `stamp_ns` [ns sim]."""
        with self._changed:
            for node in nodes:
                self.clock_sent[node] = stamp_ns

    def notify(self):
        """The simulator's own counts changed (it read a command)."""
        with self._changed:
            self._version += 1
            self._changed.notify_all()
        if self.inbox is not None:
            self.inbox.wake()

    def forget(self, node):
        """`node` left: its report no longer counts (its connections are gone too)."""
        with self._changed:
            self._reports.pop(node, None)
            self.silent.discard(node)

    def watchers(self):
        """The nodes that said they only watch."""
        with self._changed:
            return {node for node, report in self._reports.items() if report.watcher}

    @property
    def version(self):
        """Grows with every report taken and every change of the simulator's own counts."""
        return self._version

    def report_of(self, node):
        return self._reports.get(node)

    # --- the question -----------------------------------------------------------------------
    def busy(self, nodes):
        """The first of `nodes` (reporting controllers) not yet done with what it was sent,
        with why, as (node, why); None when all are done. A node stepped past at a time-out
        (`silent`) is skipped until its reports add up again."""
        if self.inbox is not None:
            self.inbox.poll()            # what has come is read first
        taken_own, written_own = self.own_counts()
        inbound = self.own_inbound()
        outbound = self.own_outbound()
        written_own = {key: n for key, n in written_own.items() if key in outbound}
        with self._changed:
            self._absorb_answered()
            for node in nodes:
                why = self._not_done(node, nodes, taken_own, written_own, inbound)
                if node in self.silent:
                    if why is None:
                        self.silent.discard(node)     # it caught up: waited for again
                    continue
                if why is not None:
                    return why
            for (service, port), client in list(self._answered.items()):
                if client in self.silent or self._watcher(client):
                    self._answered.pop((service, port), None)
                elif client in nodes:   # (kept for a client that is not a controller yet)
                    return client, "no word yet since the simulator answered its %s" % service
            for (service, port), client in list(self._called.items()):
                server = self.service_provider(service)
                if server == self.own_name:
                    # the simulator's own service: its handler notes the answer after the
                    # reply is written, so the client's word may come first; the note then
                    # finds the call here (_absorb_answered) and nothing is waited for
                    continue
                if server is None or server not in self._reports or server in self.silent \
                        or client not in nodes or client in self.silent:
                    self._called.pop((service, port), None)  # ended when its answer came
                    continue
                return client, "its call to %s not yet answered by %s" % (service, server)
        return None

    def _absorb_answered(self):
        """The calls the simulator answered: each waits for its client's report of it."""
        for service, port, client in self.own_answered():
            if self._called.pop((service, port), None) is None:
                self._remember(self._answered, (service, port), client)

    def pending_calls(self, nodes):
        """Whether a call of one of `nodes` to the simulator awaits its client's report."""
        with self._changed:
            self._absorb_answered()
            return any(client in nodes and not self._watcher(client)
                       for client in self._answered.values())

    def _watcher(self, node):
        report = self._reports.get(node)
        return report is not None and report.watcher

    def _not_done(self, node, nodes, taken_own, written_own, inbound):
        """(node, why) if `node`'s report does not yet cover what it was sent, else None."""
        me = self.own_name
        report = self._reports.get(node)
        if report is None:
            return node, "no report yet"
        if report.watcher:
            return None
        # a tick that reaches no sleeper's wake-up wakes nothing: rospy only takes its time
        # (the next one that does is waited for, with every tick before it)
        skip_clock = report.next_wake == 0 or report.next_wake > self.clock_sent.get(node, 0)
        for (topic, peer, port), count in written_own.items():
            # (ticks also go with word of what they follow, lockstep/tick_word.py)
            if peer == node and report.taken.get((topic, me, port), 0) < count \
                    and not (skip_clock and topic in (CLOCK, EXPECT_TOPIC)) \
                    and (topic, me, port) not in report.parked:
                return node, "%s not taken in: %d of %d" % (
                    topic, report.taken.get((topic, me, port), 0), count)
        for (topic, peer, port), count in report.written.items():
            if peer == me:
                # only on a connection the simulator has: a report cannot make it wait
                # for messages that no connection of its own will bring
                if (topic, node, port) in inbound and \
                        taken_own.get((topic, node, port), 0) < count:
                    return node, "%s not read by the simulator yet" % topic
            elif peer in nodes and peer not in self.silent and not self._watcher(peer) \
                    and topic != EXPECT_TOPIC:
                # (a watcher is never waited for, and reports no more once it said so; ticks
                # are the simulator's to send: a controller's own, which its peers ignore
                # (rospy_hooks), are nothing to wait for)
                other = self._reports.get(peer)
                if other is not None and other.taken.get((topic, node, port), 0) < count:
                    return peer, "%s from %s not taken in" % (topic, node)
        return None

    def wait(self, nodes, deadline, interrupted=lambda: False):
        """Waits until busy(nodes) is None, `deadline` (time.monotonic) passes or
        interrupted(); returns what was still busy, or None."""
        while True:
            version = self._version
            busy = self.busy(nodes)
            if busy is None or interrupted():
                return busy
            left = deadline - time.monotonic()
            if left <= 0:
                return busy
            if self.inbox is not None:
                if self._version == version:        # nothing came since the look
                    self.inbox.poll(min(left, 0.05))    # reads what comes (or is woken)
                continue
            with self._changed:
                if self._version == version:
                    self._changed.wait(min(left, 0.05))
