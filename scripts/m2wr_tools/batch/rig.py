"""The worker side of a batch: one simulator per worker process, and one run on it.

A Rig owns a Session (its own ROS master on a free localhost port, `roslaunch my_worlds
launch_world.launch` paused, headless, real_time_factor 0, lockstep) and a rospy node
(/m2wr_batch) in the worker process. Every run takes the same path, so that its result
depends only on its scenario:

  /gazebo/reset_simulation (sim time 0, every model at its initial pose, the laser's noise
  generator re-seeded, the drive's command and lockstep's awaited answer forgotten) ->
  /gazebo/set_model_state m2wr at the start (z 0.5 m, at rest, as spawn.launch drops it) ->
  the recorder restarted (one per rig: its connections stay up) -> the controller started
  (a Python script is forked from the session's warm zygote, m2wr_tools.running.zygote, and
  so is `roslaunch PKG FILE ARGS`, whose Python nodes are forked in turn,
  m2wr_tools.running.warm_launch; anything else is a plain process) and publishing cmd_vel
  -> if a command already reached the simulator, /gazebo/reset_world and m2wr put back
  where it stood (the drive forgets a command sent as the controller started, which
  reached it or not as the connection came up: every run starts alike) -> physics unpaused
  for `duration` s of sim time -> paused -> the controller sent SIGINT while the run is
  measured (the record's controller_stop says so; a zygote's rospy program ends ~0.1 s
  later, m2wr_tools.running.warm_rospy) -> its exit awaited (the next run's reset comes
  after it: none of its commands can reach that run).

Per-run `stages` [s wall] in the record: reset_s, controller_start_s, sim_s, measure_s (of
which replay_s made the run's replay, when asked for), stop_s; `overhead_s` = the run's wall
time less sim_s's unpaused part; `cpu_s`: the CPU [s] of each process of the worker (this
one, the simulator, its roslaunch, the master, the controller) per stage and in total
(m2wr_tools.running.cpu_meter).

The simulator is kept between runs of the same world and seed (reuse) and relaunched
otherwise (the seed is a launch argument), or before every run with reuse off. The world and
seed of a relaunch are the run's; the robot is spawned with spawn.launch once per launch.

Topics in (the recorder): /tf (odom -> link_chassis: the trajectory; /odom's publisher keeps
one message and drops under load, /tf's queues) and /gazebo/contacts; nothing else, as each
connection costs the loop being measured. The controller's case lines are read from its
log (rospy prints each with its sim time), the cmd_vel messages counted from the
simulator's getBusStats at the pause. The simulator runs with lockstep_timeout 30 s (wall)
instead of 1 s, so that a loaded machine cannot make it step on without the controller's
answer.
ROS params set for the controller: des_pos_x, des_pos_y, initial_x, initial_y [m] (the
series' go_to_point/bug names) when the task is `goal`.

A failed run (the controller crashed, never published cmd_vel, or the run overran its wall
time limit; the simulator died) is returned as a record with success False and the reason;
it never raises, so the batch goes on.
"""
from dataclasses import asdict, dataclass
import atexit
import math
import os
import shlex
import signal
import socket
import subprocess
import threading
import time
import xmlrpc.client

import numpy as np

from ..analysis import metrics
from ..running import processes, stale_nodes
from ..running.gazebo import Services, model_poses
from ..names import (BASE_FRAME, COMMAND_TOPIC, CONTACTS_TOPIC, ODOM_TOPIC, PAUSE_SERVICE,
                    RESET_SIMULATION_SERVICE, RESET_WORLD_SERVICE, ROBOT,
                    ROBOT_DESCRIPTION_PARAM, SCAN_TOPIC, SIMULATOR_NODE, TF_TOPIC,
                    UNPAUSE_SERVICE)
from ..running.param_snapshot import ParamSnapshot
from .scenarios import Scenario
from ..running.session import Session, SessionError, python_logging_config

NODE = "/m2wr_batch"
SPAWN_Z = 0.5                 # [m] spawn.launch's default drop height of link_chassis
PATH_PERIOD = 0.5             # [s] sim: the path kept in the results
CLEARANCE_PERIOD = 0.1        # [s] sim: poses whose clearance is measured
LAST_MESSAGES = 0.5           # [s] wall after the pause by which the run's last contacts
                              # messages have arrived, when the simulator cannot say how many
                              # it sent (see Rig._simulator_counts)
