"""Isolation of a submission's run: what it runs as, what it may use, and its end.

When the grader runs as root (as in CI), each Dask worker claims a slot (a lock file under
SLOTS_DIR, held for the worker's life) and its runs start as that slot's unprivileged
system user, `m2wr-grade<N>` (created with useradd on first use; no home, no login shell,
no groups): two runs at once never share a user. A run's files are a copy of the student's
packages in a folder of its own (mode 0700, owned by that user) under RUNS_DIR (0711 root:
runs cannot list each other); the class folder, the grader's output and the other runs'
folders are not readable by it (the grader makes its output 0700 and warns when CLASS_DIR
is readable by others). Every process of the run:
  - starts with RLIMIT_CPU (CPU seconds a process), RLIMIT_AS (address space a process),
    RLIMIT_NPROC (processes and threads of the user), RLIMIT_FSIZE (largest file) and no
    core dumps (`rlimits`), in a process group of its own: a Python script forked from the
    worker's warm zygote, which sets them and the user in the child before the script's
    first line (m2wr_tools.running.zygote), anything else through `prlimit` (`limited`); what the
    child runs starts as the user either way;
  - is watched (Watchdog, every WATCH_PERIOD s): the resident memory of all the user's
    processes together over the limit ends them all at once (a fork-and-allocate loop
    cannot take the machine's memory before the next look);
  - and at the run's end is stopped by PID: every process of the slot's user, found in
    /proc whatever its process group or parent (kill_user).
A user cannot signal processes of another user (the simulator, the master, the grader run
as root). Not isolated: the network (a run may open sockets, talk to the ROS master and
nodes over XML-RPC, or reach other hosts), /tmp and other world-writable folders, the CPU
share (a run's busy processes compete with the simulator's). Without root, runs start as
the grader's own user with the same limits, watchdog and end, and the report says so.
"""
import fcntl
import os
import pwd
import shutil
import signal
import stat
import subprocess
import threading
import time

from ..running import processes

SLOTS_DIR = "/tmp/m2wr-grade-slots"
RUNS_DIR = "/tmp/m2wr-grade-runs"
USER = "m2wr-grade%d"
MAX_SLOTS = 64
WATCH_PERIOD = 0.1            # [s] wall between two looks at the run's memory
MIB = 1024 * 1024
ADDRESS_SPACE_MIB = 4096      # [MiB] RLIMIT_AS of each process (rospy's threads reserve
                              # much address space they never touch; memory_mib bounds RSS)


def isolating():
    """True when runs can start as other users (this process is root)."""
    return os.geteuid() == 0


class Slot:
    """This worker's run user: (uid, gid) and the lock that makes it ours."""

    def __init__(self):
        self.index, self._lock = _claim()
        self.uid, self.gid = _user(USER % self.index) if isolating() else (os.getuid(),
                                                                            os.getgid())
        self.name = pwd.getpwuid(self.uid).pw_name

    def close(self):
        if self._lock is not None:
            self._lock.close()
            self._lock = None


def _claim():
    os.makedirs(SLOTS_DIR, mode=0o700, exist_ok=True)
    for index in range(MAX_SLOTS):
        handle = open(os.path.join(SLOTS_DIR, "%d.lock" % index), "w")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        return index, handle
    raise RuntimeError("all %d grading slots of %s are taken; are that many graders running?"
                       % (MAX_SLOTS, SLOTS_DIR))


def _user(name):
    """(uid, gid) of system user `name`, created (no home, no login) when missing."""
    try:
        entry = pwd.getpwnam(name)
    except KeyError:
        result = subprocess.run(["useradd", "--system", "--no-create-home", "--user-group",
                                 "--shell", "/usr/sbin/nologin", name],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if result.returncode not in (0, 9):           # 9: made meanwhile by another worker
            raise RuntimeError("cannot create the run user %s: %s" % (name, result.stdout))
        entry = pwd.getpwnam(name)
    return entry.pw_uid, entry.pw_gid


def prepare(slot, run_name, packages_from):
    """A fresh folder for one run, owned by the slot's user, mode 0700: ws/ (a copy of the
    packages in `packages_from`) and home/ (HOME, ROS_HOME, ROS_LOG_DIR). Returns its path."""
    os.makedirs(RUNS_DIR, exist_ok=True)
    os.chmod(RUNS_DIR, 0o711)
    folder = os.path.join(RUNS_DIR, "%s-%d" % (run_name, slot.index))
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder, mode=0o700)
    shutil.copytree(packages_from, os.path.join(folder, "ws"), symlinks=True)
    os.makedirs(os.path.join(folder, "home", "log"))
    for dirpath, dirs, files in os.walk(folder):
        for name in [dirpath] + [os.path.join(dirpath, n) for n in dirs + files]:
            os.lchown(name, slot.uid, slot.gid)
    os.chmod(folder, 0o700)
    return folder


def remove(folder):
    shutil.rmtree(folder, ignore_errors=True)


