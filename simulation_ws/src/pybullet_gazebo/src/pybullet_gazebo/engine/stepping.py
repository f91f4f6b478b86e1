"""How the world's time advances: fixed physics steps, the parts' hooks around them, their
readings collected or skipped, who touches whom, and stretches of steps in which nothing can
happen handed to Bullet in one call (batching.py). The World (world.py) owns the models;
the Stepper owns the stepping and what it remembers between calls (the contact guard's
answers, the step of the last layout change), and updates the world's step count.

The parts take part through their Part contract (part.py): every part's before_step,
after_step, due and measure; the scheduling tier (skip, next_hook_time, next_reading_time,
next_activity_time) lets the Stepper skip readings nobody collects and batch the steps
between hooks.
"""
import math
from typing import List

from .batching import MAX_BATCH, Batcher
from .entities import Reading


class Stepper:
    """Advances one World (see the module docstring)."""

    def __init__(self, world, client):
        self.world = world
        self.batcher = Batcher(client)
        self._settled = None        # layout_version after the last step (batches need one)
        self._single_until = -1     # step count before which advance steps one by one
        self._safe_until = -1       # step count up to which no contact can start
        self._read_at = -1          # step count at which the contacts were last read
        self._guard_end = -1        # step count at which the last advance ended (-1: early)
        self._horizon_end = 0       # step count up to which the guard looks in this call

    def layout_changed(self):
        """A model came or went: the next advance starts with a single step."""
        self._settled = None

    def advance(self, steps, collect=True, touched=None, until_news=False,
                collect_from=0, continues=False, horizon=None) -> List[Reading]:
        """`steps` fixed steps, with the same readings (`collect` as for step), contact events,
        sim time and physics, to the last bit, as `steps` calls of step(); stretches in which
        nothing can happen between steps (no part's hook acts, no wrench, no contact can
        start: see batching.py) go to Bullet in one call. `touched`: a set that receives
        every (robot, other model) pair touching after any of the steps. `until_news`: stop
        early, after the step that brought readings or changed which robots touch which
        models (a caller that publishes those at once, as the ROS loop does; step_count says
        how many steps ran). `collect_from`: the readings due in the steps before this one
        (0: the first) are skipped whatever `collect` says (a caller that observes only the
        last of them). A reading that is skipped does not end a stretch (see
        Part.next_reading_time), except with until_news. `continues`: this call goes on
        from where the last one ended, with nothing changed in between but parts' commands
        (a command is read by a part's hook, as within a call), so the contact guard's
        answers from the last call still hold (otherwise they hold for one call).
        (A teleport, spawn or delete since makes a fresh start all the same.)
        `horizon`: how many steps from now the contact guard looks ahead (default `steps`):
        a caller that will continue with another call asks for both at once."""
        world = self.world
        if world._robots is None:
            world.robots()                   # refreshes the caches after a spawn or delete
        parts = world._stepped[0]
        readings = []
        left = steps
        skipped_until = world.step_count + collect_from   # step count after the last skipped
        if not (continues and world.step_count == self._guard_end
                and self._settled == world.layout_version):
            self._safe_until = self._single_until = -1     # the guard's answers: one call
        self._guard_end = -1                            # (set again if this call ends well)
        self._horizon_end = world.step_count + (steps if horizon is None else horizon)
        changes = world.contacts.changes if until_news else None
        # the readings skipped whatever their time: those of parts not collected, and those
        # due up to step count skipped_until (None: none is, or readings end stretches)
        skipping = collect is not True and changes is None
        inside = ()                     # readings to skip after the next stretch
        while left > 0:
            now = world.sim_time
            for _, part in parts:
                part.before_step(now, world.step_size)
            world.wrenches.apply(now)
            if left > 1:
                k, inside = self._quiet_steps(
                    left, now, (collect, skipped_until) if skipping else None)
            else:
                k = 1
            start = world.step_count
            if k == 1 and world.step_count + 1 < self._single_until:
                # a quiet stretch the contact guard would not batch: its steps one by one,
                # contacts read after each, without the parts' hooks (idle until its end)
                k = self._single_until - world.step_count
                self._steps_one_by_one(k - 1, touched, changes)
                if changes is not None and world.contacts.changes != changes:
                    # a touch began or ended inside the stretch: news, stop at that step
                    self._settled = world.layout_version
                    return readings         # (empty: news ends every call at once)
                self.batcher.step(world.step_size, 1)
                world.step_count += 1
            else:
                self.batcher.step(world.step_size, k)
                world.step_count += k
            if k > 1 and inside:
                self._skip_readings_inside(inside, start, k)
            left -= k
            now = world.sim_time
            for robot, part in parts:
                part.after_step(now)
                if part.due(now):
                    if (collect is True or part in collect) and world.step_count > skipped_until:
                        readings.append(Reading(robot, part, part.measure(now)))
                    else:
                        part.skip(now)
            self._read_contacts(touched)
            self._settled = world.layout_version
            if changes is not None and (readings or world.contacts.changes != changes):
                break
        self._guard_end = world.step_count
        return readings

    def _steps_one_by_one(self, steps, touched, changes=None):
        """`steps` physics steps, one Bullet call each, the contacts read after each as
        advance reads them; for the inside of a quiet stretch (no part's hook acts, no
        wrench), where stepping them one at a time skips nothing but idle hooks. Stops after
        a step when `changes` (not None) differs from the contacts' change count (which
        robots touch which models changed)."""
        world = self.world
        step, size = self.batcher.step, world.step_size
        for _ in range(steps):
            step(size, 1)
            world.step_count += 1
            if self._read_contacts(touched) and changes is not None \
                    and world.contacts.changes != changes:
                return

    def _read_contacts(self, touched):
        """Reads who touches whom after a step, unless the contact guard proved no robot
        touches a model up to this step; `touched` (a set, or None) receives the pairs.
        True when read."""
        world = self.world
        if world.step_count <= self._safe_until:
            return False
        pairs = world.contacts.update(world.client, world.sim_time, world._stepped[1],
                                     world._body_owner, world._grounds)
        self._read_at = world.step_count
        if touched is not None and pairs:
            touched.update(pairs)
        return True

    def _readings_inside(self, skippers, now, steps):
        """[(part, its next_reading_time)] of the `skippers` whose next reading may fall
        inside a stretch of `steps` steps from now (at one of its k - 1 inner sim times)."""
        world = self.world
        if steps < 2:
            return ()
        last = world.time_after(steps - 1)
        inside = []
        for part in skippers:
            due = part.next_reading_time(now)
            if due <= last:
                inside.append((part, due))
        return inside

    def _skip_readings_inside(self, inside, start, k):
        """Skips the readings due at the k - 1 sim times inside the stretch of k steps that
        began at step count `start`, as single steps would have: in step order, and at
        each time in the parts' order. `inside`: _readings_inside's answer for it."""
        world = self.world
        skippers = [part for part, _ in inside]
        due_at = [due for _, due in inside]
        first = min(due_at)
        for count in range(start + 1, start + k):
            now = world._time_at(count)
            if now < first:
                continue
            for index, part in enumerate(skippers):
                if now >= due_at[index] and part.due(now):
                    part.skip(now)
                    due_at[index] = part.next_reading_time(now)
            first = min(due_at)

    def _quiet_steps(self, most, now, skipped=None):
        """(k, inside): how many of the next `most` steps, the first of which starts now
        (its before_step hooks done), may run as one Bullet call (see batching.py), and the
        readings due inside them to be skipped after (see _readings_inside). `skipped`:
        (collect, skipped_until) as advance has them, when readings nobody collects may fall
        inside a stretch; None: every reading ends one."""
        world = self.world
        if world.step_count < self._single_until:
            return 1, ()                    # the contact guard said no for this stretch
        if self._settled != world.layout_version or not world.wrenches.idle():
            return 1, ()                    # a teleport, spawn or delete: one step first
        quiet = math.inf
        k = min(most, MAX_BATCH)
        skippers = []
        if skipped is None:
            for _, part in world._stepped[0]:
                quiet = min(quiet, part.next_activity_time(now))
        else:
            collect, skipped_until = skipped
            for _, part in world._stepped[0]:
                collected = part in collect
                if collected and world.step_count >= skipped_until:
                    quiet = min(quiet, part.next_activity_time(now))    # its next is read
                    continue
                skippers.append(part)
                quiet = min(quiet, part.next_hook_time(now))
                if collected:
                    # skipped up to step count skipped_until, collected after it: the
                    # stretch may hold those skipped, and end on the first collected one
                    k = min(k, skipped_until - world.step_count + 1)
        # k steps may run when the k - 1 sim times between them come before `quiet`
        if quiet < math.inf:
            k = min(k, max(1, int((quiet - now) / world.step_size) + 2))
        while k > 1 and not world.time_after(k - 1) < quiet:
            k -= 1
        k = self.batcher.largest_exact(world.step_size, k)
        if k > 1 and world.step_count + k > self._safe_until:
            if self._read_at == world.step_count and world.contacts.any_touching():
                safe = 0.0                  # a robot touches a model now: no need to ask
            else:
                robots, others, grounds = world._guarded
                horizon = max(most, self._horizon_end - world.step_count)
                safe = self.batcher.safe_time(robots, others, grounds,
                                               horizon * world.step_size, world._statics)
            self._safe_until = world.step_count + int(safe / world.step_size)
            wanted, k = k, self.batcher.largest_exact(
                world.step_size, min(k, self._safe_until - world.step_count))
            if k < 2:
                self._single_until = world.step_count + wanted
                return 1, skippers and self._readings_inside(skippers, now, wanted)
        return k, skippers and self._readings_inside(skippers, now, k)
