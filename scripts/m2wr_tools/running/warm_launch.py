"""`roslaunch PKG FILE ARGS` started warm: the launch file read with roslaunch's own loader
and its nodes forked, in a child of the worker's zygote (m2wr_tools.running.zygote).

A graded bug run's `roslaunch motion_plan bug2.launch` costs a cold roslaunch and three cold
Python interpreters, each importing rospy and the message modules: on two busy cores, as
much wall time as the run's stepping (docs/performance.md, "Grading a class"). Forked
from the zygote, rospy and the message modules are imported already (the launcher adds
roslaunch's), and each Python node is a fork of the launcher with its script run as
__main__ (zygote.run_script: the same start as a warm controller's).

What is roslaunch's and what is ours:
- roslaunch's: reading the launch file (XmlLoader with the command line's `name:=value`
  arguments: <arg>, <include>, <group if/unless>, <param command=...>, <rosparam>, $(find),
  $(eval), all as roslaunch reads them), the parameters it sets and clears, each node's
  command line (node_args.create_local_process_args: remappings, __name, args), its
  environment (core.setup_env: ROS_NAMESPACE, <env>) and working folder (cwd="node" or
  ROS_HOME).
- ours: starting the nodes and watching them, as roslaunch's process monitor does: a
  `required` node that ends stops the others, a `respawn` node is started again after its
  respawn_delay, and the launcher ends when no node is left. A Python script of this
  interpreter is forked (zygote.warm_script decides, as for controllers); anything else (a
  binary, another interpreter, a launch-prefix) is started with fork and exec.

The nodes stay in the launcher's process group (roslaunch gives each a session of its
own and signals them one by one): the runner's SIGINT to the group reaches every node at
once, and the grader's look at the group finds them all. On SIGINT the launcher waits for
its nodes as roslaunch does (SIGTERM after SIGINT_TIMEOUT, SIGKILL after SIGTERM_TIMEOUT
more). A node with `output="screen"` (or all, with --screen) writes to the launcher's output
(the run's log), the others' standard output goes to `<ROS log dir>/<run_id>/<node>-stdout.log`
and their errors to the launcher's, as roslaunch places them; each start and end is
announced as roslaunch announces it.

Runs as the zygote child's program, so the grader's user, folder and limits apply to the
reading (a launch file's commands and $(eval)) and to every node, as they applied to the
plain roslaunch. `accepts(argv)` says which command lines it takes; the rest (roslaunch's
options other than --screen, machine tags) run as a plain roslaunch.
"""
import os
import select
import shlex
import signal
import sys
import time
import xmlrpc.client

SIGINT_TIMEOUT = 15.0      # [s] roslaunch's own (nodeprocess.DEFAULT_TIMEOUT_SIGINT)
SIGTERM_TIMEOUT = 2.0      # [s] likewise
OPTIONS = ("--screen",)    # roslaunch options a warm launch honours (--screen: every node's
                           # output on the launcher's, as output="screen" puts it)


def accepts(argv):
    """True when `argv` is `roslaunch [--screen] PKG FILE [name:=value ...]` or
    `roslaunch [--screen] FILE.launch [name:=value ...]`."""
    argv = list(argv)
    if not argv or os.path.basename(argv[0]) != "roslaunch":
        return False
    words = [a for a in argv[1:] if a not in OPTIONS]
    if any(a.startswith("-") for a in words):
        return False
    plain = [a for a in words if ":=" not in a]
    return 1 <= len(plain) <= 2