BATCH_TAG = "M2WR_BATCH"      # environment variable naming the batch every child belongs to


@dataclass
class RunOptions:
    output: str                       # folder of the batch (logs/, runs/)
    reuse: bool = True                # keep the simulator between runs of the same world/seed
    lockstep: bool = True
    clock_hz: float = 20.0            # [Hz sim] /clock rate
    lockstep_timeout: float = 30.0    # [s wall] a busy machine may hold a controller's answer
                                      # over the simulator's 1 s; a hung one hits run_timeout
    connect_timeout: float = 20.0     # [s wall] for the controller to publish cmd_vel
    run_timeout: float = 0.0          # [s wall] per run; 0: 60 + 2 x duration
    bag: bool = False                 # rosbag per run: runs/<run_id>.bag
    picture: bool = False             # the demo's picture per run: runs/<run_id>.png
    replay: bool = False              # the run's replay (browser view): runs/<run_id>.replay.json
    batch: str = ""                   # the batch's tag (BATCH_TAG in every child's environment)
    warm_start: bool = True           # fork Python controllers from a warm zygote (running.zygote)
    gui: bool = False                 # the simulator's window (replays); headless by default
    real_time_factor: float = 0.0     # sim s per wall s; 0 = as fast as the machine allows


class RunFailed(Exception):
    """The run could not do its task; the message says why (and where the log is)."""


