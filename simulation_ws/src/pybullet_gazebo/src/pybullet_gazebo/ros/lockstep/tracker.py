"""What one process has taken in, written out, and whether it is done: the controller's side
of lockstep's handshake, kept free of rospy so that it can be tested on its own (the rospy
hooks that feed it are in rospy_hooks.py).

A process is done when
  - no callback of a subscriber, and no service handler, is running; a callback whose thread
    sleeps in rospy.sleep until a later sim time is done with its message, and its
    connection is parked: what comes on it is read once the thread is back (`parked`);
  - no service call of its own is in flight;
  - no thread is due: a thread that slept in rospy.sleep (a rospy.Rate or rospy.Timer loop)
    is due from the /clock tick that reaches its wake-up time until it sleeps again, or
    until it polls; a thread that polls (calls rospy.is_shutdown() twice with nothing in
    between: no publish, no sleep, no service call) is a busy loop waiting for something to
    change, and it is done; when a callback or a handler ends it is due again until it has
    polled once more, since what it polls for may have changed;
  - nothing it published waits in a queued connection's queue;
  - no thread woken through a threading.Condition (a queue.Queue, an Event) by a callback
    or a handler is still at work: a callback that hands a message to another thread (a
    queue the main loop reads) is done with it only once that thread waits again.
Each time it becomes done with something new to say, it sends a report (`send`): the
messages taken in and written out per connection, and the service calls answered and made
since the last report. The simulator compares those counts with its own (board.py), so it
knows the report is about everything it sent, and that it has read everything the process
wrote.

While reporting is on (the simulator listens: `reporting()`), a polling thread is held in its
rospy.is_shutdown() until something happens in the process, instead of spinning: it would
take the GIL from the callbacks for Python's switch interval (5 ms) at every message, and a
core from the simulator. What it polls for can only change when something happens; `POLL_CAP`
bounds the hold for anything the tracker cannot see (a thread timed by the wall clock).
"""
import threading

POLL_CAP = 0.05          # [s] wall: the longest a polling thread is held at a time
KEEP_ANSWERED = 4096     # calls the simulator answered, kept until its board takes them

_POLL, _OTHER = "poll", "other"