def environment(env, folder):
    """`env` with the run folder's home: HOME, ROS_HOME, ROS_LOG_DIR."""
    home = os.path.join(folder, "home")
    return dict(env, HOME=home, ROS_HOME=home, ROS_LOG_DIR=os.path.join(home, "log"))


def closed_to_others(path):
    """The first folder on the way to `path` (itself included) that other users cannot pass
    (no o+x), or None: a run's user must reach the project's packages and Python."""
    path = os.path.abspath(path)
    folders = [path]
    while os.path.dirname(folders[-1]) != folders[-1]:
        folders.append(os.path.dirname(folders[-1]))
    for folder in reversed(folders):
        if not os.stat(folder).st_mode & stat.S_IXOTH:
            return folder
    return None


def rlimits(limits, own_user):
    """The spec's limits (spec.Limits) as (RLIMIT_* name, value) pairs, soft = hard.
    RLIMIT_NPROC counts every process of the user, so it is set only when the run has a user
    of its own (`own_user`)."""
    pairs = [("RLIMIT_CPU", max(1, int(limits.cpu_s))), ("RLIMIT_AS", ADDRESS_SPACE_MIB * MIB)]
    if own_user:
        pairs.append(("RLIMIT_NPROC", int(limits.processes)))
    return pairs + [("RLIMIT_FSIZE", int(limits.file_mib * MIB)), ("RLIMIT_CORE", 0)]


def limited(argv, limits, own_user):
    """`argv` started through prlimit with the limits of `rlimits`."""
    return ["prlimit"] + ["--%s=%d" % (name[len("RLIMIT_"):].lower(), value)
                          for name, value in rlimits(limits, own_user)] + ["--"] + list(argv)


def pids_of_user(uid):
    """PIDs of the live processes whose real uid is `uid` (never this process)."""
    found, me = [], os.getpid()
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == me:
            continue
        try:
            with open("/proc/%s/status" % entry, "rb") as status:
                text = status.read()
        except OSError:
            continue
        # only the two lines needed (the watchdog reads every process 10 times a second)
        if _status_field(text, b"Uid") == str(uid).encode() and \
                _status_field(text, b"State") not in (b"Z", b"X"):
            found.append(int(entry))
    return sorted(found)


def _status_field(text, name):
    """The first word of field `name` in a /proc/PID/status text (bytes), or None."""
    at = text.find(b"\n" + name + b":")
    if at < 0:
        return None
    words = text[at + len(name) + 2:].split(None, 1)
    return words[0] if words else None


def kill_user(uid, timeout=5.0):
    """SIGKILL to every process of `uid`, by PID, until none is left; returns the `ps`
    lines of what was found ("" when nothing). Never for this process's own uid."""
    if uid == os.getuid():
        return ""
    pids = pids_of_user(uid)
    text = processes.describe(pids)
    deadline = time.monotonic() + timeout
    while pids and time.monotonic() < deadline:
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        time.sleep(0.02)
        pids = pids_of_user(uid)
    return text


def memory_of(pids):
    """Resident memory [MiB] of `pids` together."""
    return sum(processes.rss_kib(p) or 0 for p in pids) / 1024.0


class Watchdog(threading.Thread):
    """Watches a run's processes: the user's (isolated) or the controller's process group;
    ends them all once their resident memory together passes `memory_mib`; calls `also()`
    at each look (the grader's rules). `finding` says what it did, or stays None."""

    def __init__(self, pids, memory_mib, kill, also=lambda: None):
        super().__init__(daemon=True, name="m2wr-grade-watchdog")
        self.pids, self.memory_mib, self.kill, self.also = pids, memory_mib, kill, also
        self.finding = None
        self.seen = ""
        self.peak_mib = 0.0
        self._halt = threading.Event()

    def run(self):
        while not self._halt.wait(WATCH_PERIOD):
            self.look()

    def look(self):
        pids = self.pids()
        used = memory_of(pids)
        self.peak_mib = max(self.peak_mib, used)
        if used > self.memory_mib and self.finding is None:
            # the same words whatever the timing (the gradebook stays the same); the figures
            # seen are in `seen`
            self.finding = ("resources: its processes used more than the %.0f MiB of memory "
                            "allowed together; all were stopped" % self.memory_mib)
            self.seen = "%d processes, %.0f MiB" % (len(pids), used)
            self.kill()
        try:
            self.also()
        except Exception:          # the rules' look may fail while the graph changes
            pass

    def stop(self):
        """Ends the looks with a last one; again, does nothing (the run's end calls it once
        its processes are stopped, when a look finds nothing and costs ~2 ms)."""
        if self._halt.is_set():
            return
        self._halt.set()
        if self.is_alive():
            self.join(timeout=5.0)
        self.look()


def group_members(pgid):
    """PIDs of the live processes in process group `pgid`."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.getpgid(int(entry)) == pgid and processes.alive(int(entry)):
                    found.append(int(entry))
            except OSError:
                pass
    return found

