"""A warm start for Python controllers: a process that has already imported rospy and the
message modules a controller usually needs, and forks a fresh child per run which runs the
controller's script as __main__, as `python SCRIPT ARGS` would.

Most of what starting a Python controller costs is imports (rospy, genpy, the message
classes): a second of CPU or more; a fork of a process that has them costs milliseconds.
The child is still the user's unmodified program started afresh: its own process (and
process group, so the batch stops it as it stops any controller), `sys.argv` = [SCRIPT,
ARGS...], `sys.path[0]` = the script's folder, its own environment, stdin from /dev/null,
stdout and stderr to the run's log file, and its exit status is the script's (sys.exit(n) ->
n, an uncaught exception -> the traceback in the log and status 1, a signal -> -signum as
subprocess reports it). Only the imports are shared, never initialised: the zygote itself
never calls rospy.init_node and runs no thread, so a child's node starts as a fresh one.
Python's `random` reseeds itself in every child; numpy's global generator is reseeded from
the OS too. The one thing a child shares with its siblings is Python's string-hash seed.
In a child, three of rospy's idle waits are shorter and its rospy.spin() tells the zygote
when the program enters it (m2wr_tools.running.warm_rospy): the program's own behaviour is the same.

Which commands can use it (`warm_script`): a `.py` script run by this interpreter, either
given as `PYTHON SCRIPT ARGS` or as an executable script whose `#!` line names `python` or
`python3` through /usr/bin/env (found on PATH as this interpreter) or this interpreter's path.
A roslaunch command line that m2wr_tools.running.warm_launch takes runs warm too: the child
reads the launch file and forks its Python nodes in turn. Anything else (a binary, a bash
script, another Python, roslaunch with other options) runs as a plain subprocess.

For the grader, a child can also start as another user in a folder of its own with resource
limits (`start(..., cwd=, user=, group=, rlimits=)`): set in the child after the fork, before
the program's first line, as prlimit and a change of user would set them for a new process.
The zygote runs as the worker's user (root, where the grader isolates runs); a child that
drops to the run's user keeps nothing of root's (no supplementary groups, real and effective
ids both changed).

Protocol (between `Zygote` in the batch worker and `serve` in the zygote process, over a
socket pair, one JSON object a line): -> {"run": [argv...], "log": path, "env": {...},
optionally "cwd": path, "uid": N, "gid": N, "rlimits": [[name, value], ...], "launch": true
(argv is a roslaunch command line: m2wr_tools.running.warm_launch runs it)} ;
<- {"pid": N} or {"error": text}; later <- {"spinning": N} when child N first enters
rospy.spin() (its node is set up), and {"exit": N, "pid": N} when it ends.
"""
import json
import os
import select
import shutil
import signal
import socket
import sys
import threading
import time

from . import processes, warm_launch

PRELOAD = ("rospy", "std_msgs.msg", "sensor_msgs.msg", "geometry_msgs.msg", "nav_msgs.msg",
           "tf2_msgs.msg", "gazebo_msgs.msg", "gazebo_msgs.srv", "std_srvs.srv", "numpy")
# (roslaunch's modules are not among them: the launcher imports them itself, rather than
# every warm child's resident size growing by theirs, which the grader reports as the
# student's memory)


def warm_script(argv, path_env):
    """(script, args) when `argv` runs a Python script with this interpreter, else None.
    `path_env`: the PATH the command would be looked up on."""
    argv = list(argv)
    if not argv:
        return None
    if _is_this_python(argv[0], path_env):
        if len(argv) >= 2 and argv[1].endswith(".py") and os.path.isfile(argv[1]):
            return os.path.abspath(argv[1]), argv[2:]
        return None
    script = argv[0]
    if not (os.path.isfile(script) and os.access(script, os.X_OK)):
        return None
    try:
        with open(script, "rb") as source:
            first = source.readline(256).decode("utf-8", "replace").strip()
    except OSError:
        return None
    if not first.startswith("#!"):
        return None
    words = first[2:].split()
    if len(words) == 2 and words[0] == "/usr/bin/env":
        interpreter = words[1]
    elif len(words) == 1:
        interpreter = words[0]
    else:
        return None                       # interpreter flags (python -u ...): run as is
    if os.path.basename(interpreter) not in ("python", "python3") \
            or not _is_this_python(interpreter, path_env):
        return None
    return os.path.abspath(script), argv[1:]


