"""Child processes of the demo and the benchmark: a free port, starting commands in process
groups of their own with their output in log files, stopping them (SIGINT to the group, then
SIGTERM, then SIGKILL after time-outs), and finding any process left behind.

A process belongs to a run when its environment carries that run's ROS_MASTER_URI (every
child inherits it, and roslaunch passes it on to the nodes it starts in sessions of their
own), so `leftovers(master_uri)` finds orphans whoever their parent was.
"""
import os
import signal
import socket
import subprocess
import time

from ..tool_exit import Interrupted   # raised by raise_on_signals; tools end on it


def free_port(host="127.0.0.1"):
    """A TCP port nobody listens on now (the kernel's pick). Another program may take it
    before we bind it; callers retry on a clash."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return sock.getsockname()[1]


def port_in_use(port, host="127.0.0.1"):
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.settimeout(0.5)
        return sock.connect_ex((host, port)) == 0


def _default_sigint():
    """In a child between fork and exec: SIGINT as a fresh program gets it."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


class Child:
    """A command started in a new session (its own process group), output to a log file;
    with `user` and `group` (ids; needs root) as that user with no supplementary groups, in
    `cwd` when given."""

    def __init__(self, name, argv, env, log_path, pass_fds=(), user=None, group=None, cwd=None):
        self.name = name
        self.argv = list(argv)
        self.log_path = log_path
        os.makedirs(os.path.dirname(os.path.abspath(log_path)), exist_ok=True)
        self._log = open(log_path, "wb")
        as_user = {} if user is None else dict(user=user, group=group, extra_groups=[])
        # A child is stopped with SIGINT (stop()). A program started in the background by a
        # non-interactive shell (`nohup scripts/test.sh &`, some CI runners) has SIGINT
        # ignored, and an ignored signal stays ignored across exec: every ROS process started
        # from it would sit out the SIGINT and be stopped only by stop()'s SIGTERM, 20 s later.
        restore = _default_sigint if signal.getsignal(signal.SIGINT) == signal.SIG_IGN else None
        try:
            self.popen = subprocess.Popen(self.argv, env=env, stdout=self._log,
                                          stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                          start_new_session=True, pass_fds=tuple(pass_fds),
                                          cwd=cwd, preexec_fn=restore, **as_user)
        except OSError as err:
            self._log.close()
            raise RuntimeError("cannot start %s (%s): %s" % (name, " ".join(self.argv), err))
        self.pid = self.popen.pid
        self.started = time.monotonic()

    def running(self):
        return self.popen.poll() is None

    @property
    def returncode(self):
        return self.popen.poll()

    def wait(self, timeout):
        """Exit code, or None if still running after `timeout` [s]."""
        try:
            return self.popen.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None

    def log_tail(self, lines=20):
        self._log.flush()
        return log_tail(self.log_path, lines)

    def signal_group(self, signum):
        try:
            os.killpg(self.pid, signum)
        except ProcessLookupError:
            pass

    def close(self):
        self._log.close()


def stop(children, sigint_timeout=20.0, sigterm_timeout=5.0):
    """Stops `children` together: SIGINT to each one's process group, SIGTERM to those still
    running after `sigint_timeout` [s], SIGKILL after `sigterm_timeout` more. Returns
    {name: how it ended} ("exit N", "SIGTERM", "SIGKILL")."""
    outcome = {}
    steps = ((signal.SIGINT, sigint_timeout), (signal.SIGTERM, sigterm_timeout),
             (signal.SIGKILL, 5.0))
    pending = [c for c in children if c.running()]
    for child in children:
        if not child.running():
            outcome[child.name] = "exit %s" % child.returncode
    for signum, timeout in steps:
        for child in pending:
            child.signal_group(signum)
        deadline = time.monotonic() + timeout
        for child in pending:
            code = child.wait(max(0.0, deadline - time.monotonic()))
            if code is not None:
                outcome[child.name] = ("exit %s" % code if signum == signal.SIGINT
                                       else signal.Signals(signum).name)
        pending = [c for c in pending if c.running()]
        if not pending:
            break
    for child in children:
        child.close()
    return outcome


