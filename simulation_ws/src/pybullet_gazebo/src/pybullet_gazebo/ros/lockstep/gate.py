"""Lockstep's gate in the simulation loop: it steps on only once the controllers are done.

Lockstep's contract (docs/lockstep.md): a controller in lockstep sees what a controller that
takes no time would see at real time. Whatever it does with a message the simulator sends it
(a scan, odometry, a /clock tick that wakes its rospy.Rate or rospy.Timer loop), it has done
before the simulation goes on past the next moment that it could change: the next message to
the controllers, or the next update at which a drive reads its command.

How: the loop tells Lockstep when it sends something to the controllers (`sending`), and
before it sends the next thing or steps into a command update it calls `settle`, which waits
until they are done with it. A controller whose process reports (the handshake) is
done when its report says so and the counts agree (board.py): exact. A controller
that cannot report (roscpp, a Python outside the project's environment) is watched in /proc
instead (idle_threads.py: a guess, named in the log and the run summary). `timeout` [s wall]
bounds each wait: whoever is still at work then is stepped past, and named once in the log
and in the run summary.
"""
import time


def sort_controllers(names, reporters, was_reporting, was_leaving):
    """How lockstep waits for each controller `names` (the nodes on its loop connections),
    given `reporters` (the nodes whose report connections are open now) and the previous
    answer's reporting and leaving sets: (reporting, watched, leaving).

    A node that ends closes its connections all at once, but the simulator sees them go one
    by one: the report connection first (it reads from it, so the end of the stream shows at
    once), those it writes to at its next write. A reporter that lost only its report
    connection is leaving, not a controller without the handshake: it will say no more, and
    it is not waited for at all (neither by reports nor in /proc) until it is gone or
    reports again (a new process under its name)."""
    reporting = names & reporters
    leaving = (was_leaving | (was_reporting - reporters)) & (names - reporters)
    return reporting, names - reporting - leaving, leaving


class LockstepStats:
    """What lockstep cost in a run, for the simulator's run summary."""

    def __init__(self):
        self.settles = 0            # times the loop asked for the controllers to be done
        self.waits = 0              # of those, the ones that found someone at work
        self.timeouts = 0           # waits that ended with someone still at work
        self.wall_waiting = 0.0     # [s] wall spent in those waits
        self.stepped_past = {}      # who was still at work at a timeout -> times
        self.waited_for = {}        # who was at work when a wait began -> [s] wall waited
        self.ticks_while_stepping = 0   # /clock ticks handed on while physics ran on
        self.ticks = 0                  # /clock ticks handed on to a loop node in all
        self.ticks_with_readings = 0    # ... sent with the readings (tick_word.py)
        self.handshake = set()          # controllers waited for by their reports
        self.watched = set()            # ... and by the /proc watch (no reports)

    def summary(self):
        text = ("%d waits for the controllers (of %d settles), %.1f s of wall time waiting, "
                "%d time-outs" % (self.waits, self.settles, self.wall_waiting, self.timeouts))
        if self.ticks:
            text += ", %d of %d /clock ticks to a loop node handed on while physics ran" % (
                self.ticks_while_stepping, self.ticks)
            if self.ticks_with_readings:
                text += " and %d sent with the readings" % self.ticks_with_readings
        if self.stepped_past:
            text += " (still at work: %s)" % ", ".join(
                "%s %d x" % item for item in sorted(self.stepped_past.items()))
        if self.handshake:
            text += "; by handshake (exact): %s" % ", ".join(sorted(self.handshake))
        if self.watched:
            text += "; watched in /proc (no handshake): %s" % ", ".join(sorted(self.watched))
        if self.waited_for:
            text += "; waited for: %s" % ", ".join(
                "%s %.2f s" % item for item in sorted(self.waited_for.items(),
                                                       key=lambda item: -item[1])[:5])
        return text


