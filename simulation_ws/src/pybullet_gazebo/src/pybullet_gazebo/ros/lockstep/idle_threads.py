"""Whether processes have finished with what they were sent, as Linux shows it: lockstep's
fallback for the controllers that cannot say so themselves (gate.py; a process of the
project's environment reports instead, lockstep/).

A controller that sends no reports (roscpp, a Python outside the project's venv) is watched
in its process, as the kernel sees it: a process is idle when
none of its threads is running or waiting for a CPU (state R in /proc/PID/task/TID/stat) or
in an uninterruptible wait (D). That holds on a loaded machine too: a thread that waits for a
CPU is R.

Why "all threads asleep" means "done with what it was sent":
- on localhost, writing to a socket wakes its reader inside the write call, so a message
  the simulator has sent makes its reader R before the send returns;
- a Python thread that waits for the GIL sleeps, but only while another thread of its
  process holds the GIL, and that one is R (a thread that releases the GIL wakes the next
  before it sleeps itself);
- a controller's command travels the same way back: once its process is idle, the command
  is in the simulator's socket or being read there (OwnReceivers checks that side);
- except that the kernel may leave a loopback packet in a CPU's input backlog, for its
  ksoftirqd thread to deliver later (on a loaded machine): until then no reader is woken.
  So nobody is idle while a backlog holds packets (/proc/net/softnet_stat's backlog
  column, Linux 5.10 and later; on older kernels this check is skipped).

A look is not a snapshot: it reads the threads one after another, and work may pass from a
thread not yet read to one already read (a reader thread hands a message to the main thread
and goes back to its socket; a node answers a service call another node sleeps on). So a look
that finds everyone idle is confirmed by a second one: every thread still asleep and none of
them run in between (the run counts of /proc/PID/task/TID/schedstat, read before each thread's
state in the first look, unchanged). Then there was a moment, between the two looks, when all
slept with nothing handed on (a thread only falls asleep by running). Measured on bug 2 (four
nodes handing work on through service calls): without the second look, one run in two took a
switch at a different tick.

Busy loops. A thread that never sleeps (the series' go_to_point spins in
`while not rospy.is_shutdown(): if not active_: continue` while switched off) is never idle.
A thread seen running at every look for SPIN_WALL of wall time, having had at least
SPIN_SHARE of a CPU in that time (less is a thread waiting for a CPU on a loaded machine), is
taken for a busy loop and not waited for, until it is seen asleep while every other thread
of its process sleeps too (asleep beside a running thread, it may only be waiting for the
GIL; with no thread of its process running, nobody holds the GIL). The look that starts a
wait starts the count afresh: a thread running at two looks with an idle spell between them
is no busy loop. A thread that computes for longer than SPIN_WALL at once is taken for one
too: lockstep then steps on without waiting for its answer.
Beside a busy loop, "asleep" is not "done": the busy loop holds the GIL, and a thread woken
by a message sleeps until it gets it (Python hands it over after its 5 ms switch interval).
So in a process with a busy loop, a sleeping thread counts as done only if it has not run
since the last message went out (its count of runs in /proc/.../schedstat), or it sleeps in
a socket wait (back to reading: done), or it has not run while the busy loop ran for
GIL_WAIT of CPU (a thread waiting for the GIL wakes every 5 ms, the switch interval, to ask
for it, or waits for the busy loop to release the GIL's mutex, which takes the busy loop's
running: on a loaded machine, where the busy loop waits for a CPU, this takes longer). A
busy loop thus costs lockstep about one switch interval of wall time per message its process
gets, as it delays that process's callbacks at real time.

Polling. A wait looks again every POLL of wall time. Linux lets a thread's short sleeps run
late by its timer slack (50 us by default, so the kernel can batch wake-ups), which would
make each short sleep several times as long; the waiting thread asks for a slack of 1 ns
(precise_sleeps). A rospy.Rate loop's tick passes from thread to thread (its /clock reader
wakes the loop, which publishes through rospy's writer thread), and every hand-off the wait
sees late costs it a whole sleep.

Linux only (/proc); threads of processes on other machines cannot be watched.
"""
import ctypes
import os
import threading
import time

SPIN_WALL = 0.1          # [s] wall: running at every look for this long ...
SPIN_SHARE = 0.25        # ... on at least this share of a CPU: a busy loop
GIL_WAIT = 0.02          # [s] of the busy loop's CPU: 4 of Python's 5 ms switch intervals (a
                         # waiter's 5 ms timed wake comes late on a loaded machine: 6 ms
                         # let one in five unit runs take a GIL waiter for done)

