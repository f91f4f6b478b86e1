"""Wall-clock pacing of the simulation loop, kept out of the engine.

RealTimePacer holds sim time to `real_time_factor` sim seconds per wall second (0 = as fast
as the machine allows); when the machine falls more than half a second behind it does not try
to catch up. Lockstep's gate, which holds the loop for the controllers instead of the wall
clock, is lockstep/gate.py.
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