def environment_of(pid):
    """{name: value} of a process's start-up environment ({} when unreadable or gone)."""
    try:
        with open("/proc/%d/environ" % pid, "rb") as source:
            raw = source.read()
    except OSError:
        return {}
    env = {}
    for item in raw.split(b"\0"):
        name, sep, value = item.partition(b"=")
        if sep:
            env[name.decode("utf-8", "replace")] = value.decode("utf-8", "replace")
    return env


def leftovers(master_uri, exclude=()):
    """PIDs of live processes (zombies excluded) started with ROS_MASTER_URI == master_uri,
    other than this process and `exclude`."""
    return tagged("ROS_MASTER_URI", master_uri, exclude)


def tagged(name, value, exclude=()):
    """PIDs of live processes (zombies excluded) whose start-up environment has name=value,
    other than this process and `exclude`."""
    skip = {os.getpid(), *exclude}
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) in skip:
            continue
        pid = int(entry)
        if environment_of(pid).get(name) == value and not _zombie(pid):
            found.append(pid)
    return sorted(found)


def alive(pid):
    """True while `pid` is a live process (not a zombie)."""
    return os.path.exists("/proc/%d" % pid) and not _zombie(pid)


def _zombie(pid):
    try:
        with open("/proc/%d/stat" % pid) as source:
            return source.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except (OSError, IndexError):
        return True


def describe(pids):
    """`ps` lines (pid, state, command) of `pids`, for an error message."""
    if not pids:
        return ""
    result = subprocess.run(["ps", "-o", "pid=,stat=,args=", "-p", ",".join(map(str, pids))],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    return result.stdout.rstrip()


def kill_leftovers(master_uri, exclude=(), timeout=5.0):
    """SIGTERM, then SIGKILL, to every process of the run still alive; returns the `ps`
    description of what was found (empty when nothing was)."""
    return kill_tagged("ROS_MASTER_URI", master_uri, exclude, timeout)


def kill_tagged(name, value, exclude=(), timeout=5.0):
    """SIGTERM, then SIGKILL, to every live process whose environment has name=value (by
    PID); returns the `ps` description of what was found (empty when nothing was)."""
    pids = tagged(name, value, exclude)
    if not pids:
        return ""
    text = describe(pids)
    for signum in (signal.SIGTERM, signal.SIGKILL):
        for pid in pids:
            try:
                os.kill(pid, signum)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and tagged(name, value, exclude):
            time.sleep(0.1)
        pids = tagged(name, value, exclude)
        if not pids:
            break
    return text


def peak_rss_kib(pid):
    """VmHWM (peak resident set) of a process [KiB], or None when it is gone."""
    return _status_field(pid, "VmHWM")


def rss_kib(pid):
    """VmRSS (resident set now) of a process [KiB], or None when it is gone."""
    return _status_field(pid, "VmRSS")


def _status_field(pid, field):
    try:
        with open("/proc/%d/status" % pid) as source:
            for line in source:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
    except (OSError, ValueError, IndexError):
        return None
    return None


def cpu_seconds(pid, children=False):
    """User + system CPU time a process has used [s] (with `children`, plus that of the
    children it has reaped), or None when it is gone."""
    try:
        with open("/proc/%d/stat" % pid) as source:
            fields = source.read().rsplit(")", 1)[1].split()
        ticks = int(fields[11]) + int(fields[12])
        if children:
            ticks += int(fields[13]) + int(fields[14])
        return ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def log_tail(path, lines=20):
    """The last `lines` lines of a log file ("" when it cannot be read)."""
    try:
        with open(path, "rb") as log:
            text = log.read().decode("utf-8", "replace")
    except OSError:
        return ""
    return "\n".join(text.rstrip().splitlines()[-lines:])


def raise_on_signals():
    """From now on SIGINT and SIGTERM raise Interrupted in the main thread, so a tool stops
    what it started and reports instead of printing a traceback. Returns the handlers it
    replaced, {signal: handler}, for a caller that restores them."""
    def interrupt(signum, _frame):
        raise Interrupted(signal.Signals(signum).name)
    return {s: signal.signal(s, interrupt) for s in (signal.SIGINT, signal.SIGTERM)}
