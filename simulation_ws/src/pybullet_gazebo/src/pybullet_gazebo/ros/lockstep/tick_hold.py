"""A controller's side of the ticks the simulator sends it with word of what they follow
(lockstep_msgs/LockstepExpect on /lockstep/expect): a tick sets sim time only once the process
has taken in the readings the simulator sent before it.

Why: a rospy.Rate loop acts on what its callbacks stored. Its tick must therefore come after
the readings of that time have gone through their callbacks; the readings and the tick travel
on different connections, read by different threads, so the order they are written in says
nothing about the order they are taken in. Without word the simulator had to wait for the
process's report of the readings before it sent the tick: a second round trip per tick, which
a program that answers in its scan callback does not pay. With it, the simulator sends the
readings and the tick together, and the tick waits here, in the thread that reads it, until
the counts it names are reached; the program sees the same thing at the same sim time, and the
process reports once, when its loop sleeps again.

The simulator says HOLD once on a connection: from then on this process's ticks come on it,
none on /clock; the /clock ticks written before the HOLD (its count) are taken in before the
first tick here sets the time, so time never goes back. A tick whose counts are not reached
within HOLD_CAP (a simulator that went away) is set anyway and counted in `late`.
"""
import threading

from pybullet_gazebo.ros.lockstep import CLOCK_TOPIC as CLOCK

HOLD, TICK = 1, 2           # lockstep_msgs/LockstepExpect's kinds
HOLD_CAP = 1.0              # [s] wall: the longest a tick is held for counts that do not come


class TickHold:
    def __init__(self, taken, parked=lambda: ()):
        """`taken()`: {(topic, publisher, port): messages taken in} of this process now (the
        Tracker's counts, those its queue_size dropped included); `parked()`: the
        connections whose reading thread sleeps in a callback until a later sim time (what
        comes on them is read only once a tick wakes it: not waited for)."""
        self._taken = taken
        self._parked = parked
        self._changed = threading.Condition()
        self._changed._lockstep_untracked = True      # (its waits are not the program's)
        self._before = {}           # simulator -> {(topic, port): count}: /clock before HOLD
        self.late = 0               # ticks set without their counts, after HOLD_CAP

    def heard_hold(self, simulator, clock_port, clock_count):
        """`simulator` sends this process's ticks with word from now on, after the first
        `clock_count` on the /clock connection whose end here has `clock_port`."""
        with self._changed:
            self._before[simulator] = {(CLOCK, clock_port): clock_count}

    def taken_changed(self):
        """A callback returned: the counts grew."""
        with self._changed:
            if self._before:
                self._changed.notify_all()

    def wait(self, simulator, counts, wall_clock):
        """Returns once this process has taken in `counts` ({(topic, port): count}) from
        `simulator`, and the /clock ticks it sent before its HOLD. `wall_clock()`: for
        HOLD_CAP."""
        with self._changed:
            needed = dict(self._before.get(simulator, {}))
            needed.update(counts)
            deadline = None
            while not self._reached(needed, simulator):
                now = wall_clock()
                if deadline is None:
                    deadline = now + HOLD_CAP
                elif now >= deadline:
                    self.late += 1
                    return
                self._changed.wait(deadline - now)

    def _reached(self, counts, publisher):
        if not counts:
            return True
        taken, parked = self._taken(), self._parked()
        return all(taken.get((topic, publisher, port), 0) >= count
                   or (topic, publisher, port) in parked
                   for (topic, port), count in counts.items())

    def start_over(self):
        """A forked child: no simulator has said anything to it."""
        with self._changed:
            self._before = {}