class _Node:
    """One node of the launch file: its command, environment and folder, and its process."""

    def __init__(self, node, master_uri, log_dir=None):
        from roslaunch import core, node_args
        self.node = node
        self.argv = node_args.create_local_process_args(node, node.machine)
        self.env = core.setup_env(node, node.machine, master_uri)
        self.prefix = shlex.split(node.launch_prefix) if node.launch_prefix else []
        self.label = node.name if node.namespace in ("", "/") else \
            "%s/%s" % (node.namespace.strip("/"), node.name)
        self.pid = None
        self.stdout = None if log_dir is None or node.output == "screen" else os.path.join(
            log_dir, "%s-stdout.log" % self.label.replace("/", "-"))

    def cwd(self):
        if self.node.cwd == "node":
            return os.path.dirname(self.argv[0])
        import rospkg
        return rospkg.get_ros_home(self.env)

    def start(self, own_fds):
        """Forks the node; its pid."""
        from . import zygote
        folder = self.cwd()
        os.makedirs(folder, exist_ok=True)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid:
            self.pid = pid
            return pid
        code = 127
        try:
            for fd in own_fds:
                os.close(fd)
            signal.set_wakeup_fd(-1)
            for signum in (signal.SIGCHLD, signal.SIGTERM):
                signal.signal(signum, signal.SIG_DFL)
            os.chdir(folder)
            if self.stdout is not None:
                os.makedirs(os.path.dirname(self.stdout), exist_ok=True)
                out = os.open(self.stdout, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
                os.dup2(out, 1)
                os.close(out)
            found = None if self.prefix else zygote.warm_script(
                self.argv, self.env.get("PATH", os.defpath))
            if found is not None:
                code = zygote.run_script(*found, self.env)
            else:
                argv = self.prefix + self.argv
                signal.signal(signal.SIGINT, signal.SIG_DFL)
                try:
                    os.execvpe(argv[0], argv, self.env)
                except OSError as err:
                    sys.stderr.write("ERROR: cannot launch node [%s] (%s): %s\n"
                                     % (self.label, " ".join(argv), err))
        finally:
            os._exit(code)


def _load(words):
    """(the launch file's ROSLaunchConfig, its path), read as roslaunch reads it."""
    import roslaunch.config
    import roslaunch.rlutil
    plain = [w for w in words if w not in OPTIONS]
    files = roslaunch.rlutil.resolve_launch_arguments(plain)
    config = roslaunch.config.load_config_default([(files[0], plain)], None, verbose=False)
    return config, files[0]


def _log_dir(master):
    """roslaunch's folder for its nodes' output: the ROS log folder, and in it the run's."""
    import rospkg
    folder = rospkg.get_log_dir()
    code, _, run_id = master.getParam("/roslaunch", "/run_id")
    return os.path.join(folder, run_id) if code == 1 and run_id else folder


def _set_params(config, master):
    """The parameters roslaunch sets: its clear_params namespaces deleted, then every param."""
    from roslaunch.launch import _unify_clear_params
    caller = "/roslaunch"
    for name in _unify_clear_params(config.clear_params):
        if master.hasParam(caller, name)[2]:
            master.deleteParam(caller, name)
    for param in config.params.values():
        code, message, _ = master.setParam(caller, param.key, param.value)
        if code != 1:
            raise RuntimeError("cannot set parameter %s: %s" % (param.key, message))


def main(argv, env):
    """The launcher's program (in a child of the zygote, as its own process group leader);
    its exit status: 0 once every node has ended, 1 when the launch file cannot be read or
    its parameters set."""
    os.environ.clear()
    os.environ.update(env)
    master_uri = env.get("ROS_MASTER_URI", "")
    try:
        from roslaunch.core import RLException, is_machine_local
        config, path = _load(list(argv[1:]))
        for node in config.nodes:
            if node.machine is not None and not is_machine_local(node.machine):
                raise RLException("node [%s] runs on machine [%s]: a warm launch starts local "
                                  "nodes only" % (node.name, node.machine.name))
        master = xmlrpc.client.ServerProxy(master_uri)
        _set_params(config, master)
        log_dir = None if "--screen" in argv else _log_dir(master)
        nodes = []
        for node in config.nodes:
            try:
                nodes.append(_Node(node, master_uri, log_dir))
            except Exception as err:        # as roslaunch: that node is reported, the rest run
                print("ERROR: cannot launch node of type [%s/%s]: %s"
                      % (node.package, node.type, err), flush=True)
    except Exception as err:               # roslaunch's RLException, a master that is gone
        print("%s: %s" % (type(err).__name__, err), file=sys.stderr, flush=True)
        return 1
    print("warm launch of %s (m2wr_tools.running.warm_launch): %d node(s)"
          % (path, len(nodes)), flush=True)
    return _supervise(nodes)


def _supervise(nodes):
    """Starts `nodes` and watches them until none is left."""
    wake_read, wake_write = os.pipe()
    os.set_blocking(wake_read, False)
    os.set_blocking(wake_write, False)
    stop = {"at": None}

    def stopping(_signum, _frame):
        if stop["at"] is None:
            stop["at"] = time.monotonic()
    signal.signal(signal.SIGCHLD, lambda *_: None)
    signal.signal(signal.SIGINT, stopping)
    signal.signal(signal.SIGTERM, stopping)
    signal.set_wakeup_fd(wake_write)
    own = (wake_read, wake_write)
    running = {}                                 # pid -> _Node
    respawn_at = {}                              # _Node -> monotonic time
    for node in nodes:
        running[node.start(own)] = node
        print("process[%s]: started with pid [%d]" % (node.label, node.pid), flush=True)
    sent = set()
    while running or (respawn_at and stop["at"] is None):
        now = time.monotonic()
        if stop["at"] is not None:
            waited = now - stop["at"]
            for signum, after in ((signal.SIGTERM, SIGINT_TIMEOUT),
                                  (signal.SIGKILL, SIGINT_TIMEOUT + SIGTERM_TIMEOUT)):
                if waited >= after and signum not in sent:
                    sent.add(signum)
                    for pid in running:
                        _signal(pid, signum)
        for node, when in list(respawn_at.items()):
            if stop["at"] is None and now >= when:
                del respawn_at[node]
                running[node.start(own)] = node
                print("[%s] restarting process, pid [%d]" % (node.label, node.pid), flush=True)
        waits = [0.5] + [max(0.0, w - now) for w in respawn_at.values()]
        try:
            select.select([wake_read], [], [], min(waits))
            os.read(wake_read, 4096)
        except (BlockingIOError, InterruptedError):
            pass
        while True:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                pid = 0
            if not pid:
                break
            node = running.pop(pid, None)
            if node is None:
                continue
            code = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
            if code == 0:
                print("[%s] process has finished cleanly" % node.label, flush=True)
            else:
                print("[%s] process has died [pid %d, exit code %d, cmd %s]"
                      % (node.label, pid, code, " ".join(node.argv)), flush=True)
            if node.node.required and stop["at"] is None:
                print("[%s] required node has ended: stopping the others" % node.label,
                      flush=True)
                stop["at"] = time.monotonic()
                for other in running:
                    _signal(other, signal.SIGINT)
            elif node.node.respawn and stop["at"] is None:
                respawn_at[node] = time.monotonic() + float(node.node.respawn_delay or 0.0)
    print("all processes on machine have died, roslaunch will exit", flush=True)
    return 0


def _signal(pid, signum):
    try:
        os.kill(pid, signum)
    except ProcessLookupError:
        pass