def _is_this_python(name, path_env):
    found = shutil.which(name, path=path_env) if os.sep not in name else name
    if not found:
        return False
    return os.path.dirname(os.path.abspath(found)) == os.path.dirname(sys.executable) \
        and os.path.realpath(found) == os.path.realpath(sys.executable)


# --- the batch worker's side ----------------------------------------------------------------
class Zygote:
    """The zygote process of one session (started with the session's environment) and the
    children it forks, which look like processes.Child to their users."""

    def __init__(self, env, log_path):
        ours, theirs = socket.socketpair()
        ours.settimeout(None)            # blocking, whatever socket's default timeout is
        self._socket = ours
        self._reader = ours.makefile("r", encoding="utf-8")
        self._lock = threading.Lock()            # one request at a time
        self._answers = []
        self._answer = threading.Condition()
        self._exits = {}                         # pid -> exit status
        self._spinning = set()                   # pids that have entered rospy.spin()
        env = dict(env, M2WR_ZYGOTE_FD=str(theirs.fileno()))
        try:
            self.process = processes.Child(
                "zygote", [sys.executable, "-m", "m2wr_tools.running.zygote"], env, log_path,
                pass_fds=(theirs.fileno(),))
        finally:
            theirs.close()
        self._thread = threading.Thread(target=self._listen, name="zygote-listener",
                                        daemon=True)
        self._thread.start()

    def running(self):
        return self.process.running()

    def _listen(self):
        while True:
            try:
                line = self._reader.readline()
            except (OSError, ValueError):     # closed
                line = ""
            if not line:
                break
            try:
                message = json.loads(line)
            except ValueError:
                continue
            with self._answer:
                if "exit" in message:
                    self._exits[message["pid"]] = message["exit"]
                    self._spinning.discard(message["pid"])
                elif "spinning" in message:
                    self._spinning.add(message["spinning"])
                else:
                    self._answers.append(message)
                self._answer.notify_all()
        with self._answer:                       # the zygote is gone
            self._answer.notify_all()

    def start(self, name, argv, env, log_path, timeout=10.0, cwd=None, user=None, group=None,
              rlimits=(), launch=False):
        """A child running `argv` (warm_script must accept it) with `env`, output to
        log_path; a ZygoteChild. RuntimeError when the zygote cannot start it. `cwd`: its
        working folder; `user`, `group`: the ids it runs as; `rlimits`: (name, value) pairs
        of the resource module's RLIMIT_* limits, soft and hard. `launch`: `argv` is a
        roslaunch command line that warm_launch.accepts, run by warm_launch."""
        request = {"run": list(argv), "env": dict(env), "log": log_path}
        if launch:
            request["launch"] = True
        if cwd is not None:
            request["cwd"] = cwd
        if user is not None:
            request.update(uid=int(user), gid=int(group if group is not None else user))
        if rlimits:
            request["rlimits"] = [[name, int(value)] for name, value in rlimits]
        request = json.dumps(request) + "\n"
        with self._lock:
            try:
                self._socket.sendall(request.encode("utf-8"))
            except OSError as err:
                raise RuntimeError("the controller zygote is gone (%s); see %s"
                                   % (err, self.process.log_path))
            deadline = time.monotonic() + timeout
            with self._answer:
                while not self._answers:
                    left = deadline - time.monotonic()
                    if left <= 0 or not self.process.running():
                        raise RuntimeError("the controller zygote did not answer; see %s"
                                           % self.process.log_path)
                    self._answer.wait(min(left, 0.1))
                answer = self._answers.pop(0)
        if "error" in answer:
            raise RuntimeError("cannot start %s (%s): %s" % (name, " ".join(argv),
                                                            answer["error"]))
        return ZygoteChild(self, name, argv, log_path, answer["pid"])

    def exit_status(self, pid):
        with self._answer:
            return self._exits.get(pid)

    def spinning(self, pid, timeout=0.0):
        """True once child `pid` has entered rospy.spin() (and has not ended); waits up to
        `timeout` [s] for it."""
        deadline = time.monotonic() + timeout
        with self._answer:
            while pid not in self._spinning and pid not in self._exits:
                left = deadline - time.monotonic()
                if left <= 0 or not self.process.running():
                    break
                self._answer.wait(left)
            return pid in self._spinning

    def wait_exit(self, pid, timeout):
        deadline = time.monotonic() + timeout
        with self._answer:
            while pid not in self._exits:
                left = deadline - time.monotonic()
                if left <= 0 or not self.process.running():
                    break
                self._answer.wait(min(left, 0.05))
            return self._exits.get(pid)

    def forget(self, pid):
        with self._answer:
            self._exits.pop(pid, None)
            self._spinning.discard(pid)

    def close(self):
        """Stops the zygote (its children are stopped by their owners first)."""
        try:
            self._socket.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        if self.process.wait(1.0) is None:       # the end of its input ends it
            processes.stop([self.process], sigint_timeout=0.0, sigterm_timeout=2.0)
        self.process.close()
        # the listener's readline ends with the shutdown; the socket's file is closed after
        # it (a socket closed while its file is open stays open until collected)
        self._thread.join(2.0)
        if not self._thread.is_alive():
            self._reader.close()
        self._socket.close()