class Rig:
    def __init__(self):
        self.session = None
        self.key = None               # (lockstep, clock_hz, simulator_key) now running
        self.simulator_pid = None
        self.recorder = None
        self.commands = 0
        self._recorder_connected = None   # simulator pid the recorder was seen connected to
        self._run_nodes = {}          # {node: XML-RPC address} seen on the master this run
        self.scenes = {}              # world -> scene.Scene (offline geometry)
        self.zygote = None            # zygote.Zygote of this session (warm Python controllers)
        self.services = Services()    # the simulator's services, connections kept between runs
        self.params = ParamSnapshot()  # the parameters as a run found them, put back after it
        self._executables = {}        # (package, name) -> path, for rosrun command lines
        self.worker = "%s:%d" % (socket.gethostname(), os.getpid())

    # --- the simulator ------------------------------------------------------------------
    def _ensure_master(self, options):
        if self.session is not None:
            return
        if options.batch:
            os.environ[BATCH_TAG] = options.batch
        log_dir = os.path.join(options.output, "logs", "worker-%s-%d" % (socket.gethostname(),
                                                                        os.getpid()))
        session = Session(log_dir, name=NODE.lstrip("/"))
        try:
            uri = session.start_master()
        except SessionError:
            session.stop_all()
            raise
        config = python_logging_config(session.env)
        if config:
            session.env["ROS_PYTHON_LOG_CONFIG_FILE"] = config
        self.session = session
        session.join()
        import rospy
        rospy.init_node(NODE.lstrip("/"), disable_signals=True)

    def _simulator_counts(self, contacts=True):
        """(cmd_vel messages the simulator has received from the publishers connected now,
        /gazebo/contacts messages it has written to the recorder), from its node's
        getBusStats and getBusInfo (XML-RPC; no subscription of the batch's to /cmd_vel
        costs the controller a second connection). (None, None) when it does not answer.
        `contacts` False: the commands only (no getBusInfo), contacts None."""
        uri = self.session.node_uri(SIMULATOR_NODE)
        if uri is None:
            return None, None
        node = xmlrpc.client.ServerProxy(uri)
        try:
            code, _, (published, subscribed, _) = node.getBusStats(NODE)
            code_info, _, bus = node.getBusInfo(NODE) if contacts else (1, "", [])
        except (OSError, xmlrpc.client.Error, ValueError):
            return None, None
        if code != 1 or code_info != 1:
            return None, None
        # getBusStats: [topic, [[connection id, bytes, messages, drops, connected], ...]] for
        # subscriptions; [topic, bytes, [[connection id, bytes, messages, connected], ...]]
        # for publications. getBusInfo: [connection id, peer, direction, transport, topic, ...]
        commands = sum(c[2] for topic, connections in subscribed if topic == COMMAND_TOPIC
                       for c in connections)
        if not contacts:
            return commands, None
        ours = {c[0] for c in bus if len(c) >= 5 and c[4] == CONTACTS_TOPIC and c[1] == NODE}
        contacts = [c[2] for topic, _, connections in published if topic == CONTACTS_TOPIC
                    for c in connections if c[0] in ours]
        return commands, (contacts[0] if len(contacts) == 1 else None)

    @classmethod
    def simulator_key(cls, scenario):
        """What of `scenario` decides the simulator its run needs: a worker keeps its running
        simulator for a next run of the same key (and the same batch options) and relaunches
        it for another, so a batch handed out in key order relaunches least."""
        return (scenario.world, scenario.seed) + tuple(cls._world_args(scenario))

    def _ensure_simulator(self, scenario, options):
        """True when the running simulator is reused; else (re)launches it."""
        extra = tuple(self._world_args(scenario))
        key = (options.lockstep, options.clock_hz) + self.simulator_key(scenario)
        world = self.session.child("world")
        if options.reuse and self.key == key and world is not None and world.running():
            return True
        self.session.stop(["controller", "rosbag", "spawn", "world"])
        self.services.close()
        self.key = None
        self.session.launch_world(scenario.world, real_time_factor=options.real_time_factor,
                                  gui=options.gui, lockstep=options.lockstep,
                                  seed=scenario.seed, paused=True,
                                  pub_clock_frequency=options.clock_hz,
                                  lockstep_timeout=options.lockstep_timeout, extra=extra)
        self.session.wait_for_simulator()
        self.session.spawn(scenario.x, scenario.y, scenario.yaw)
        self.simulator_pid = self.session.node_pid(SIMULATOR_NODE)
        self.key = key
        return False

    @classmethod
    def _world_args(cls, scenario):
        """Further `name:=value` arguments of the world launch for `scenario` (a tool built
        on the batch runner adds its own, e.g. the grader's legacy_mode); part of the key
        that decides whether the running simulator is kept."""
        return ()

    def _resolve(self, argv):
        """`rosrun PKG EXECUTABLE ARGS` as the executable's own path (rosrun's bash and its
        package search cost ~0.3 s a run); other command lines as given. A single argument
        with spaces is split like a shell would."""
        argv = tuple(argv)
        if len(argv) == 1 and " " in argv[0]:
            argv = tuple(shlex.split(argv[0]))
        if len(argv) >= 3 and argv[0] == "rosrun":
            key = argv[1:3]
            if key not in self._executables:
                found = subprocess.run(["catkin_find", "--first-only", argv[1], argv[2]],
                                       stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                       text=True, env=self.session.env).stdout.strip()
                self._executables[key] = found if found and os.access(found, os.X_OK) else None
            if self._executables[key]:
                return (self._executables[key],) + argv[3:]
        return argv

    def _scene(self, world):
        if world not in self.scenes:
            import rospy
            from ..analysis.scene import Scene
            self.scenes[world] = Scene.of_world(world, rospy.get_param(ROBOT_DESCRIPTION_PARAM))
        return self.scenes[world]

    # --- one run ------------------------------------------------------------------------
    def run(self, scenario: Scenario, options: RunOptions):
        """The run's record (a plain dict); never raises for a run that fails."""
        wall0 = time.monotonic()
        record = {"run_id": scenario.run_id, "scenario": scenario.as_dict(),
                  "world": scenario.world_label, "x": scenario.x, "y": scenario.y,
                  "yaw": scenario.yaw, "seed": scenario.seed, "task": scenario.task.kind,
                  "worker": self.worker}
        runs_dir = os.path.join(options.output, "runs")
        os.makedirs(runs_dir, exist_ok=True)
        log_path = os.path.join(runs_dir, scenario.run_id + ".log")
        record.update(controller_log=log_path, controller_exit=None, reused=False)
        meter = None
        try:
            self._ensure_master(options)
            record["reused"] = self._ensure_simulator(scenario, options)
            meter = self._cpu_meter()
            record.update(self._run(scenario, options, log_path, runs_dir, meter))
        except RunFailed as err:
            record.update(success=False, reason=str(err))
            self.key = None       # the loop may still wait for that controller: relaunch
        except SessionError as err:            # the simulator itself failed: relaunch next time
            record.update(success=False, reason="simulator: %s" % err)
            self.key = None
        except Exception as err:               # a ROS call failed: say which
            record.update(success=False, reason="%s: %s" % (type(err).__name__, err))
            self.key = None
        finally:
            stopping = time.monotonic()
            record["controller_exit"] = self._stop_controller(record.get("controller_exit"))
            try:
                record["params_put_back"] = self.params.restore()
            except Exception as err:           # the master is gone: relaunched next run
                record["params_put_back"] = "failed: %s" % err
                self.key = None
            if "distance_m" in record:          # measured: the controller's lines are all out
                record["cases_s"] = _case_shares(log_path, scenario.duration)
            if isinstance(record.get("stages"), dict):
                record["stages"]["stop_s"] = round(time.monotonic() - stopping, 3)
            if meter is not None:
                meter.mark("stop_s")
                record["cpu_s"] = {"total": meter.totals(), "stages": meter.stages}
        record["wall_time_s"] = time.monotonic() - wall0
        record["finished_at"] = time.time()
        sim = record.get("sim_time_s") or 0.0
        unpaused = record.pop("_unpaused_wall_s", None)
        record["real_time_factor"] = sim / unpaused if unpaused else None
        record["overhead_s"] = record["wall_time_s"] - unpaused if unpaused else None
        record["worker_rss_mib"] = (processes.rss_kib(os.getpid()) or 0) / 1024.0
        sim_rss = processes.rss_kib(self.simulator_pid) if self.simulator_pid else None
        record["simulator_rss_mib"] = sim_rss / 1024.0 if sim_rss else None
        zygote_rss = processes.rss_kib(self.zygote.process.pid) if self.zygote else None
        record["zygote_rss_mib"] = zygote_rss / 1024.0 if zygote_rss else None
        for name in ("success", "reason"):
            record.setdefault(name, False if name == "success" else "")
        return record

    def _forget_early_commands(self):
        """A command the controller published as it started (a rospy.Rate loop's first turn,
        before its first sleep, computed from no reading) reached the simulator or not, as
        the simulator's connection to its publisher came up before or after: in two gradings
        of 30 identical students, 3 of the 120 runs of the series-style wall follower and
        bug 2 set off unlike the others (0.2 mm apart at 0.5 s), and that bug 2 ended
        metres away. So a run starts with no command: if one came, reset_world makes
        the drive forget it (as Gazebo's diff drive forgets its command there), and the robot
        goes back where it stood (at the run's start, or where the controller itself put it
        with set_model_state, as bug 2 does). Physics is paused: nothing else moved."""
        commands, _ = self._simulator_counts(contacts=False)
        if not commands:
            return
        pose = self.services.model_pose(ROBOT)
        self.services.empty(RESET_WORLD_SERVICE)
        self.services.place(ROBOT, pose)

    def _note_run_nodes(self):
        """Adds the nodes registered on the master now to the run's (stale_nodes.registered).
        A controller's node that shuts down, at the runner's SIGINT or by itself, takes back
        its topics but not rospy's parameter subscription: the master keeps its name and
        address, and when the next run's node of that name registers, it sends "shutdown"
        to that address, to whatever process has taken the port since. Known while they
        run, the stop makes the master forget them."""
        with self.session.master() as master:
            self._run_nodes.update(stale_nodes.registered(master, NODE))

    def _stop_controller(self, known_exit):
        if self.session is None:
            return known_exit
        child = self.session.child("controller")
        nodes, self._run_nodes = self._run_nodes, {}
        report = dict(self.session.stop(["controller", "rosbag"], nodes=nodes)) \
            if child is not None else {}
        self.session.stop_report.clear()
        if known_exit is not None:
            return known_exit
        return report.get("controller", known_exit)

    def _cpu_meter(self):
        """CPU of the run's processes (see m2wr_tools.running.cpu_meter): this worker (with the
        children it reaped: controllers started as plain processes), the simulator node, its
        roslaunch, the master, the controller while it runs, and the zygote with the
        controllers it has reaped (their whole CPU, their exit included)."""
        from ..running.cpu_meter import CpuMeter

        def child(name):
            def pid():
                found = self.session.child(name) if self.session is not None else None
                return found.pid if found is not None else None
            return pid
        return CpuMeter({
            "worker": (os.getpid, True),
            "simulator": (lambda: self.simulator_pid, False),
            "roslaunch": (child("world"), False),
            "master": (child("roscore"), False),
            "controller": (child("controller"), False),
            "zygote": (lambda: self.zygote.process.pid if self.zygote else None, True),
        })

    def _run(self, scenario, options, log_path, runs_dir, meter):
        import rospy
        from ..running.recorder import Recorder
        session = self.session
        stages, mark = {}, [time.monotonic()]

        def stage(name):
            now = time.monotonic()
            stages[name] = round(now - mark[0], 3)
            mark[0] = now
            meter.mark(name)
        self.services.empty(PAUSE_SERVICE)
        self.services.empty(RESET_SIMULATION_SERVICE)
        self.params.take()                     # put back after the run (param_snapshot.py)
        self.services.set_model_pose(ROBOT, scenario.x, scenario.y, SPAWN_Z, scenario.yaw)
        task = scenario.task
        if task.kind == "goal":
            for name, value in (("des_pos_x", task.goal[0]), ("des_pos_y", task.goal[1]),
                                ("initial_x", scenario.x), ("initial_y", scenario.y)):
                rospy.set_param("/" + name, float(value))
        # One recorder for the rig's life: its connections stay up between runs, and a
        # latched /gazebo/contacts message of an earlier run never reaches a new one.
        # The case lines come from the controller's log file, not /rosout: with no
        # subscriber, its rospy publishes no Log message (600 a wall second at 30x). No
        # scans either (the run's metrics need none).
        if self.recorder is None:
            self.recorder = Recorder(poses_from_tf=BASE_FRAME, cases_from_rosout=False,
                                     scan_window=None)
        recorder = self.recorder
        recorder.restart()
        if self._recorder_connected != self.simulator_pid:
            self._wait(lambda: session.connected(SIMULATOR_NODE, TF_TOPIC, NODE)
                       and session.connected(SIMULATOR_NODE, CONTACTS_TOPIC, NODE), 10.0,
                       "the batch's recorder did not connect to the simulator")
            self._recorder_connected = self.simulator_pid
        stage("reset_s")
        controller = self._start_controller(self._resolve(scenario.controller), log_path,
                                            options.warm_start)
        self._wait_for_controller(controller, options.connect_timeout, log_path)
        self._note_run_nodes()
        self._forget_early_commands()
        stage("controller_start_s")
        if options.bag:
            session.start_bag(os.path.join(runs_dir, scenario.run_id + ".bag"),
                              (SCAN_TOPIC, ODOM_TOPIC, COMMAND_TOPIC))
            time.sleep(1.0)
        limit = options.run_timeout or 60.0 + 2.0 * scenario.duration
        recorder.fire_at(scenario.duration)
        self.services.empty(UNPAUSE_SERVICE)
        start = time.monotonic()
        outcome = None
        while not recorder.reached.wait(0.1):
            if not controller.running():
                outcome = "controller exited with status %s at %.2f s of sim time; see %s" % (
                    controller.returncode, recorder.sim_time or 0.0, log_path)
                break
            session.check_running(["world"])
            if task.kind == "goal" and recorder.poses:
                last = recorder.poses[-1]
                if math.hypot(last[1] - task.goal[0], last[2] - task.goal[1]) <= task.tolerance:
                    break
            if time.monotonic() - start > limit:
                outcome = ("did not finish within %.0f s of wall time (sim time %.2f of %.0f s; "
                           "lockstep waits for the controller's answers: a hung controller "
                           "stalls it); see %s" % (limit, recorder.sim_time or 0.0,
                                                  scenario.duration, log_path))
                break
        self.services.empty(PAUSE_SERVICE)
        paused_at = time.monotonic()
        unpaused = paused_at - start
        commands, contacts_sent = self._simulator_counts()
        self._note_run_nodes()                 # before the SIGINT: see _stop_controller
        stage("sim_s")
        exit_status = stopped = None
        if not controller.running():
            exit_status = "exit %s" % controller.returncode
        else:
            # Physics is paused: the loop takes no step, even if lockstep was waiting for an
            # answer (a pause ends that wait), and the next run's reset forgets the awaited
            # answer and the drive's command; the controller may stop at once.
            controller.signal_group(signal.SIGINT)     # it ends while the run is measured
            stopped = "SIGINT from the runner at the end of its run"

        def settled():
            """Every /gazebo/contacts message the simulator sent to the recorder before the
            pause has been heard (/tf's, the track, are in: `reached` waited for them); at
            most LAST_MESSAGES [s] of wall time after the pause when the count is unknown."""
            deadline = paused_at + LAST_MESSAGES
            while (contacts_sent is None or recorder.contact_messages < contacts_sent) \
                    and time.monotonic() < deadline:
                time.sleep(0.002)
        result = self._measure(scenario, recorder, options, runs_dir, settled)
        self.commands = commands or 0
        if outcome is None and self.commands == 0:
            outcome = "the controller never published on %s; see %s" % (COMMAND_TOPIC, log_path)
        stage("measure_s")
        if "_replay_s" in result:
            stages["replay_s"] = result.pop("_replay_s")
        result["stages"] = stages
        result["_unpaused_wall_s"] = unpaused
        result["cmd_vel_messages"] = self.commands
        result["controller_stop"] = stopped
        if exit_status is not None:
            result["controller_exit"] = exit_status
        if outcome is not None:
            result.update(success=False, reason=outcome)
            self.key = None       # the loop may still wait for that controller: relaunch
        return result

    def _start_controller(self, argv, log_path, warm):
        """The run's controller as the session's child "controller": forked from the warm
        zygote when it is a Python script of this interpreter or a roslaunch command line
        (see _start_warm_or_plain), else a plain subprocess (binaries, other interpreters)."""
        session = self.session
        return self._start_warm_or_plain(
            argv, log_path, warm, session.env, lambda: session.start_controller(
                argv, log_name=os.path.relpath(log_path[:-4], session.log_dir)))

    def _start_warm_or_plain(self, argv, log_path, warm, env, plain, **confine):
        """The session's child "controller": forked from the worker's zygote when `warm` and
        `argv` is a Python script of this interpreter or a roslaunch command line that
        running.warm_launch takes (its Python nodes forked in turn), with `confine`
        (zygote.Zygote.start's cwd, user, group, rlimits) set in the child before the
        script's first line; else, or when the zygote fails (a new one comes next run),
        `plain()`'s child."""
        from ..running import warm_launch, zygote
        child = None
        launch = warm_launch.accepts(argv)
        if warm and (launch or zygote.warm_script(argv, env.get("PATH", os.defpath))):
            try:
                child = self._zygote().start("controller", argv, env, log_path, launch=launch,
                                             **confine)
            except RuntimeError:
                self.zygote.close()
                self.zygote = None
        if child is None:
            child = plain()
        self.session.children["controller"] = child
        return child

    def _zygote(self):
        """The worker's warm zygote (running.zygote), started anew if it is not running."""
        from ..running import zygote
        if self.zygote is None or not self.zygote.running():
            if self.zygote is not None:
                self.zygote.close()
            self.zygote = zygote.Zygote(self.session.env,
                                        os.path.join(self.session.log_dir, "zygote.log"))
        return self.zygote

    def _wait(self, condition, timeout, what):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if condition():
                return
            time.sleep(0.02)
        raise SessionError("%s within %.0f s" % (what, timeout))

    def _wait_for_controller(self, controller, timeout, log_path, settle=0.3, idle=0.1,
                             poll=0.02, poll_spinning=0.005):
        """Until a node other than the batch's publishes cmd_vel to the simulator, and every
        topic of the simulator it subscribes to is connected, unchanged for `settle` [s]
        (a program may subscribe after it advertises, as obstacle_avoidance.py does) - or
        for `idle` [s] during which the controller used no CPU at all, when that node is
        the controller's own process (it has finished starting and waits for messages) -
        or at once when the controller, forked from the zygote, has entered rospy.spin()
        (its main thread has made every subscription: m2wr_tools.running.warm_rospy)."""
        master = self.session.master()
        deadline = time.monotonic() + timeout
        ready_since, last = None, None
        own, cpu, idle_since = None, None, None
        spinning = getattr(controller, "spinning", None)
        while time.monotonic() < deadline:
            spun = spinning is not None and spinning(poll)      # an event wait, not a sleep
            if not controller.running():
                raise RunFailed("controller exited with status %s while starting; see %s:\n%s"
                                % (controller.returncode, log_path, controller.log_tail(8)))
            try:
                _, _, (publishers, subscribers, _) = master.getSystemState(NODE)
            except OSError:
                publishers, subscribers = [], []
            simulator_topics = {t for t, names in publishers if SIMULATOR_NODE in names}
            nodes = {n for topic, names in publishers if topic == COMMAND_TOPIC for n in names
                     if n != NODE}
            wanted = sorted((n, t) for t, names in subscribers if t in simulator_topics
                            for n in names if n in nodes)
            ready = any(self.session.connected(SIMULATOR_NODE, COMMAND_TOPIC, n) for n in nodes) \
                and all(self.session.connected(SIMULATOR_NODE, t, n) for n, t in wanted)
            now = time.monotonic()
            if ready and spun:
                return
            if ready and wanted == last:
                if ready_since is None:
                    ready_since = now
                    own = len(nodes) == 1 and self.session.node_pid(next(iter(nodes))) \
                        == controller.pid
                used = processes.cpu_seconds(controller.pid) if own else None
                if used is None or used != cpu:
                    cpu, idle_since = used, now
                if now - ready_since >= settle or (
                        own and now - idle_since >= idle and now - ready_since >= idle):
                    return
            else:
                ready_since, own, cpu, idle_since = None, None, None, None
            last = wanted
            if spinning is None or spun:
                time.sleep(poll_spinning if spun else poll)
        raise RunFailed("the controller published no %s within %.0f s of wall time (it is "
                        "running; see %s)" % (COMMAND_TOPIC, timeout, log_path))

    def _measure(self, scenario, recorder, options, runs_dir, settled=lambda: None):
        """The run's metrics over [0, duration] of sim time. What needs only the track
        (heard up to `duration` already) comes first; `settled()` returns once the other
        topics' last messages are in."""
        from pybullet_gazebo.engine.transforms import Pose, yaw_from_quaternion
        task, duration = scenario.task, scenario.duration
        rows = [(p[0], p[1], p[2], yaw_from_quaternion(p[4:8]), *p[3:8]) for p in recorder.poses]
        track = metrics.clip_track(np.array(rows).reshape(-1, 9), duration)
        if not len(track):
            raise RunFailed("no odometry was heard during the run")
        goal_time = metrics.time_to_goal(track, task.goal, task.tolerance) \
            if task.kind == "goal" else None
        if goal_time is not None:
            # a goal run ends at the goal: the world is paused a few ticks later, as many as
            # the wall clock lets pass (the run's wait looks every 0.1 s), so what came
            # after (the final pose, the distance) would differ between the same runs
            duration = goal_time
            track = metrics.clip_track(track, goal_time)
        end = float(track[-1, 0])
        sampled = metrics.decimate(track, CLEARANCE_PERIOD)
        poses = [Pose(tuple(r[1:3]) + (r[4],), tuple(r[5:9])) for r in sampled]
        scene = self._scene(scenario.world)
        clearances = nearest = None
        if task.kind == "wall":
            clearances = scene.clearance(poses, max_distance=50.0)
        else:
            nearest = scene.nearest(poses, max_distance=50.0)
        settled()
        events, touching = metrics.contact_figures(recorder.contacts, duration)
        if events:      # obstacles may have been pushed: measure where the simulator left them
            try:
                scene.set_model_poses({n: p for n, p in model_poses().items() if n != ROBOT})
                if task.kind == "wall":
                    clearances = scene.clearance(poses, max_distance=50.0)
                else:
                    nearest = scene.nearest(poses, max_distance=50.0)
            finally:
                scene.world.reset_world()
        wall_share = None
        if clearances is not None:
            distances = np.array([c.distance for c in clearances])
            nearest = clearances[int(np.argmin(distances))] if len(clearances) else None
            wall_share = metrics.fraction_within(distances, task.wall_near, task.wall_far)
        distance = metrics.distance_travelled(track[:, 1:3])
        success, reason = metrics.judge(task, distance, events, goal_time, wall_share)
        path = metrics.decimate(track, PATH_PERIOD)
        result = {
            "success": success, "reason": reason, "sim_time_s": end,
            "time_to_goal_s": goal_time, "distance_m": distance,
            "min_clearance_m": metrics.finite_or_none(nearest.distance) if nearest else None,
            "min_clearance_model": nearest.model if nearest else "",
            "contact_events": events, "time_in_contact_s": touching,
            "time_stuck_s": metrics.stuck_time(track),
            "wall_share": wall_share,
            "final_x": float(track[-1, 1]), "final_y": float(track[-1, 2]),
            "final_yaw": float(track[-1, 3]),
            "path": [[round(float(t), 3), round(float(x), 4), round(float(y), 4)]
                     for t, x, y in path[:, :3]],
        }
        if options.bag:
            result["bag"] = os.path.join(runs_dir, scenario.run_id + ".bag")
        if options.picture:
            result["picture"] = self._picture(scenario, track, scene, runs_dir)
        if options.replay:
            began = time.monotonic()
            result["replay"] = self._replay(scenario, track, scene, runs_dir)
            result["_replay_s"] = round(time.monotonic() - began, 3)   # (in measure_s)
        return result

    def _replay(self, scenario, track, scene, runs_dir):
        import json
        import rospy
        from ..analysis import replays
        path = os.path.join(runs_dir, scenario.run_id + ".replay.json")
        rows = np.concatenate([track[:, :3], track[:, 4:9]], axis=1)   # t x y z q (no yaw)
        replay = replays.build(scene, rospy.get_param(ROBOT_DESCRIPTION_PARAM), rows,
                               "%s: %s from (%.2f, %.2f), seed %d" % (
                                   scenario.world_label,
                                   os.path.basename(scenario.controller[-1]), scenario.x,
                                   scenario.y, scenario.seed))
        with open(path, "w") as out:
            json.dump(replay, out, separators=(",", ":"))
        return path

    def _picture(self, scenario, track, scene, runs_dir):
        from ..analysis import picture
        from ..analysis.scene import SCAN_HEIGHT
        path = os.path.join(runs_dir, scenario.run_id + ".png")
        picture.draw(path, scene.outlines(SCAN_HEIGHT), track[:, 0], track[:, 1], track[:, 2],
                     track[:, 3], title="%s: %s from (%.2f, %.2f), yaw %.0f deg, seed %d" % (
                         scenario.world_label, os.path.basename(scenario.controller[-1]),
                         scenario.x, scenario.y, math.degrees(scenario.yaw), scenario.seed))
        return path

    # --- the end ------------------------------------------------------------------------
    def close(self):
        for scene in self.scenes.values():
            scene.close()
        self.scenes.clear()
        self.services.close()
        if self.session is not None:
            try:
                import rospy
                if rospy.core.is_initialized():
                    rospy.signal_shutdown("batch worker closing")
            except ImportError:
                pass
            # quick: a closing Dask worker may be killed a few seconds later. The zygote
            # first (idle: it ends at once), then the rest together.
            if self.zygote is not None:
                self.zygote.close()
                self.zygote = None
            children = list(self.session.children.values())
            processes.stop(children, sigint_timeout=3.0, sigterm_timeout=2.0)
            if self.session.master_uri:
                processes.kill_leftovers(self.session.master_uri)
            self.session = None


