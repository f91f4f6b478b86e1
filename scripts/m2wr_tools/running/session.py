"""One ROS session of the demo or the benchmark: its own master on a free localhost port,
the simulator (my_worlds launch_world.launch), the robot (m2wr_description spawn.launch), the
tutorial's controller (motion_plan obstacle_avoidance.py) and optionally rosbag, each a child
process in a process group of its own with its output in <log_dir>/<name>.log.

Every child gets ROS_MASTER_URI=http://<host>:<port> and ROS_HOSTNAME=<host>, and
ROS_LOG_DIR=<log_dir>/ros; the caller's own ROS_MASTER_URI is never used, so a master the
user runs is left alone. <host> is localhost, or the loopback address ROS_HOSTNAME names
(`loopback_host`). `stop()` ends the children (SIGINT, then SIGTERM, SIGKILL) and
checks that no process of the session is left (`processes.leftovers`).
"""
import os
import re
import sys
import signal
import time
import uuid
import xmlrpc.client

from . import processes, stale_nodes
from ..names import (COMMAND_TOPIC, CONTROLLER_NODE, ROBOT_DESCRIPTION_PARAM, SCAN_TOPIC,
                     SIMULATOR_NODE, SPAWN_LAUNCH, SPAWN_NODE, SPAWN_SERVICE,
                     TUTORIAL_CONTROLLER, WORLD_LAUNCH)


def loopback_host():
    """The address of the session's ROS graph: the loopback address that ROS_HOSTNAME names
    (127.x.y.z), else localhost; never an address another machine can reach.

    Why another loopback address at all: a master keeps the address of a node that ended
    without unregistering (killed), and calls it when the node's topics change
    (publisherUpdate, "shutdown"). On one address the kernel may have given that port to a
    node of another ROS graph running beside it, which then connects to the wrong graph's
    publishers. scripts/test.sh runs its background streams each on its own address."""
    host = os.environ.get("ROS_HOSTNAME", "")
    return host if re.fullmatch(r"127(\.\d{1,3}){3}", host) else "localhost"


class SessionError(RuntimeError):
    """A step of the session failed; the message says which and why."""