class ZygoteChild:
    """A forked controller, with processes.Child's interface (running, returncode, wait,
    signal_group, log_tail, close)."""

    def __init__(self, zygote, name, argv, log_path, pid):
        self.zygote, self.name, self.argv, self.log_path, self.pid = \
            zygote, name, list(argv), log_path, pid
        self.started = time.monotonic()

    def running(self):
        if self.zygote.exit_status(self.pid) is not None:
            return False
        if self.zygote.running():
            return True
        return processes.alive(self.pid)        # the zygote died: ask the kernel

    @property
    def returncode(self):
        return self.zygote.exit_status(self.pid) if not self.running() else None

    def spinning(self, timeout=0.0):
        """True once the program has entered rospy.spin(): its node is set up. Waits up to
        `timeout` [s] for it."""
        return self.zygote.spinning(self.pid, timeout)

    def wait(self, timeout):
        code = self.zygote.wait_exit(self.pid, timeout)
        if code is None and not self.zygote.running():
            deadline = time.monotonic() + timeout
            while processes.alive(self.pid) and time.monotonic() < deadline:
                time.sleep(0.05)
            return None if processes.alive(self.pid) else -signal.SIGKILL
        return code

    def log_tail(self, lines=20):
        return processes.log_tail(self.log_path, lines)

    def signal_group(self, signum):
        try:
            os.killpg(self.pid, signum)
        except (ProcessLookupError, PermissionError):
            pass

    def close(self):
        self.zygote.forget(self.pid)


# --- the zygote process ---------------------------------------------------------------------
def serve(fd):
    """The zygote's loop: forks a child per request, reports each child's exit. Sleeps in
    select() until a request comes or a child ends (SIGCHLD wakes it)."""
    channel = socket.socket(fileno=fd)
    channel.setblocking(False)
    wake_read, wake_write = os.pipe()
    os.set_blocking(wake_read, False)
    os.set_blocking(wake_write, False)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    signal.set_wakeup_fd(wake_write)
    signal.signal(signal.SIGINT, signal.SIG_IGN)     # stopped by its owner (SIGTERM/EOF)
    pending = b""
    children = set()
    spin_pipes = {}                                   # read end -> pid (see warm_rospy)
    while True:
        ready, _, _ = select.select([channel, wake_read, *spin_pipes], [], [], 1.0)
        if wake_read in ready:
            try:
                os.read(wake_read, 4096)
            except BlockingIOError:
                pass
        for fd in [fd for fd in ready if fd in spin_pipes]:
            try:
                data = os.read(fd, 64)
            except OSError:
                data = b""
            if data:
                _send(channel, {"spinning": spin_pipes[fd]})
            os.close(fd)                              # one message a child, or its end
            del spin_pipes[fd]
        if channel in ready:
            try:
                chunk = channel.recv(65536)
            except BlockingIOError:
                chunk = None
            if chunk == b"":
                break                                 # the worker is gone
            pending += chunk or b""
        while b"\n" in pending:
            line, pending = pending.split(b"\n", 1)
            answer, spin_pipe = _fork(json.loads(line.decode("utf-8")), channel,
                                      (wake_read, wake_write, *spin_pipes))
            if "pid" in answer:
                children.add(answer["pid"])
                spin_pipes[spin_pipe] = answer["pid"]
            _send(channel, answer)
        for pid in list(children):
            try:
                done, status = os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                done, status = pid, 0
            if done:
                children.discard(pid)
                code = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else \
                    os.WEXITSTATUS(status)
                _send(channel, {"exit": code, "pid": pid})
    for pid in children:                              # orphans of a vanished worker
        try:
            os.killpg(pid, signal.SIGTERM)
        except ProcessLookupError:
            pass