class Tracker:
    def __init__(self, send=lambda report: None, reporting=lambda: False):
        self.send = send                  # send(report dict): to the simulator
        self.reporting = reporting        # () -> True while the simulator listens
        self.pending_writes = lambda: 0   # messages waiting in queued connections
        self.thread_alive = lambda tid: True   # whether thread `tid` still runs
        self.on_change = None             # called (no lock held) when `taken` grows
        self.counting_only = False
        self.start_over()

    def start_over(self):
        """Forgets every thread, call and count: for a process just forked from another (the
        batch runner's warm interpreters), whose threads and connections are not its own."""
        self._lock = threading.Lock()
        self._changed = threading.Condition(self._lock)   # pollers wait on it
        self._changed._lockstep_untracked = True          # (its own waits are not news)
        self._waiting = {}                # id(condition) -> [thread ids waiting, in order]
        self._running = 0                 # callbacks and handlers running (not sleeping)
        self._in_callback = {}            # thread id -> [[key, count, parked]], innermost last
        self._calls = 0                   # service calls in flight
        self._due = set()                 # thread ids due (see the module docstring)
        self._sleeping = {}               # thread id -> (start, wake, duration) [ns sim]
        self._last = {}                   # thread id -> _POLL or _OTHER: its last event
        self._held = set()                # polling threads held now
        self.taken = {}                   # (topic, peer, port) -> messages taken in
        self._dropped = {}                # (topic, port) -> dropped by queue_size
        self.written = {}                 # (topic, peer, port) -> messages written
        self._served = []                 # [(service, port)] answered since the last report
        self._called = []                 # [(service, port)] made since the last report
        self._news = False                # something to report once done
        self._sent_taken = {}             # the counts as last reported
        self._sent_written = {}
        self.seq = 0
        # the simulator's own process counts what it takes in and writes, nothing more: its
        # loop polls rospy.is_shutdown() and must not be taken for a busy loop
        self.answered = []                # the simulator's: [(service, port, client)]
        # a process that only watches says so (rospy_hooks.watch_only) and reports no more
        self.watcher = False

    # --- what the hooks say ------------------------------------------------------------
    def callback_started(self, tid=None, key=None, count=0):
        """Thread `tid` runs the callbacks of `count` messages of `key` (topic, peer, port)."""
        with self._lock:
            self._running += 1
            if tid is not None:
                self._in_callback.setdefault(tid, []).append([key, count, False])

    def callback_ended(self, topic, peer, port, count, now=None, news=None, tid=None):
        """`count` messages of (topic, peer, port) went through every callback; `now` [ns sim]:
        the time a tick just set (wakes the sleepers it reaches); `news`: whether the
        simulator waits for word of these even when they wake no sleeper (default: unless
        they set the time); `tid`: the thread, as given to callback_started."""
        with self._lock:
            entry = self._callback_left(tid)
            if entry is not None and entry[2]:
                # it slept in the callback: taken in then (_park_callbacks); back from that
                # sleep the thread was due, and now it is back to reading
                self._due.discard(tid)
                self._last.pop(tid, None)
                self._wake_pollers()
            else:
                key = (topic, peer, port)
                self.taken[key] = self.taken.get(key, 0) + count
                # a tick that wakes no sleeper is no news: the simulator does not wait for
                # such a tick (board.py), so it needs no report of it
                woke = now is not None and self._wake_sleepers(now)
                news = woke or (now is None if news is None else news)
                self._running -= 1
                self._wake_pollers(news)
        self._after_change()
        if self.on_change is not None:
            self.on_change()

    def parked(self):
        """{(topic, peer, port)} of the connections whose reading thread sleeps now inside a
        callback: what comes on them waits in the socket until it is back."""
        with self._lock:
            return self._parked()

    def _parked(self):
        return {entry[0] for tid, entries in self._in_callback.items()
                if tid in self._sleeping for entry in entries if entry[2]}

    def _callback_left(self, tid):
        """The innermost callback record of thread `tid`, removed; None if it has none."""
        entries = self._in_callback.get(tid)
        if not entries:
            return None
        entry = entries.pop()
        if not entries:
            del self._in_callback[tid]
        return entry

    def _park_callbacks(self, tid):
        """Thread `tid` sleeps until a later sim time inside callbacks (a learner's
        rospy.sleep in a scan callback): they have done all they will do before that time, so
        their messages count as taken in and the process may be done. Had they counted only
        once they returned, the simulator would wait for them and they for its next tick."""
        for entry in self._in_callback.get(tid, ()):
            if not entry[2]:
                entry[2] = True
                key = entry[0]
                self.taken[key] = self.taken.get(key, 0) + entry[1]
                self._running -= 1
                self._news = True

    def dropped(self, topic, port, count):
        """A subscriber's queue_size dropped `count` messages unread: they are done with."""
        with self._lock:
            key = (topic, port)
            self._dropped[key] = self._dropped.get(key, 0) + count

    def handler_started(self):
        with self._lock:
            self._running += 1

    def handler_ended(self, service, port, client=None):
        with self._lock:
            if self.counting_only:
                # the simulator answered a call: it waits for the client's word on it
                self.answered.append((service, port, client))
                del self.answered[:-KEEP_ANSWERED]
            else:
                # kept even before the simulator listens, as a call is (call_answered): a
                # server that starts with its client (the series' bug 1 switches go to point
                # on as both start) may answer before its reports reach the simulator, which
                # then waits for word of that answer once the client reports the call
                self._served.append((service, port))
                del self._served[:-KEEP_ANSWERED]
            self._running -= 1
            self._wake_pollers()
        self._after_change()
        if self.counting_only and self.on_change is not None:
            self.on_change()

    def call_started(self, tid):
        if self.counting_only:
            return
        with self._lock:
            self._calls += 1
            self._last[tid] = _OTHER

    def call_answered(self, service, port):
        # kept even before the simulator listens (a program that calls a service as it
        # starts): the simulator waits for its client's word on a call it answered
        with self._lock:
            self._called.append((service, port))
            del self._called[:-KEEP_ANSWERED]
            self._news = True

    def call_ended(self, tid):
        if self.counting_only:
            return
        with self._lock:
            self._calls -= 1
            self._wake_pollers()
        self._after_change()

    def wrote(self, topic, peer, port):
        with self._lock:
            key = (topic, peer, port)
            self.written[key] = self.written.get(key, 0) + 1
            self._news = True

    def unqueued(self):
        """A queued connection wrote a message (pending_writes() fell)."""
        self._after_change()

    def published(self, tid):
        if self.counting_only:
            return
        with self._lock:
            self._last[tid] = _OTHER

    def sleep_started(self, tid, start, duration):
        """Thread `tid` sleeps `duration` from sim time `start` [ns sim]; start 0: sim time
        is not set yet, and rospy's sleep starts counting at the first /clock."""
        with self._lock:
            self._sleeping[tid] = (start, start + duration if start else None, duration)
            self._due.discard(tid)
            self._last[tid] = _OTHER
            if tid in self._in_callback:
                self._park_callbacks(tid)
        self._after_change()
        if tid in self._in_callback and self.on_change is not None:
            self.on_change()

    def sleep_start(self, tid):
        """The sim time [ns] thread `tid`'s sleep counts from, once known: for a sleep begun
        before the first /clock, that tick's time. None when not known (yet)."""
        with self._lock:
            start = self._sleeping.get(tid, (0,))[0]
        return start or None

    def cond_wait_started(self, tid, condition):
        """Thread `tid` waits on a threading.Condition: done until it is notified."""
        if self.counting_only:
            return
        with self._lock:
            self._waiting.setdefault(id(condition), []).append(tid)
            self._due.discard(tid)
            self._last[tid] = _OTHER
        self._after_change()

    def cond_wait_ended(self, tid, condition):
        if self.counting_only:
            return
        with self._lock:
            waiting = self._waiting.get(id(condition))
            if waiting and tid in waiting:              # it timed out: not woken by anyone
                waiting.remove(tid)
                if not waiting:
                    del self._waiting[id(condition)]

    def cond_notified(self, condition, count):
        """`count` waiters of `condition` are woken (in the order they came, as CPython
        does): due until they wait again."""
        if self.counting_only:
            return
        with self._lock:
            waiting = self._waiting.get(id(condition))
            if waiting:
                self._due.update(waiting[:count])
                del waiting[:count]
                if not waiting:
                    del self._waiting[id(condition)]

    def wall_sleep(self, tid):
        """Thread `tid` waits for the wall clock: it is timed by the machine, not by sim
        time, and nothing it does next can be waited for."""
        if tid in self._due:
            with self._lock:
                self._due.discard(tid)
                self._last[tid] = _OTHER
            self._after_change()

    def sleep_ended(self, tid):
        """Thread `tid` is back from rospy.sleep: at work until it sleeps, polls or waits
        again. Marked here as well as by the /clock callback's end (`callback_ended`): rospy
        wakes the sleeper inside that callback, and the sleeper may run, and leave the
        sleepers' list, before the callback returns; had only the callback's end marked it,
        the process would have looked done (the next tick sent) while its loop was still at
        work on this one."""
        with self._lock:
            if self._sleeping.pop(tid, None) is not None:
                self._due.add(tid)
                self._news = True           # its wake-up is gone from the next report

    def time_set(self, now):
        """Sim time is `now` [ns] (for a /clock message read outside a callback)."""
        with self._lock:
            self._wake_sleepers(now)

    def polled(self, tid):
        """Thread `tid` called rospy.is_shutdown(); a second call with nothing between makes
        it a poller: done, and held (while reporting) until something happens."""
        if self.counting_only:
            return
        with self._lock:
            if self._last.get(tid) != _POLL:
                self._last[tid] = _POLL
                return
            self._due.discard(tid)
        self._after_change()
        if not self.reporting():
            return
        with self._lock:
            self._held.add(tid)
            try:
                self._changed.wait(POLL_CAP)
            finally:
                self._held.discard(tid)

    def forget_thread(self, tid):
        with self._lock:
            self._due.discard(tid)
            self._sleeping.pop(tid, None)
            self._last.pop(tid, None)
        self._after_change()

    # --- state ---------------------------------------------------------------------------
    def take_answered(self):
        """The calls the simulator answered since the last time asked (for its board)."""
        with self._lock:
            answered, self.answered = self.answered, []
            return answered

    def counts_taken(self):
        """A copy of the messages taken in per connection, dropped ones included."""
        with self._lock:
            return self._taken()

    def written_to(self, peer):
        """{(topic, port): messages written} on this process's connections to `peer`."""
        with self._lock:
            return {(topic, port): n for (topic, node, port), n in self.written.items()
                    if node == peer}

    def counts(self):
        """(taken, written): copies, for the simulator's board."""
        with self._lock:
            return self._taken(), dict(self.written)

    def _taken(self):
        """Taken in per connection, the messages its queue dropped unread included."""
        taken = dict(self.taken)
        if self._dropped:
            for (topic, peer, port) in list(taken):
                taken[(topic, peer, port)] += self._dropped.get((topic, port), 0)
        return taken

    def done(self):
        with self._lock:
            return self._done()

    def _done(self):
        if self._due:
            self._forget_ended()
        return not (self._running or self._calls or self._due or self.pending_writes())

    def _forget_ended(self):
        """A thread due when it ended (a loop that stopped after a look, rospy's reconnect
        thread of a publisher that went away) does nothing more: were it kept, the process
        would never be done again, and every report after it would wait for lockstep_timeout."""
        for tid in [tid for tid in self._due if not self.thread_alive(tid)]:
            self._due.discard(tid)
            self._sleeping.pop(tid, None)
            self._last.pop(tid, None)

    def _wake_sleepers(self, now):
        """Marks due the sleepers whose time has come; True if there were any, or if a
        sleeper's wake-up became known (the first /clock: next_wake changes)."""
        woke = False
        for tid, (start, wake, duration) in list(self._sleeping.items()):
            if wake is None:
                if now:
                    self._sleeping[tid] = (now, now + duration, duration)
                    woke = True
            elif now >= wake or now < start:
                self._due.add(tid)
                woke = True
        return woke

    def _wake_pollers(self, news=True):
        """Something happened: a held poller must look again before the process is done."""
        self._news = self._news or news
        if self._held:
            self._due.update(self._held)        # (its next poll, if it finds nothing to do,
            self._changed.notify_all()          # is a second one in a row: done again)

    def _after_change(self):
        if self.counting_only or self.watcher:
            return
        report = None
        with self._lock:
            if self._news and self._done() and self.reporting():
                report = self._report()
        if report is not None:
            self.send(report)

    def _report(self, whole=False):
        """The report: the connections whose counts changed since the last one (all with
        `whole`): totals, so the simulator keeps the others as they were."""
        self._news = False
        self.seq += 1
        taken, written = self._taken(), dict(self.written)
        if not whole:
            taken = {k: n for k, n in taken.items() if self._sent_taken.get(k) != n}
            written = {k: n for k, n in written.items() if self._sent_written.get(k) != n}
        self._sent_taken.update(taken)
        self._sent_written.update(written)
        served, self._served = self._served, []
        called, self._called = self._called, []
        wakes = [wake for _, wake, _ in self._sleeping.values() if wake is not None]
        if any(wake is None for _, wake, _ in self._sleeping.values()):
            wakes.append(1)             # waits for the first /clock: any tick wakes it
        return {"seq": self.seq, "taken": taken, "written": written,
                "served": served, "called": called, "next_wake": min(wakes, default=0),
                "watcher": self.watcher, "parked": sorted(self._parked())}

    def report_now(self):
        """A report of the counts as they are (for a simulator that just connected)."""
        with self._lock:
            if not (self._done() or self.watcher):
                self._news = True
                return None
            return self._report(whole=True)