class Session:
    def __init__(self, log_dir, name="demo"):
        self.name = name
        self.log_dir = os.path.abspath(log_dir)
        os.makedirs(self.log_dir, exist_ok=True)
        self.port = None
        self.host = "localhost"
        self.master_uri = None
        self.env = None
        self.children = {}                      # name -> processes.Child, in start order
        self.stop_report = {}
        self._urdf = None                       # m2wr's URDF, made once (spawn_in_process)

    # --- processes ----------------------------------------------------------------------
    def _start(self, name, argv):
        child = processes.Child(name, argv, self.env, os.path.join(self.log_dir, name + ".log"))
        self.children[name] = child
        return child

    def child(self, name):
        return self.children.get(name)

    def start_master(self, timeout=20.0, attempts=3):
        """A ROS master on a free port of the session's loopback address (`loopback_host`);
        returns its URI once it answers. `rosmaster --core`, not roscore: roscore also starts
        rosout, a roscpp node whose XML-RPC server listens on every interface (roscpp binds
        it to 0.0.0.0 whatever ROS_HOSTNAME says); the master itself binds to the loopback
        address ROS_HOSTNAME gives it. Nothing here needs rosout:
        the demo and the batch read the controller's log lines from /rosout directly."""
        self.host = loopback_host()
        for _ in range(attempts):
            self.port = processes.free_port(self.host.replace("localhost", "127.0.0.1"))
            self.master_uri = "http://%s:%d" % (self.host, self.port)
            self.env = dict(os.environ, ROS_MASTER_URI=self.master_uri, ROS_HOSTNAME=self.host,
                            ROS_LOG_DIR=os.path.join(self.log_dir, "ros"))
            self.env.pop("ROS_IP", None)
            master = self._start("roscore", ["rosmaster", "--core", "-p", str(self.port)])
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline and master.running():
                if self.master_pid() is not None:
                    # what roscore's roslaunch does: every roslaunch started on this master
                    # then shares one run id (each would declare its own, and the second
                    # would stop at "run_id on parameter server does not match")
                    with self.master() as master:
                        master.setParam("/" + self.name, "/run_id", str(uuid.uuid1()))
                    return self.master_uri
                time.sleep(0.1)
            if master.running():
                raise SessionError("the ROS master on port %d did not answer within %.0f s; "
                                   "see %s" % (self.port, timeout, master.log_path))
            del self.children["roscore"]      # the port was taken meanwhile: try another
        raise SessionError("the ROS master would not start (%d attempts); last output:\n%s"
                           % (attempts, master.log_tail()))

    def join(self):
        """This process's own rospy node (init_node after this) joins the session's graph."""
        os.environ.update(ROS_MASTER_URI=self.master_uri, ROS_HOSTNAME=self.host)
        os.environ.pop("ROS_IP", None)

    def master(self):
        """The master's XML-RPC proxy; use it in a `with` block, which closes its socket."""
        return xmlrpc.client.ServerProxy(self.master_uri)

    def master_pid(self):
        try:
            with self.master() as master:
                code, _, pid = master.getPid("/" + self.name)
            return pid if code == 1 else None
        except (OSError, xmlrpc.client.Error):
            return None

    def node_uri(self, node):
        try:
            with self.master() as master:
                code, _, uri = master.lookupNode("/" + self.name, node)
            return uri if code == 1 else None
        except (OSError, xmlrpc.client.Error):
            return None

    def node_pid(self, node):
        uri = self.node_uri(node)
        if uri is None:
            return None
        try:
            with xmlrpc.client.ServerProxy(uri) as proxy:
                code, _, pid = proxy.getPid("/" + self.name)
            return pid if code == 1 else None
        except (OSError, xmlrpc.client.Error):
            return None

    def launch_world(self, world, gui=False, real_time_factor=0.0, lockstep=True, seed=0,
                     paused=False, pub_clock_frequency=None, contacts=True,
                     lockstep_timeout=None, extra=()):
        """Starts the world; `contacts` turns on /gazebo/contacts (the demo's summary, the
        bench and the batch runner count touches from it)."""
        args = ["roslaunch", "--sigint-timeout=10", "--sigterm-timeout=3", *WORLD_LAUNCH,
                "world:=%s" % world, "gui:=%s" % str(bool(gui)).lower(),
                "contacts:=%s" % str(bool(contacts)).lower(),
                "real_time_factor:=%g" % real_time_factor,
                "lockstep:=%s" % str(bool(lockstep)).lower(), "seed:=%d" % seed,
                "pause:=%s" % str(bool(paused)).lower()]
        if pub_clock_frequency is not None:
            args.append("pub_clock_frequency:=%g" % pub_clock_frequency)
        if lockstep_timeout is not None:
            args.append("lockstep_timeout:=%g" % lockstep_timeout)
        args.extend(extra)
        return self._start("world", args)

    def wait_for_simulator(self, timeout=60.0):
        """Waits until /gazebo offers its spawn service; SessionError with the simulator's
        own message when the launch ends first (e.g. an unknown world)."""
        world = self.children["world"]
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if not world.running():
                raise SessionError("the simulator stopped while starting (roslaunch exit %s):\n%s"
                                   % (world.returncode, _problem_lines(world.log_tail(40))))
            if self.service_offered(SPAWN_SERVICE):
                return
            time.sleep(0.1)
        raise SessionError("the simulator offered no %s within %.0f s; see %s"
                           % (SPAWN_SERVICE, timeout, world.log_path))

    def service_offered(self, service):
        try:
            with self.master() as master:
                code, _, uri = master.lookupService("/" + self.name, service)
            return code == 1
        except (OSError, xmlrpc.client.Error):
            return False

    def spawn(self, x, y, yaw, timeout=60.0):
        """roslaunch m2wr_description spawn.launch x:= y:= yaw:=; waits for it to end.
        SessionError with its output unless it exits 0 without a node dying."""
        self.start_spawn(x, y, yaw)
        self.finish_spawn(timeout)

    def spawn_in_process(self, x, y, yaw, z=0.5, timeout=30.0):
        """What spawn.launch does, from this process (its rospy node initialised on this
        session's master): robot_description from the xacro, then one spawn_urdf_model call
        for model m2wr at (x, y, z, yaw), as spawn_model makes it. For tools that spawn once a
        run: spawn.launch starts three Python interpreters (roslaunch, xacro, spawn_model),
        about 2 s. The URDF is made once a session. SessionError with the simulator's answer
        when the spawn is refused (gazebo.spawn_urdf_model)."""
        import rospy
        from ..paths import robot_urdf
        from .gazebo import spawn_urdf_model
        if self._urdf is None:
            self._urdf = robot_urdf()
        rospy.set_param(ROBOT_DESCRIPTION_PARAM, self._urdf)
        try:
            spawn_urdf_model("m2wr", self._urdf, x, y, z, yaw, timeout)
        except (rospy.ROSException, rospy.ServiceException, RuntimeError) as error:
            raise SessionError("spawning m2wr at (%g, %g, yaw %g) failed: %s"
                               % (x, y, yaw, error)) from None

    def start_spawn(self, x, y, yaw):
        self._spawn_pose = (float(x), float(y), float(yaw))
        return self._start("spawn", ["roslaunch", *SPAWN_LAUNCH,
                                     "x:=%r" % float(x), "y:=%r" % float(y),
                                     "yaw:=%r" % float(yaw)])

    def finish_spawn(self, timeout=60.0):
        """Waits for start_spawn's roslaunch; SessionError unless the spawn succeeded.
        (roslaunch exits 0 even when its node failed, so its output is read too.)"""
        child = self.children["spawn"]
        x, y, yaw = self._spawn_pose
        code = child.wait(timeout)
        if code is None:
            processes.stop([child], sigint_timeout=5.0)
            raise SessionError("spawning m2wr did not finish within %.0f s:\n%s"
                               % (timeout, child.log_tail()))
        with self.master() as master:        # its node ended: see stale_nodes.py
            stale_nodes.forget_gone(master, "/" + self.name, [SPAWN_NODE])
        log = child.log_tail(60)
        if code != 0 or "process has died" in log or "spawn_model:" in log:
            raise SessionError("spawning m2wr at (%g, %g, yaw %g) failed (roslaunch exit %d):\n%s"
                               % (x, y, yaw, code, _problem_lines(log)))

    def start_controller(self, argv=TUTORIAL_CONTROLLER, log_name="controller"):
        """The controller (default: the tutorial's obstacle_avoidance.py) as child
        "controller"; its output goes to <log_dir>/<log_name>.log."""
        child = processes.Child("controller", argv, self.env,
                                os.path.join(self.log_dir, log_name + ".log"))
        self.children["controller"] = child
        return child

    def start_episode(self, world, start, lockstep=True, real_time_factor=0.0, seed=0,
                      pub_clock_frequency=None, gui=False, controller=TUTORIAL_CONTROLLER,
                      say=lambda _text: None, extra=(), in_process_spawn=False):
        """The simulator paused on `world`, m2wr spawned at `start` (x [m], y [m], yaw [rad])
        and `controller` connected to its scan and cmd_vel: ready to unpause. The spawn
        starts at once (it waits for the simulator's service), the controller once the
        simulator is up, so that /use_sim_time is set when it starts. `extra`: more
        `name:=value` arguments of the world's launch file. `in_process_spawn`: spawn from
        this process (spawn_in_process; its rospy node must be initialised on this session's
        master) instead of spawn.launch, for tools and tests that start many episodes."""
        self.launch_world(world, gui=gui, real_time_factor=real_time_factor, lockstep=lockstep,
                          seed=seed, paused=True, pub_clock_frequency=pub_clock_frequency,
                          extra=extra)
        say("spawning m2wr at x %g y %g yaw %g" % tuple(start))
        if in_process_spawn:
            self.wait_for_simulator()
            self.spawn_in_process(*start)
        else:
            self.start_spawn(*start)          # it waits for the simulator's service itself
            self.wait_for_simulator()
        say("starting %s" % os.path.basename(controller[-1]))
        self.start_controller(controller)
        if not in_process_spawn:
            self.finish_spawn()
        self.wait_for_controller(label=os.path.basename(controller[-1]))

    def start_bag(self, path, topics):
        return self._start("rosbag", ["rosbag", "record", "--quiet", "-O", path] + list(topics))

    # --- the graph ----------------------------------------------------------------------
    def connected(self, node, topic, peer_node):
        """True when `node` has a live connection on `topic` with `peer_node` (from the
        node's getBusInfo)."""
        peer_uri = self.node_uri(peer_node)
        _, bus = self._bus_info(node)
        if peer_uri is None or not isinstance(bus, list):
            return False
        for connection in bus:
            # [id, destination (caller id or URI), direction, transport, topic, connected, ...]
            if len(connection) >= 6 and connection[4] == topic and connection[5] \
                    and connection[1] in (peer_node, peer_uri):
                return True
        return False

    def _bus_info(self, node):
        """(`node`'s XML-RPC address or None, its connections as getBusInfo lists them, or
        a string saying why there are none to read)."""
        uri = self.node_uri(node)
        if uri is None:
            return None, "not registered on the master"
        try:
            with xmlrpc.client.ServerProxy(uri) as proxy:
                code, _, bus = proxy.getBusInfo("/" + self.name)
        except (OSError, xmlrpc.client.Error) as error:
            return uri, "does not answer (%s)" % error
        return (uri, bus) if code == 1 else (uri, "no bus information")

    def describe_connections(self, node):
        """`node`'s address on the master and its live connections, as a line for an error
        message (what a "did not connect" needs to be understood afterwards)."""
        uri, bus = self._bus_info(node)
        if uri is None:
            return "%s: not registered on the master" % node
        if not isinstance(bus, list):
            return "%s at %s: %s" % (node, uri, bus)
        # [id, destination, direction, transport, topic, connected, ...]
        return "%s at %s: %s" % (node, uri, ", ".join(sorted(
            "%s %s %s%s" % (c[4], c[2], c[1], "" if c[5] else " (not connected)")
            for c in bus if len(c) >= 6)) or "no connections")

    def wait_for_controller(self, timeout=30.0, node=CONTROLLER_NODE,
                            label="obstacle_avoidance.py"):
        """Until the simulator sends scans to the controller's `node` and hears its cmd_vel."""
        controller = self.children["controller"]
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if not controller.running():
                raise SessionError("%s stopped while starting (exit %s):\n%s"
                                   % (label, controller.returncode, controller.log_tail()))
            if self.connected(SIMULATOR_NODE, SCAN_TOPIC, node) \
                    and self.connected(SIMULATOR_NODE, COMMAND_TOPIC, node):
                return
            time.sleep(0.05)
        raise SessionError("%s did not connect to the simulator within %.0f s; see %s"
                           % (label, timeout, controller.log_path))

    def check_running(self, names):
        """SessionError naming the first of `names` that is no longer running."""
        for name in names:
            child = self.children.get(name)
            if child is not None and not child.running():
                raise SessionError("%s stopped unexpectedly (exit %s):\n%s"
                                   % (name, child.returncode, _problem_lines(child.log_tail(40))))

    # --- the end ------------------------------------------------------------------------
    def stop(self, names=None, nodes=None):
        """Stops the named children (default: all), the controller and the bag before the
        simulator and the simulator before the master. Returns {name: how it ended}. The
        master, if it stays, forgets the nodes that ended (stale_nodes.py: else the next node
        of the same name could have the master shut down whatever took the old one's port).
        `nodes`: {node: address} (stale_nodes.registered) taken by a caller that signalled the
        children before this call: a node that has already shut down is no longer listed
        by topic, yet the master still holds it. Default: the nodes registered now."""
        order = [["controller", "rosbag", "spawn"], ["world"], ["roscore"]]
        names = set(self.children) if names is None else set(names)
        nodes = dict(nodes or {})
        if self.master_uri is not None and "roscore" not in names and not nodes:
            with self.master() as master:
                nodes = stale_nodes.registered(master, "/" + self.name)
        for group in order + [[n for n in self.children if n not in sum(order, [])]]:
            batch = [self.children[n] for n in group if n in names and n in self.children]
            if batch:
                self.stop_report.update(processes.stop(batch))
                for child in batch:
                    del self.children[child.name]
        if nodes:
            with self.master() as master:
                stale_nodes.forget_ended(master, "/" + self.name, nodes)
        return self.stop_report

    def shut_down(self, tool):
        """The end of a run of `tool` (demo, bench), whatever happened: signals are held off
        while this process's ROS node and everything the session started are stopped. Reports
        on stderr any process that had to be killed afterwards."""
        signal.signal(signal.SIGINT, signal.SIG_IGN)     # let the clean-up finish
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        try:
            import rospy
            if rospy.core.is_initialized():
                rospy.signal_shutdown("%s finished" % tool)
        except ImportError:
            pass
        killed = self.stop_all()
        if killed:
            sys.stderr.write("%s: these processes outlived their parents and were killed:\n%s\n"
                             % (tool, killed))
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)

    def stop_all(self):
        """stop() everything, then make sure no process of the session is left. Returns the
        `ps` lines of processes that had to be killed afterwards ("" when none)."""
        self.stop()
        if self.master_uri is None:
            return ""
        deadline = time.monotonic() + 3.0
        while processes.leftovers(self.master_uri) and time.monotonic() < deadline:
            time.sleep(0.1)      # nodes whose roslaunch just ended may still be exiting
        return processes.kill_leftovers(self.master_uri)


