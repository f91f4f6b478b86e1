"""How often the topics people watch go out when the simulation runs faster than real time.

"Watching" topics are the ones a display or a monitoring tool reads, not a controller in
lockstep: ~model_states, ~link_states and joint_states (robot_state_publisher turns the
latter into the wheels' TF for rviz). Each has its rate in sim time (model_states_rate, the
joint-state part's updateRate). In lockstep at 30x real time, a 50 Hz topic would be 1500
messages per wall second, each built and serialized in the loop's thread and read by
listeners that share the machine's cores with the simulator and the controller; no display
shows more than a few tens of frames per second.

The rule (~watch_rate, [Hz] of wall time, default 30): a watching topic keeps its sim-time
rate while that is at most max(watch_rate, its own rate) messages per wall second, so at
real time or slower nothing changes (what Gazebo publishes); faster than that, messages
that would exceed this many per wall second are skipped. The messages that do go out are
the state at their own step, stamped with its sim time. 0 = no limit: every message at its
sim-time rate whatever the speed (a controller that takes its pose from model_states in
lockstep at high speed needs that).

Not limited, because controllers use them in lockstep: /clock, the laser scans, the diff
drive's odometry and its odom -> base TF, the services.
"""
import math
import time

DEFAULT_WATCH_RATE = 30.0       # [Hz] wall: rviz's default frame rate


class WallRateLimit:
    """Lets at most `limit` [Hz] calls through per wall second on average (a token bucket).
    Calls that come no faster than that all pass, even in bursts of up to BURST seconds'
    worth: the real-time pacer catches up to half a second late (pacing.py) by stepping at
    full speed, and those messages must not be lost at real time. `limit` <= 0: every call
    passes."""

    BURST = 0.5             # [s] wall

    def __init__(self, limit, clock=time.monotonic):
        self.limit = limit if 0 < limit < math.inf else 0.0
        self._capacity = max(2.0, self.limit * self.BURST)
        self._clock = clock
        self._tokens = self._capacity
        self._last = None
        self.skipped = 0                    # calls refused so far

    def _tokens_at(self, now):
        """The tokens in the bucket at wall time `now`, refilled since the last call."""
        if self._last is None:
            return self._tokens
        return min(self._capacity, self._tokens + (now - self._last) * self.limit)

    def ready(self):
        """True when a call now would pass (allow() would say True); takes nothing."""
        return self.limit == 0.0 or self._tokens_at(self._clock()) >= 1.0

    def allow(self):
        if self.limit == 0.0:
            return True
        now = self._clock()
        self._tokens = self._tokens_at(now)
        self._last = now
        if self._tokens >= 1.0:
            self._tokens -= 1.0
            return True
        self.skipped += 1
        return False


def topic_limit(watch_rate, sim_rate):
    """Wall-time limit [Hz] of a watching topic published at `sim_rate` [Hz of sim time]:
    never below its own rate (real time is unchanged); 0 (no limit) when watch_rate is 0 or
    the topic goes out at every step (sim_rate inf)."""
    if watch_rate <= 0 or not math.isfinite(sim_rate):
        return 0.0
    return max(watch_rate, sim_rate)