# system call numbers of the socket waits a reader sleeps in (x86_64, aarch64)
SOCKET_WAITS = {
    "x86_64": {0, 7, 23, 43, 45, 47, 232, 270, 271, 281, 288},   # read poll select accept
    #         recvfrom recvmsg epoll_wait pselect6 ppoll epoll_pwait accept4
    "aarch64": {63, 73, 72, 202, 207, 212, 22, 242},   # read ppoll pselect6 accept recvfrom
    #         recvmsg epoll_pwait accept4
}.get(os.uname().machine, set())

_BUSY_STATES = (ord("R"), ord("D"))
_PR_SET_TIMERSLACK = 29


def precise_sleeps():
    """Asks Linux to end the calling thread's sleeps on time (a timer slack of 1 ns, see
    the module docstring). Elsewhere, or if the call fails, sleeps stay as they were."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_TIMERSLACK, 1, 0, 0, 0)
    except (OSError, AttributeError):
        pass


def state_of(stat):
    """The state letter (as a byte value) of a /proc/.../stat line; its command name may hold
    spaces and parentheses, so the state is found after the last ')'."""
    return stat[stat.rindex(b")") + 2]


def in_socket_wait(syscall):
    """Whether a /proc/.../syscall line says its thread sleeps in a socket wait (SOCKET_WAITS)."""
    call = syscall.split(None, 1)[0] if syscall.strip() else b""
    return call.isdigit() and int(call) in SOCKET_WAITS


class _Thread:
    """What the watch remembers of one thread."""
    __slots__ = ("fd", "sched_fd", "runs", "busy_since", "cpu_since", "spinning",
                 "runs_at_send", "runs_seen", "runs_seen_at")

    def __init__(self, fd, sched_fd):
        self.fd = fd                # its /proc stat, for its state
        self.sched_fd = sched_fd    # its /proc schedstat: CPU time, wait and count of runs
        self.runs = None            # that schedstat at the last look
        self.busy_since = None      # [s] monotonic: first seen running in this streak
        self.cpu_since = 0          # [ns] its CPU time then
        self.spinning = False
        self.runs_at_send = None    # its count of runs when the last message went out
        self.runs_seen = None       # its count of runs at the last look (beside a busy loop)
        self.runs_seen_at = None    # [ns] the busy loops' CPU time when that count was seen


class ProcessThreads:
    """The threads of one process, their /proc stat files kept open (re-read with pread)."""

    def __init__(self, pid, on_spin=lambda pid, tid: None):
        self.pid = pid
        self.task_dir = "/proc/%d/task" % pid
        self.threads = {}           # tid -> _Thread
        self.on_spin = on_spin      # told (pid, tid) when a thread is taken for a busy loop

    def busy_thread(self, now, round_start):
        """A tid that is running and not a busy loop (None: the process is idle), or False
        when the process is gone. `round_start`: when the present wait began."""
        running = self._states(note_runs=True)
        if running is None:
            return False
        threads = self.threads
        others_run = any(run for tid, run in running.items() if not threads[tid].spinning)
        spinners = [tid for tid, t in threads.items() if t.spinning]
        spun = sum(self._cpu_ns(tid) for tid in spinners) if spinners else None
        busy = None
        for tid, run in running.items():
            thread = threads[tid]
            if thread.spinning:
                if not run and not others_run:
                    thread.spinning = False                # asleep, and not for the GIL
                continue
            if not run:
                thread.busy_since = None
                if spinners and not self._done_beside_spinner(tid, thread, spun):
                    busy = tid if busy is None else busy
                continue
            if thread.busy_since is None or thread.busy_since < round_start:
                thread.busy_since, thread.cpu_since = now, self._cpu_ns(tid)
            elif now - thread.busy_since >= SPIN_WALL and self._cpu_ns(tid) - \
                    thread.cpu_since >= SPIN_SHARE * 1e9 * (now - thread.busy_since):
                thread.spinning = True
                self.on_spin(self.pid, tid)
                continue
            if busy is None:
                busy = tid
        return busy

    def spinners(self):
        return [tid for tid, t in self.threads.items() if t.spinning]

    def running(self, tid):
        """Whether thread `tid` (seen before) runs or waits for a CPU now."""
        thread = self.threads.get(tid)
        try:
            return thread is not None and \
                state_of(os.pread(thread.fd, 512, 0)) in _BUSY_STATES
        except (OSError, ValueError, IndexError):
            return False

    def _states(self, note_runs):
        """{tid: running or waiting for a CPU} of every thread now, those new since the last
        look too (ended ones forgotten), or None when the process is gone. `note_runs`: keep
        each thread's schedstat, read before its state, for moved_since_look."""
        try:
            tids = [int(name) for name in os.listdir(self.task_dir)]
        except OSError:
            return None
        running = {}
        for tid in tids:
            thread = self.threads.get(tid)
            try:
                if thread is None:
                    thread = self.threads[tid] = self._open(tid)
                if note_runs:
                    thread.runs = os.pread(thread.sched_fd, 128, 0)
                running[tid] = state_of(os.pread(thread.fd, 512, 0)) in _BUSY_STATES
            except (OSError, ValueError, IndexError):
                continue                                   # the thread ended meanwhile
        if len(self.threads) > len(tids):
            self._forget_ended(set(tids))
        return running

    def moved_since_look(self):
        """After a look that found this process idle: a tid that is running or has run since
        (or True for a thread that came meanwhile), None if all slept through. A process with
        a busy loop is left to the look's rules (its threads waiting for the GIL run every
        switch interval)."""
        threads = self.threads
        if any(t.spinning for t in threads.values()):
            return None
        try:
            if len(os.listdir(self.task_dir)) != len(threads):
                return True
        except OSError:
            return None                                    # ended: nothing left to do
        for tid, thread in threads.items():
            try:
                if state_of(os.pread(thread.fd, 512, 0)) in _BUSY_STATES or \
                        os.pread(thread.sched_fd, 128, 0) != thread.runs:
                    return tid
            except (OSError, ValueError, IndexError):
                continue                                   # the thread ended meanwhile
        return None

    def _open(self, tid):
        base = "%s/%d/" % (self.task_dir, tid)
        fd = os.open(base + "stat", os.O_RDONLY)
        try:
            return _Thread(fd, os.open(base + "schedstat", os.O_RDONLY))
        except OSError:
            os.close(fd)
            raise

    def note_sent(self):
        """A message went out to this process: beside a busy loop, remember how often each
        thread has run so far."""
        if any(t.spinning for t in self.threads.values()):
            for tid, thread in self.threads.items():
                if not thread.spinning:
                    thread.runs_at_send = self._schedstat(tid, 2)

    def _done_beside_spinner(self, tid, thread, spun):
        """A sleeping thread in a process with a busy loop: done with what it was sent?
        `spun` [ns]: the busy loops' CPU time now."""
        runs = self._schedstat(tid, 2)
        if runs == thread.runs_at_send:
            return True                            # it has not run since the message
        try:
            with open("%s/%d/syscall" % (self.task_dir, tid), "rb") as f:
                if in_socket_wait(f.read()):
                    return True                    # back to reading its socket
        except OSError:
            return True                            # ended
        if runs != thread.runs_seen:
            thread.runs_seen, thread.runs_seen_at = runs, spun
            return False
        return spun - thread.runs_seen_at >= GIL_WAIT * 1e9   # no GIL waiter sleeps so long

    def _cpu_ns(self, tid):
        return self._schedstat(tid, 0)

    def _schedstat(self, tid, field):
        """A field of /proc/PID/task/TID/schedstat: 0 = CPU time [ns], 2 = runs."""
        try:
            with open("%s/%d/schedstat" % (self.task_dir, tid), "rb") as f:
                return int(f.read().split()[field])
        except (OSError, ValueError, IndexError):
            return 0

    def _forget_ended(self, present):
        for tid in [t for t in self.threads if t not in present]:
            thread = self.threads.pop(tid)
            os.close(thread.fd)
            os.close(thread.sched_fd)

    def close(self):
        for thread in self.threads.values():
            os.close(thread.fd)
            os.close(thread.sched_fd)
        self.threads.clear()