def _send(channel, message):
    data = (json.dumps(message) + "\n").encode("utf-8")
    channel.setblocking(True)
    try:
        channel.sendall(data)
    finally:
        channel.setblocking(False)


def _fork(request, channel, own_fds):
    argv, env, log_path = request["run"], request["env"], request["log"]
    """Forks a child running the request; ({"pid": N} and the read end of its spin pipe) or
    ({"error": text}, None). `own_fds`: the zygote's descriptors, closed in the child."""
    launch = bool(request.get("launch"))
    found = warm_launch.accepts(argv) if launch else warm_script(argv, env.get("PATH",
                                                                               os.defpath))
    if not found:
        return {"error": "not a roslaunch command line a warm launch takes" if launch
                else "not a Python script for this interpreter"}, None
    try:
        os.makedirs(os.path.dirname(os.path.abspath(log_path)), exist_ok=True)
        log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    except OSError as err:
        return {"error": "log file %s: %s" % (log_path, err)}, None
    spin_read, spin_write = os.pipe()                 # not inherited by the child's children
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid:
        os.close(log)
        os.close(spin_write)
        return {"pid": pid}, spin_read
    # the child: never returns
    code = 1
    try:
        channel.close()
        signal.set_wakeup_fd(-1)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        for fd in (*own_fds, spin_read):
            os.close(fd)
        os.setsid()
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.dup2(log, 1)
        os.dup2(log, 2)
        os.close(null)
        os.close(log)
        _confine(request)
        if launch:           # the launcher's nodes say nothing of spin(): see warm_launch
            os.close(spin_write)
            code = warm_launch.main(argv, env)
        else:
            code = run_script(*found, env, spin_write)
    finally:
        os._exit(code)


def _confine(request):
    """The request's limits, folder and user, in the child, before the program runs (limits
    first: lowering them needs no privilege, but the user change drops what raising would)."""
    import resource
    for name, value in request.get("rlimits", ()):
        resource.setrlimit(getattr(resource, name), (value, value))
    if "cwd" in request:
        os.chdir(request["cwd"])
    if "uid" in request:
        os.setgroups([])
        os.setgid(request["gid"])
        os.setuid(request["uid"])                 # real, effective and saved: no way back


def run_script(script, args, env, spin_fd=None):
    """Runs `script` as __main__ in this (fresh) child; returns its exit status. `spin_fd`,
    if given, gets one byte when the program enters rospy.spin()."""
    import atexit
    import runpy
    import traceback
    from . import warm_rospy

    def spinning():
        if spin_fd is None:
            return
        try:
            os.write(spin_fd, b"s")
            os.close(spin_fd)
        except OSError:
            pass
    if "rospy" in sys.modules:
        warm_rospy.quicken(on_spin=spinning)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    os.environ.clear()
    os.environ.update(env)
    sys.argv = [script] + list(args)
    sys.path[0] = os.path.dirname(os.path.realpath(script))
    if "rospy" in sys.modules:
        warm_rospy.take_command_line()
    if "numpy" in sys.modules:
        sys.modules["numpy"].random.seed()       # a fresh process draws a fresh seed
    code = 0
    try:
        runpy.run_path(script, run_name="__main__")
    except SystemExit as end:
        code = _exit_code(end.code)
    except BaseException:                         # as the interpreter would print it
        traceback.print_exc()
        code = 1
    try:
        threading._shutdown()                     # non-daemon threads, as at a normal exit
    except Exception:
        pass
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    return code


def _exit_code(value):
    if value is None:
        return 0
    if isinstance(value, int):
        return value & 0xFF
    sys.stderr.write("%s\n" % value)
    return 1


def main():
    fd = int(os.environ.pop("M2WR_ZYGOTE_FD"))
    os.environ.pop("M2WR_ZYGOTE_FD", None)
    for name in PRELOAD:
        try:
            __import__(name)
        except ImportError as err:
            sys.stderr.write("zygote: %s not preloaded (%s)\n" % (name, err))
    sys.stdout.flush()
    serve(fd)


if __name__ == "__main__":
    main()
