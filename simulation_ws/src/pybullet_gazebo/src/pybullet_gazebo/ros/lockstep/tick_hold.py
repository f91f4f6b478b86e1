"""A controller's side of the simulator's word on its /clock ticks (lockstep_msgs/
LockstepExpect on /lockstep/expect): a tick is set only once the process has taken in the
readings the simulator sent before it.

Why: a rospy.Rate loop acts on what its callbacks stored. Its tick must therefore come after
the readings of that time have gone through their callbacks; the readings and the tick travel
on different connections, read by different threads, so the order they are written in says
nothing about the order they are taken in. Without this word the simulator had to wait for
the process's report of the readings before it sent the tick: a second round trip per tick,
which a program that answers in its scan callback does not pay. With it, the simulator sends
the readings, its word and the tick together, and the process holds the tick in rospy's /clock
thread until the counts the word names are reached; the program sees the same thing at the
same sim time, and the process reports once, when its loop sleeps again.

The simulator says HOLD once on a connection before it relies on the hold (it waits for the
report that counts it): every tick on this process's /clock connection after the first N
comes after a TICK word naming its number there. Ticks are matched to their word by that
number, so neither a tick sent before HOLD nor the ticks rospy's /clock subscriber drops
(queue_size 1) can take another's word. A tick whose word does not come within HOLD_CAP (a
simulator that went away) is set anyway and counted in `late`.
"""
import collections
import threading

HOLD, TICK = 1, 2           # lockstep_msgs/LockstepExpect's kinds
HOLD_CAP = 1.0              # [s] wall: the longest a tick is held for word that does not come


class TickHold:
    def __init__(self, taken):
        """`taken()`: {(topic, publisher, port): messages taken in} of this process now (the
        Tracker's counts, those its queue_size dropped included)."""
        self._taken = taken
        self._changed = threading.Condition()
        self._changed._lockstep_untracked = True      # (its waits are not the program's)
        self._connection = None      # the simulator's connection that said HOLD
        self._simulator = None       # ... that simulator's node name
        self._clock_port = None      # ... the /clock connection it is about (this end's port)
        self._free = 0               # ... and the ticks on it before the hold
        self._words = collections.deque()    # [(tick number, {(topic, port): count})]
        self.late = 0                # ticks set without their word, after HOLD_CAP

    def heard(self, kind, clock_port, clock_count, counts, simulator, connection):
        """A LockstepExpect from `simulator` on `connection` (rospy's, for its liveness)."""
        with self._changed:
            if kind == HOLD:
                self._connection, self._simulator = connection, simulator
                self._clock_port, self._free = clock_port, clock_count
                self._words.clear()
            elif kind == TICK and connection is self._connection:
                self._words.append((clock_count, counts))
            self._changed.notify_all()

    def active(self):
        """A simulator said HOLD (the /clock callback then asks wait_for_word tick by tick)."""
        return self._connection is not None

    def taken_changed(self):
        """A callback returned: the counts grew."""
        with self._changed:
            if self._connection is not None:
                self._changed.notify_all()

    def wait_for_word(self, number, publisher, port, wall_clock):
        """Returns once tick `number` (1: the first) on the /clock connection from `publisher`
        whose end here has `port` may be set: at once unless a live simulator said HOLD about
        that connection and the tick comes after the ticks it left free; else when the counts
        of its word are taken in. `wall_clock()`: for HOLD_CAP."""
        with self._changed:
            deadline = None
            while True:
                connection = self._connection
                if connection is None or getattr(connection, "done", False) or \
                        publisher != self._simulator or port != self._clock_port or \
                        number <= self._free:
                    return
                words = self._words
                # words of earlier ticks (dropped unread) go; of several for this tick (its
                # first write found the socket full), the last counts
                while words and (words[0][0] < number
                                 or len(words) > 1 and words[1][0] == number):
                    words.popleft()
                if words and words[0][0] == number and self._counts_reached(words[0][1],
                                                                             publisher):
                    words.popleft()
                    return
                now = wall_clock()
                if deadline is None:
                    deadline = now + HOLD_CAP
                elif now >= deadline:
                    self.late += 1
                    return
                self._changed.wait(deadline - now)

    def _counts_reached(self, counts, publisher):
        taken = self._taken()
        return all(taken.get((topic, publisher, port), 0) >= count
                   for (topic, port), count in counts.items())

    def start_over(self):
        """A forked child: no simulator has said anything to it."""
        with self._changed:
            self._connection = self._simulator = self._clock_port = None
            self._free = 0
            self._words.clear()