def _backlog_columns(columns):
    """The columns of softnet_stat that count packets not yet delivered, for a line of
    `columns` columns: from Linux 6.0 (15 columns) the input queue (13) and the queue being
    processed (14); from 5.10 (13 columns) the input queue (11); none before."""
    if columns >= 15:
        return (13, 14)
    if columns >= 13:
        return (11,)
    return ()


class KernelBacklog:
    """Packets in the CPUs' input backlogs, not yet delivered to any socket."""

    def __init__(self):
        try:
            with open("/proc/net/softnet_stat", "rb") as f:
                self.columns = _backlog_columns(len(f.readline().split()))
        except OSError:
            self.columns = ()
        self._fd = os.open("/proc/net/softnet_stat", os.O_RDONLY) if self.columns else None

    def packets(self):
        if self._fd is None:
            return 0
        data = os.pread(self._fd, 4096, 0)
        return sum(int(fields[c], 16) for fields in map(bytes.split, data.splitlines())
                   for c in self.columns)

    def close(self):
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None


class IdleWatch:
    """Waits until a set of processes is idle (see the module docstring)."""

    POLL = 0.00003           # [s] wall between looks (with precise_sleeps: ~55 us)
    FOLLOW = 0.01            # [s] wall: how long a wait may watch one running thread alone
                             # (then whole looks again, which find busy loops)

    def __init__(self, own_busy=lambda: False, own_moved=lambda: False,
                 on_spin=lambda pid, tid: None):
        self.own_busy = own_busy            # the simulator's own side (OwnReceivers.busy)
        self.own_moved = own_moved          # ... and its second look (OwnReceivers.moved)
        self.on_spin = on_spin              # told (pid, tid) of a thread taken for a busy loop
        self.backlog = KernelBacklog()
        self._processes = {}                # pid -> ProcessThreads
        self._round_start = 0.0             # [s] monotonic: when the present wait began
        self._precise_thread = None         # the thread whose sleeps precise_sleeps shortened

    def watch(self, pids):
        """From now on, the processes `pids` (an iterable of ints)."""
        pids = set(pids)
        for pid in [p for p in self._processes if p not in pids]:
            self._processes.pop(pid).close()
        for pid in pids:
            if pid not in self._processes:
                self._processes[pid] = ProcessThreads(pid, on_spin=self.on_spin)

    def note_sent(self):
        """A message went out to the watched processes (see ProcessThreads.note_sent)."""
        for process in self._processes.values():
            process.note_sent()

    @property
    def pids(self):
        return set(self._processes)

    def busy(self, new_round=True):
        """(pid, tid) of a thread still at work, ("self", None) for the simulator's own
        receivers, ("kernel", n) for n packets not yet delivered, or None when all are idle.
        Processes that ended are dropped.
        `new_round`: this look starts a wait (see the module docstring on busy loops)."""
        now = time.monotonic()
        if new_round:
            self._round_start = now
        packets = self.backlog.packets()
        if packets:
            return "kernel", packets
        busy = self._first_busy(lambda p: p.busy_thread(now, self._round_start))
        if busy is not None:
            return busy
        if self.own_busy():
            return "self", None
        return self._second_look()

    def _first_busy(self, look):
        """(pid, tid) of the first process in which `look(process)` finds a thread at work,
        or None; processes it finds gone (False) are dropped."""
        for pid, process in list(self._processes.items()):
            tid = look(process)
            if tid is False:
                self._processes.pop(pid).close()
            elif tid is not None:
                return pid, tid
        return None

    def _second_look(self):
        """After a look that found all idle: what has moved since (see the module docstring),
        or None."""
        packets = self.backlog.packets()
        if packets:
            return "kernel", packets
        for pid, process in self._processes.items():
            tid = process.moved_since_look()
            if tid is not None:
                return pid, tid
        if self.own_moved():
            return "self", None
        return None

    def wait(self, deadline, interrupted=lambda: False, busy=None):
        """Waits until every watched process is idle (None) or the monotonic clock reaches
        `deadline` or interrupted() is true (the (pid, tid) still busy). `busy`: what the
        look just before found at work (busy()'s answer), followed first: a second whole look
        at once would find the same thread and cost a large part of the controller's whole
        tick (a look reads every thread's state in /proc)."""
        if self._precise_thread != threading.get_ident():
            precise_sleeps()
            self._precise_thread = threading.get_ident()
        follow_until = time.monotonic() + self.FOLLOW
        while True:
            # while one thread is at work, look at it alone (one read, not a look at all)
            if busy is None or not self._still_running(busy) or \
                    time.monotonic() >= follow_until:
                busy = self.busy(new_round=False)
                if busy is None:
                    return None
            if time.monotonic() >= deadline or interrupted():
                return busy
            time.sleep(self.POLL)

    def _still_running(self, busy):
        pid, tid = busy
        process = self._processes.get(pid)
        return process is not None and process.running(tid)

    def spinners(self):
        """{pid: [tid, ...]} of the threads taken for busy loops now."""
        return {pid: p.spinners() for pid, p in self._processes.items() if p.spinners()}

    def close(self):
        self.watch(())
        self.backlog.close()
