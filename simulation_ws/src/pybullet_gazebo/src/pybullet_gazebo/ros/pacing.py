"""Wall-clock pacing of the simulation loop, kept out of the engine.

RealTimePacer holds sim time to `real_time_factor` sim seconds per wall second (0 = as fast
as the machine allows); when the machine falls more than half a second behind it does not try
to catch up.

Lockstep (see README, "Lockstep"): after a step that published a scan, the loop may step on
until the drive next reads its command (`next_command_time`), and there waits until a
controller has answered (a command counted since that scan), at most `timeout` wall seconds.
The answer then reaches the wheels at the same sim time on every run.

Controllers that publish from their own loop (rospy.Rate, as the series' later programs do)
wake on /clock, not on scans: when no answer came within WAKE_AFTER of wall time,
`before_wait` is called (the node brings /clock up to now), so a loop whose tick fell since
the last /clock publishes its command before the drive reads it. A loop whose next tick lies
after the drive's update cannot answer before it (in Gazebo its command too reaches the
wheels one update later): seen in the series' bug programs when a behaviour is switched on
just after its loop ticked. So when no answer came within `step_on_after` (0.25 s, or a
quarter of `timeout` when that is longer) of the scan's wait, lockstep steps on without a
word (before: it stalled the whole `timeout`, 1 s, and logged
`no cmd_vel within`). When no command at all comes for `timeout` (every controller switched
off, say), lockstep reports it once and stops waiting until the next command arrives,
instead of stalling at every scan. A controller that answers scans is waited for up to
`step_on_after`: far more than it takes (a few ms); where even a rare step-on must not happen
(the batch runner's metrics must not depend on the machine's load), raise `timeout`
(lockstep_timeout): the batch runner's 30 s makes it 7.5 s. Time spent paused
is not silence: a pause (an agent that thinks between steps, a user at the GUI) interrupts
the wait, and the wait starts afresh, for the same answer, once physics runs again. A reset forgets both the awaited answer and the
silence (a new episode: its controller is waited for again).
"""
import threading
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
        self.waits = 0              # scans whose answer was not in when the drive needed it
        self.wake_ups = 0           # of those, waits that needed the wake-up /clock
        self.step_ons = 0           # waits that ended without an answer, stepping on
        self.timeouts = 0           # of those, the ones that found the controllers silent
        self.wall_waiting = 0.0     # [s] wall spent in those waits

    def summary(self):
        return ("%d waits for a cmd_vel (%d needed the wake-up /clock, %d stepped on without "
                "an answer, %d found the controllers silent), %.1f s of wall time waiting"
                % (self.waits, self.wake_ups, self.step_ons, self.timeouts, self.wall_waiting))


class Lockstep:
    WAKE_AFTER = 0.005        # [s] wall: how long an answer may take before the wake-up /clock
    STEP_ON_AFTER = 0.25      # [s] wall, at least: no answer this long after a scan: step on
    STEP_ON_SHARE = 0.25      # ... or this share of `timeout` when that is longer

    def __init__(self, enabled, timeout, on_timeout, is_shutdown, before_wait=lambda: None,
                 is_paused=lambda: False):
        self.enabled = enabled
        self.timeout = timeout               # [s] wall
        self.on_timeout = on_timeout         # called once per silence (see the docstring)
        self.is_shutdown = is_shutdown
        self.is_paused = is_paused           # physics paused: a wait ends without a verdict
        self.before_wait = before_wait       # called before waiting for an answer not yet in
        self.commands = 0                    # commands received since the start
        self.stats = LockstepStats()
        self.silent_at = None                # commands counted when a wait last timed out
        self._arrived = threading.Condition()
        self._awaited = None                 # (commands counted at a scan, sim time needed by)
        self._quiet = None                   # (commands counted, wall time) unanswered since

    @property
    def step_on_after(self):
        """[s] wall: how long a scan's answer is waited for before stepping on."""
        return min(self.timeout, max(self.STEP_ON_AFTER, self.STEP_ON_SHARE * self.timeout))

    def command_arrived(self):
        with self._arrived:
            self.commands += 1
            self._arrived.notify_all()

    def expect_answer(self, commands_before, needed_at):
        """A scan went out when `commands_before` commands had come; its answer is needed
        before the step that starts at `needed_at` [s] (None: no part takes commands)."""
        if self.enabled and needed_at is not None:
            self._awaited = (commands_before, needed_at)

    def answer_needed_at(self):
        """Sim time [s] before whose step lockstep may wait for an answer, or None."""
        awaited = self._awaited
        return awaited[1] if awaited is not None else None

    def forget(self):
        """A reset: no answer awaited, and no controller taken as silent any more."""
        self._awaited = None
        self.silent_at = None
        self._quiet = None

    def wait_if_due(self, sim_time, anyone_commands):
        """Before a step at `sim_time`: waits for the awaited answer if it is needed now and
        some controller publishes commands at all. False when physics was paused meanwhile:
        the step must not be taken now, and the answer is still awaited."""
        awaited = self._awaited
        if awaited is None or sim_time < awaited[1]:
            return True
        if self.commands != awaited[0] or self.commands == self.silent_at \
                or not anyone_commands():
            self._awaited = None
            return True             # answered already, controllers silent, or none at all
        started = time.monotonic()
        if self._quiet is not None and self._quiet[0] != self.commands:
            self._quiet = None                       # a command came since: not quiet
        # a controller that answers scans is usually a few ms away: no wake-up /clock for it
        # (each /clock wakes every node); one on its own loop gets it after WAKE_AFTER
        outcome = self._wait_for(awaited[0], started + min(self.WAKE_AFTER, self.timeout))
        self.stats.waits += 1
        if outcome is None:
            self.stats.wake_ups += 1
            self.before_wait()
            outcome = self._wait_for(awaited[0], started + self.step_on_after)
        self.stats.wall_waiting += time.monotonic() - started
        if outcome is False:                         # paused: wait again after the pause
            self._quiet = None
            return False
        self._awaited = None
        if outcome:
            self._quiet = None
            return True
        if self._quiet is None:
            self._quiet = (self.commands, started)
        if time.monotonic() - self._quiet[1] < self.timeout:
            self.stats.step_ons += 1                 # its tick lies beyond the update
            return True
        self._quiet = None
        self.stats.timeouts += 1
        self.silent_at = self.commands
        self.on_timeout()
        return True

    def _wait_for(self, commands_before, deadline):
        """Waits until a command beyond `commands_before` came (True), physics was paused
        (False) or the wall clock reached `deadline` (None)."""
        with self._arrived:
            while self.commands == commands_before and not self.is_shutdown():
                if self.is_paused():
                    return False
                left = deadline - time.monotonic()
                if left <= 0:
                    return None
                self._arrived.wait(min(left, 0.02))
        return True