def python_logging_config(env):
    """The logging configuration file every rospy node of `env` would find for itself
    (ROS_PYTHON_LOG_CONFIG_FILE if set; else the first python_logging.conf or .yaml in
    $ROS_HOME/config, $ROS_ETC_DIR, rosgraph's conf/), or None. Given to a node as
    ROS_PYTHON_LOG_CONFIG_FILE, it spares its init_node a crawl of ROS_PACKAGE_PATH for
    rosgraph's folder (a walk of every package folder, at every node's start) and changes
    nothing else."""
    if env.get("ROS_PYTHON_LOG_CONFIG_FILE"):
        return env["ROS_PYTHON_LOG_CONFIG_FILE"]
    import rospkg
    folders = [os.path.join(rospkg.get_ros_home(env), "config"), rospkg.get_etc_ros_dir(env)]
    try:
        folders.append(os.path.join(rospkg.RosPack(rospkg.get_ros_paths(env)).get_path(
            "rosgraph"), "conf"))
    except rospkg.ResourceNotFound:
        pass
    for folder in folders:
        for extension in ("conf", "yaml"):
            path = os.path.join(folder, "python_logging." + extension)
            if os.path.isfile(path):
                return path
    return None


_ANSI = re.compile(r"\x1b(\[[0-9;]*[A-Za-z]|\][^\x07]*\x07)")


def _problem_lines(text):
    """The lines of a log that say what went wrong (or the whole tail when none does),
    without terminal colour codes."""
    text = _ANSI.sub("", text)
    text = "\n".join(l.lstrip("=") for l in text.splitlines()
                     if "symlink to latest log directory" not in l)
    keys = ("error", "not found", "failed", "fatal", "exception", "no such", "cannot",
            "invalid", "died", "spawn_model:", "gazebo_world:", "unknown", "traceback")
    lines = [l for l in text.splitlines() if any(k in l.lower() for k in keys)]
    return "\n".join(lines) if lines else text