class Lockstep:
    def __init__(self, enabled, timeout, board, watch, is_shutdown, is_paused=lambda: False,
                 describe=str, on_timeout=lambda who: None):
        """`board`: the handshake (board.py); `watch`: an IdleWatch (idle_threads.py)
        for the controllers that do not report; `describe(busy)`: a name for what the watch
        found at work (a node name), `on_timeout(name)`: told once per name that a wait timed
        out on."""
        self.enabled = enabled
        self.timeout = timeout               # [s] wall
        self.board = board
        self.watch = watch
        self.is_shutdown = is_shutdown
        self.is_paused = is_paused           # physics paused: a wait ends without a verdict
        self.describe = describe
        self.on_timeout = on_timeout
        self.stats = LockstepStats()
        self.reporting = set()               # controllers that report (the board asks them)
        self.watching = False                # the watch has processes to look at
        self._sent = False                   # something went to the controllers since settle
        self._busy_at = None                 # the board's version when last found busy

    def wait_for(self, reporting, watched):
        """From now on: the controllers `reporting` by their reports, and `watched` (names)
        by the watch (given their processes)."""
        self.reporting = set(reporting)
        self.watching = bool(watched)
        self.stats.handshake.update(reporting)
        self.stats.watched.update(watched)

    def sending(self):
        """Something goes to the controllers now (call it just before): settle() waits for
        them to be done with it."""
        if self.enabled:
            self._sent = True
            self._busy_at = None
            if self.watching:
                self.watch.note_sent()

    @property
    def unsettled(self):
        """Something went to the controllers, or the simulator answered a call of theirs,
        since they were last found done."""
        return self._sent or bool(self.reporting) and self.board.pending_calls(self.reporting)

    def forget(self):
        """A reset: nothing sent is waited for any more."""
        self._sent = False

    def settled_now(self):
        """Without waiting: True when the controllers are done with what they were sent (as
        settle() would find at once), False when someone may still be at work. Cheap: for
        the loop's steps between two looks."""
        if not self.unsettled:
            return True
        if self.reporting:
            version = self.board.version
            if version == self._busy_at:         # nothing came since it was found busy
                return False
            if self.board.busy(self.reporting) is not None:
                self._busy_at = version
                return False
        if self.watching:
            return False        # the /proc watch takes two looks: only settle() waits
        self.stats.settles += 1
        self._sent = False
        return True

    def _look(self):
        if self.reporting:
            busy = self.board.busy(self.reporting)
            if busy is not None:
                return "report", busy
        if self.watching:
            busy = self.watch.busy()
            if busy is not None:
                return "watch", busy
        return None

    def _name(self, busy):
        kind, what = busy
        if kind == "report":
            return "node %s" % what[0]
        return self.describe(what)

    def settle(self):
        """Waits until the controllers are done with what they were sent. False when physics
        was paused meanwhile (the wait is taken up again once it runs)."""
        if not self.unsettled:
            return True
        self.stats.settles += 1
        busy = self._look()
        if busy is not None:
            started = time.monotonic()
            deadline = started + self.timeout
            stop = lambda: self.is_paused() or self.is_shutdown()     # noqa: E731
            self.stats.waits += 1
            first = self._name(busy)
            if busy[0] == "report":
                first += " (%s)" % busy[1][1].split(":")[0]
            if busy[0] == "report":
                left = self.board.wait(self.reporting, deadline, stop)
                busy = ("report", left) if left is not None else self._look()
            if busy is not None and busy[0] == "watch":
                left = self.watch.wait(deadline, stop, busy[1])
                busy = ("watch", left) if left is not None else None
            waited = time.monotonic() - started
            self.stats.wall_waiting += waited
            self.stats.waited_for[first] = self.stats.waited_for.get(first, 0.0) + waited
            if busy is not None:
                if stop():
                    return False
                self.stats.timeouts += 1
                who = self._name(busy)
                if busy[0] == "report":
                    self.board.silent.add(busy[1][0])
                    who += " (%s)" % busy[1][1]
                if who not in self.stats.stepped_past:
                    self.on_timeout(who)
                self.stats.stepped_past[who] = self.stats.stepped_past.get(who, 0) + 1
        self._sent = False
        return True