def _case_shares(log_path, duration):
    """{case: sim seconds} of obstacle_avoidance.py's case lines in the controller's log
    (rospy prints each with its sim time), {} for a controller that prints none."""
    from ..analysis.summary import case_durations, case_lines
    try:
        with open(log_path, encoding="utf-8", errors="replace") as log:
            return case_durations(case_lines(log.read()), 0.0, duration)
    except OSError:
        return {}


# --- the Dask task --------------------------------------------------------------------
_RIG = None
_LOCK = threading.Lock()          # one run at a time per worker process (one master, one node)


def run_scenario(scenario, options):
    """Dask task: runs `scenario` (Scenario.as_dict()) with `options` (RunOptions as a dict)
    on this process's rig; returns the record."""
    return run_on(Rig, Scenario.from_dict(scenario), RunOptions(**options))


def run_on(rig_class, scenario, options):
    """Runs `scenario` on this process's rig, made as `rig_class()` on first use (a tool
    built on the batch runner passes its Rig subclass); returns the record."""
    global _RIG
    with _LOCK:
        if _RIG is None:
            _RIG = rig_class()
            atexit.register(close_rig)
        return _RIG.run(scenario, options)


def close_rig():
    """Stops this process's rig (its simulator, controller and master), if any."""
    global _RIG
    with _LOCK:
        if _RIG is not None:
            _RIG.close()
            _RIG = None


def options_dict(options: RunOptions):
    return asdict(options)

