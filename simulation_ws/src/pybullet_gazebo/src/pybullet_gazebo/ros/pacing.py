"""Wall-clock pacing of the simulation loop, kept out of the engine.

RealTimePacer holds sim time to `real_time_factor` sim seconds per wall second (0 = as fast
as the machine allows); when the machine falls more than half a second behind it does not try
to catch up.

Lockstep's contract (README, "Lockstep"): a controller in lockstep sees what a controller
that takes no time would see at real time. Whatever it does with a message the simulator
sends it (a scan, odometry, a /clock tick that wakes its rospy.Rate or rospy.Timer loop), it
has done before the simulation goes on past the next moment that it could change: the next
message to the controllers, or the next update at which a drive reads its command. So a tick
at sim time t acts on the odometry, scans and TF published up to t, and its command reaches
the wheels at the drive's first update after t, on every run, whatever the machine's load.

How: the loop tells Lockstep when it sends something to the loop nodes (`sending`, see
clock_topic.py for who they are), and before it sends the next thing or steps into a command
update it calls `settle`, which waits until the loop nodes' processes and the simulator's own
readers are idle (idle_threads.py, own_receivers.py): done with what they got, their answers
(commands, service calls) in. A controller that is idle and published nothing has nothing to
say this tick: lockstep does not wait for a command that will not come. Physics runs on while
a controller acts, up to the next thing it could change: a /clock tick owed to a rospy.Rate
loop is handed on between two steps as soon as a look that never waits (`settled_now`) finds
the loop nodes done with the readings (SimulatorNode._advance).

What it cannot promise: a node on another machine cannot be watched (it is named in the run
summary); a thread that computes for longer than idle_threads.SPIN_CPU of CPU at once is
taken for a busy loop and not waited for; a program that acts on wall time (time.sleep, a
thread of its own timed by the wall clock) sees sim time run at whatever speed the machine
gives. `timeout` [s wall] bounds each wait: a process still busy then is stepped past, and
named once in the log and in the run summary.
"""
import time


class RealTimePacer:
    def __init__(self, real_time_factor, sim_time=0.0):
        self.real_time_factor = real_time_factor
        self.restart(sim_time)

    def restart(self, sim_time):
        self._wall = time.monotonic()
        self._sim = sim_time

    def pace(self, sim_time):
        """Sleeps until wall time catches up with `sim_time` [s] at the set factor."""
        if self.real_time_factor <= 0:
            return
        target = self._wall + (sim_time - self._sim) / self.real_time_factor
        delay = target - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        elif delay < -0.5:          # far behind (a slow machine): do not try to catch up
            self.restart(sim_time)


class LockstepStats:
    """What lockstep cost in a run, for the simulator's run summary."""

    def __init__(self):
        self.settles = 0            # times the loop asked for the loop nodes to be idle
        self.waits = 0              # of those, the ones that found someone at work
        self.timeouts = 0           # waits that ended with someone still at work
        self.wall_waiting = 0.0     # [s] wall spent in those waits
        self.stepped_past = {}      # who was still at work at a timeout -> times
        self.waited_for = {}        # who was at work when a wait began -> [s] wall waited
        self.ticks_while_stepping = 0   # /clock ticks handed on while physics ran on
        self.ticks = 0                  # /clock ticks handed on to a loop node in all

    def summary(self):
        text = ("%d waits for the controllers (of %d settles), %.1f s of wall time waiting, "
                "%d time-outs" % (self.waits, self.settles, self.wall_waiting, self.timeouts))
        if self.ticks:
            text += ", %d of %d /clock ticks to a loop node handed on while physics ran" % (
                self.ticks_while_stepping, self.ticks)
        if self.stepped_past:
            text += " (still at work: %s)" % ", ".join(
                "%s %d x" % item for item in sorted(self.stepped_past.items()))
        if self.waited_for:
            text += "; waited for: %s" % ", ".join(
                "%s %.2f s" % item for item in sorted(self.waited_for.items(),
                                                       key=lambda item: -item[1])[:5])
        return text


class Lockstep:
    def __init__(self, enabled, timeout, watch, is_shutdown, is_paused=lambda: False,
                 describe=str, on_timeout=lambda who: None):
        """`watch`: an IdleWatch (idle_threads.py) that settle() waits on; `describe(busy)`:
        a name for what watch.busy() returned (a node name), `on_timeout(name)`: told once
        per name that a wait timed out on."""
        self.enabled = enabled
        self.timeout = timeout               # [s] wall
        self.watch = watch
        self.is_shutdown = is_shutdown
        self.is_paused = is_paused           # physics paused: a wait ends without a verdict
        self.describe = describe
        self.on_timeout = on_timeout
        self.stats = LockstepStats()
        self._sent = False                   # something went to the loop nodes since settle

    def sending(self):
        """Something goes to the loop nodes now (call it just before): settle() waits for
        them to be done with it."""
        if self.enabled:
            self._sent = True
            self.watch.note_sent()

    @property
    def unsettled(self):
        return self._sent

    def forget(self):
        """A reset: nothing sent is waited for any more."""
        self._sent = False

    def settled_now(self):
        """Without waiting: True when the loop nodes are done with what they were sent (as
        settle() would find at once), False when someone may still be at work. The look is
        taken only when the machine runs nothing but the caller (IdleWatch.idle_now): it is
        for the loop's steps between two looks, which must stay cheap."""
        if not self._sent:
            return True
        if not self.watch.idle_now():
            return False
        self.stats.settles += 1
        self._sent = False
        return True

    def settle(self):
        """Waits until the loop nodes are done with what they were sent. False when physics
        was paused meanwhile (the wait is taken up again once it runs)."""
        if not self._sent:
            return True
        self.stats.settles += 1
        busy = self.watch.busy()
        if busy is not None:
            started = time.monotonic()
            self.stats.waits += 1
            first = self.describe(busy)
            busy = self.watch.wait(started + self.timeout,
                                   lambda: self.is_paused() or self.is_shutdown(), busy)
            waited = time.monotonic() - started
            self.stats.wall_waiting += waited
            self.stats.waited_for[first] = self.stats.waited_for.get(first, 0.0) + waited
            if busy is not None:
                if self.is_paused() or self.is_shutdown():
                    return False
                self.stats.timeouts += 1
                who = self.describe(busy)
                if who not in self.stats.stepped_past:
                    self.on_timeout(who)
                self.stats.stepped_past[who] = self.stats.stepped_past.get(who, 0) + 1
        self._sent = False
        return True
