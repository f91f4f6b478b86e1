"""One graded run on a Dask worker: the batch runner's rig (m2wr_tools.batch.rig, same lockstep
run, same metrics) with the student's packages resolved first, the run isolated
(m2wr_tools.grade.sandbox) and the task's rules enforced (m2wr_tools.grade.rules).

A GradedScenario is a batch Scenario plus who and what: student, task, run index, the folder
of the student's staged packages (shared by every worker: under the grader's output), the
permissions of the task, its turning convention (legacy_mode, a world launch argument: the
simulator is relaunched when it changes) and what to do once the controller is up
(after_start). Its run_id is `<student>__<task>__<index>_<digest>`.

What GradeRig adds to a run:
  before   the packages copied into the run's own folder (sandbox.prepare), the
           controller's environment made from it (classroom.overlay_env: their packages
           first, `shadowed` names nowhere else) and its command resolved in it; a launch
           file's simulator, world and spawn left out of the run's copy (launch_filter)
  up       the task's after_start steps (a switch service called, a parameter set), with
           the world still paused
  start    the controller through prlimit, as the slot's user, in its own process group;
           a Watchdog on its memory that also looks at the master's graph (rules)
  end      every process of the run stopped by PID (the slot user's, or the controller's
           group); the simulator's call log read from where the run began; findings judged:
           a rule broken or the memory limit passed fails the run with that reason
The record gets: student, task, index, legacy_mode, left_out (what the launch files lost:
file, element, why), after_start (what each step did, in words), turned_in_place_deg (a goal
run's turns on the spot, [away from the goal, toward it], scoring.turns_in_place; a missed
goal's reason says "turned away from the goal" from them), findings (each rule
finding), user, isolated, memory_peak_mib, leftovers (processes that outlived the controller's stop), grader_s (the
wall time of what the grader adds around the batch runner's run: files in and out, the end).
"""
from dataclasses import asdict, dataclass, fields
import hashlib
import json
import os
import threading
import time
import xmlrpc.client
from typing import Tuple

import yaml

from ..running import gazebo_calls, processes, stale_nodes
from ..batch.rig import NODE, Rig, RunFailed, RunOptions, run_on
from ..batch.scenarios import Scenario
from . import classroom, launch_filter, rules, sandbox, scoring
from .spec import Limits, Step

SET_MODEL_STATE = "/gazebo/set_model_state"
PLACEMENT_WAIT = 5.0                    # [s] wall: longest wait for a bug program's placement
CALL_TIMEOUT = 10.0                     # [s] wall: an after_start call's answer, after its wait
SIMULATOR = "/gazebo"


@dataclass(frozen=True)
class GradedScenario(Scenario):
    student: str = ""
    task_name: str = ""
    index: int = 0
    packages: str = ""                 # folder of the student's staged packages
    allow: Tuple[str, ...] = ()
    legacy_mode: bool = False          # the world launch's legacy_mode:= (Kinetic's turning)
    after_start: Tuple[Step, ...] = ()

    @property
    def run_id(self):
        digest = hashlib.sha1(json.dumps(self.as_dict(), sort_keys=True).encode()).hexdigest()
        return "%s__%s__%d_%s" % (self.student, self.task_name, self.index, digest[:8])

    def as_dict(self):
        data = super().as_dict()
        data.update(student=self.student, task_name=self.task_name, index=self.index,
                    packages=self.packages, allow=list(self.allow))
        # only when set: a task without them keeps the run_id (and resume) it had before
        if self.legacy_mode:
            data["legacy_mode"] = True
        if self.after_start:
            data["after_start"] = [step.as_dict() for step in self.after_start]
        return data

    @classmethod
    def from_dict(cls, data):
        base = Scenario.from_dict(data)
        return cls(**{f.name: getattr(base, f.name) for f in fields(Scenario)},
                   student=data["student"], task_name=data["task_name"],
                   index=int(data["index"]), packages=data["packages"],
                   allow=tuple(data["allow"]), legacy_mode=bool(data.get("legacy_mode")),
                   after_start=tuple(Step(**step) for step in data.get("after_start", ())))


@dataclass
class GradeOptions(RunOptions):
    shadowed: Tuple[str, ...] = ()     # package names found only in the student's folder
    cpu_s: float = Limits.cpu_s
    memory_mib: float = Limits.memory_mib
    processes: int = Limits.processes
    file_mib: float = Limits.file_mib

    @property
    def limits(self):
        return Limits(self.cpu_s, self.memory_mib, self.processes, self.file_mib)


class GradeRig(Rig):
    def __init__(self):
        super().__init__()
        self.slot = sandbox.Slot()
        self.current = None            # the run being graded: _Run

    # --- the simulator logs who calls its services ---------------------------------------
    def _call_log(self):
        return os.path.join(self.session.log_dir, gazebo_calls.FILE_NAME)

    @classmethod
    def _world_args(cls, scenario):
        return ("legacy_mode:=%s" % str(bool(getattr(scenario, "legacy_mode", False))).lower(),)

    def _ensure_simulator(self, scenario, options):
        # set before each (re)launch: a run may have changed the parameter
        self.session.master().setParam(NODE, gazebo_calls.PARAM, self._call_log())
        return super()._ensure_simulator(scenario, options)

    # --- one run --------------------------------------------------------------------------
    def run(self, scenario, options):
        began = time.monotonic()
        folder = sandbox.prepare(self.slot, scenario.student, scenario.packages)
        self.current = _Run(scenario, options, folder)
        inner = None
        try:
            inner = time.monotonic()
            record = super().run(scenario, options)
            inner = time.monotonic() - inner
        finally:
            current, self.current = self.current, None
            current.finish(self)
            sandbox.remove(folder)
        # the grader's own part of the run [s wall], beside the batch runner's overhead_s:
        # the student's files copied in and removed, the last look, the end by PID
        record["grader_s"] = round(time.monotonic() - began - inner, 3)
        record.update(student=scenario.student, task=scenario.task_name, index=scenario.index,
                      legacy_mode=scenario.legacy_mode, left_out=current.left_out,
                      after_start=current.steps, user=self.slot.name,
                      isolated=sandbox.isolating(),
                      findings=current.findings, memory_peak_mib=current.peak_mib,
                      memory_over=current.watchdog.seen if current.watchdog else "",
                      leftovers=current.leftovers)
        turns = None
        if scenario.task.kind == "goal" and "path" in record:
            turns = self._turns_in_place(scenario)
            if turns is not None:       # [deg] on the spot, away from the goal and toward it
                record["turned_in_place_deg"] = list(turns)
        broken = current.watchdog_finding or rules.verdict(current.findings)
        if broken:
            record.update(success=False, reason=broken)
        elif not record.get("success") and scenario.task.kind == "goal" and "path" in record:
            hint = scoring.goal_hint(record, scenario.task.goal, scenario.legacy_mode,
                                     turns=turns)
            if hint:
                record["reason"] = "%s: %s" % (record.get("reason", ""), hint)
        return record

    def _turns_in_place(self, scenario):
        """scoring.turns_in_place of the run just measured (its whole track, [0, duration]
        of sim time, as the recorder heard it), or None without one."""
        poses = getattr(self.recorder, "poses", None)
        if not poses:
            return None
        from pybullet_gazebo.engine.transforms import yaw_from_quaternion
        track = [(p[0], p[1], p[2], yaw_from_quaternion(p[4:8])) for p in poses
                 if 0.0 <= p[0] <= scenario.duration]
        return scoring.turns_in_place(track, scenario.task.goal)

    def _resolve(self, argv):
        """`rosrun PKG EXE ARGS` as the executable's path in the student's packages (as
        rosrun would find it there); `roslaunch PKG FILE ARGS` as given, its launch file (in
        the run's copy) without what would touch the grader's world (launch_filter, which
        the record's left_out lists); anything else as given."""
        argv = tuple(argv)
        if self.current is None or len(argv) < 3:
            return argv
        from ..running.commands import find_in_package, package_dir
        if argv[0] == "rosrun":
            folder = package_dir(argv[1], self.current.env(self))
            found = find_in_package(folder, argv[2], executable=True) if folder else []
            if found:
                return (found[0],) + argv[3:]
        elif argv[0] == "roslaunch":
            words = [a for a in argv[1:] if not a.startswith("-") and ":=" not in a]
            folder = package_dir(words[0], self.current.env(self)) if len(words) >= 2 else None
            ws = os.path.join(self.current.folder, "ws")
            packages = {name: os.path.join(ws, name) for name in sorted(os.listdir(ws))
                        if os.path.isfile(os.path.join(ws, name, "package.xml"))}
            for path in find_in_package(folder, words[1], executable=False) if folder else []:
                self.current.left_out += [vars(left) for left in launch_filter.filter_in_place(
                    path, packages, root=ws)]
        return argv

    def _start_controller(self, argv, log_path, warm):
        """The student's command with the run's limits, folder and user: a Python script
        (`rosrun PKG SCRIPT.py`, resolved in their packages) forked from the worker's warm
        zygote, which sets them in the child before the script's first line, as the batch
        runner starts its controllers; anything else (roslaunch, a binary) through prlimit."""
        run = self.current
        env = run.env(self)
        run.calls_from = run.calls_start = _size(self._call_log())
        run.master = xmlrpc.client.ServerProxy(self.session.master_uri)
        isolating = sandbox.isolating()
        user = self.slot.uid if isolating else None
        group = self.slot.gid if isolating else None
        child = self._start_warm_or_plain(
            argv, log_path, warm, env, lambda: processes.Child(
                "controller", sandbox.limited(argv, run.options.limits, isolating), env,
                log_path, cwd=run.folder, user=user, group=group),
            cwd=run.folder, user=user, group=group,
            rlimits=sandbox.rlimits(run.options.limits, isolating))
        run.watch(self, child)
        return child

    def _wait_for_controller(self, controller, timeout, log_path, **kwargs):
        """As the batch runner waits, then a look at the rules while the world is still
        paused: what the program subscribed to as it started is found at the start's sim
        time on every grading (the watchdog's looks come at wall times the machine picks;
        seen first by one of them, a warm-started program's subscription was dated 0.00 s
        in one grading and 0.01 s in the next, and grades.csv differed). A program the
        rules stopped before the world ran ends its run here, whichever look found it: the
        watchdog's while it started (its processes stopped) or this one."""
        super()._wait_for_controller(controller, timeout, log_path, **kwargs)
        run = self.current
        if run is not None:
            if "set_model_state_to_start" in run.scenario.allow:
                self._wait_for_placement(run, controller)
            for step in run.scenario.after_start:
                run.steps.append(self._after_start(step, controller))
            run.look(self)
            if run.broken:
                raise RunFailed(rules.verdict(run.findings))

    def _wait_for_placement(self, run, controller):
        """A task that lets the program put m2wr at its start (the series' bug programs call
        set_model_state as they start, after waiting for their services): the world stays
        paused until the call log shows that call, for PLACEMENT_WAIT s of wall time at most
        (a program that never calls it then starts as it is). Unpaused first, the run would
        start a few ticks before the call on one grading and after it on the next."""
        deadline = time.monotonic() + PLACEMENT_WAIT
        while time.monotonic() < deadline and controller.running():
            calls, _ = gazebo_calls.read(self._call_log(), run.calls_start)   # the
            # watchdog moves calls_from on as it reads
            if gazebo_calls.called(calls, SET_MODEL_STATE, not_by=NODE):
                return
            time.sleep(0.02)

    def _after_start(self, step, controller):
        """Does one after_start step with the world paused (the series' switch, called as its
        pages call it by hand: `rosservice call /go_to_point_switch "data: true"`); what it
        did, in words. RunFailed when a call the task needs cannot be made."""
        import rospy
        name = step.name if step.name.startswith("/") else "/" + step.name
        if step.kind == "param":
            rospy.set_param(name, yaml.safe_load(step.text))
            return "set the parameter %s to %s" % (name, step.text)
        deadline = time.monotonic() + step.wait
        while not self.session.service_offered(name):
            if time.monotonic() >= deadline or not controller.running():
                if step.if_offered:
                    return ("did not call %s: the program offers no such service (it runs "
                            "as it starts)" % name)
                raise RunFailed("after start: the program offered no %s within %g s of wall "
                                "time; the task calls it (%s)" % (name, step.wait,
                                                                  step.describe()))
            time.sleep(0.02)
        answer = {}

        def call():
            try:
                import genpy
                import rosservice
                kind = rosservice.get_service_class_by_name(name)
                request = kind._request_class()
                value = yaml.safe_load(step.text) if step.text.strip() else None
                genpy.message.fill_message_args(request, [] if value is None else [value])
                answer["response"] = rospy.ServiceProxy(name, kind)(request)
            except Exception as err:            # the student's service: any failure is theirs
                answer["error"] = "%s: %s" % (type(err).__name__, err)
        caller = threading.Thread(target=call, daemon=True)
        caller.start()
        caller.join(step.wait + CALL_TIMEOUT)
        if caller.is_alive() or "error" in answer:
            raise RunFailed("after start: %s did not answer %s" % (
                step.describe(), "within %g s of wall time" % (step.wait + CALL_TIMEOUT)
                if caller.is_alive() else "(%s)" % answer["error"]))
        fields = answer["response"].__slots__
        said = ", ".join("%s: %s" % (f, getattr(answer["response"], f)) for f in fields)
        return "called %s (%s): %s" % (name, step.text, said[:120] or "answered")

    def _stop_controller(self, known_exit):
        if self.current is not None and self.current.watchdog is not None:
            self.current.watchdog.stop()
            self.current.look(self)                # the graph as it ends, nodes still up
        return super()._stop_controller(known_exit)

    def close(self):
        super().close()
        self.slot.close()


class _Run:
    """The state of one graded run on the rig."""

    def __init__(self, scenario, options, folder):
        self.scenario, self.options, self.folder = scenario, options, folder
        self.findings, self.seen = [], set()
        self.left_out = []              # launch_filter.LeftOut as dicts
        self.steps = []                 # what each after_start step did, in words
        self.broken = False             # a finding no rule allows was seen
        self.watchdog = self.controller = self.master = None
        self.calls_from = None          # the call log's offset the next look reads from
        self.calls_start = None         # ... and where it stood as the controller started
        self.peak_mib = 0.0
        self.leftovers = ""
        self._env = None
        self._looking = threading.Lock()

    @property
    def watchdog_finding(self):
        return self.watchdog.finding if self.watchdog is not None else None

    def env(self, rig):
        if self._env is None:
            env = classroom.overlay_env(rig.session.env, os.path.join(self.folder, "ws"),
                                        self.options.shadowed)
            self._env = sandbox.environment(env, self.folder)
        return self._env

    def pids(self, rig):
        if sandbox.isolating():
            return sandbox.pids_of_user(rig.slot.uid)
        return sandbox.group_members(self.controller.pid) if self.controller else []

    def kill(self, rig):
        if sandbox.isolating():
            return sandbox.kill_user(rig.slot.uid)
        if self.controller is not None:
            pids = self.pids(rig)
            self.controller.signal_group(9)
            return processes.describe(pids)
        return ""

    def watch(self, rig, controller):
        self.controller = controller
        self.watchdog = sandbox.Watchdog(lambda: self.pids(rig), self.options.memory_mib,
                                         lambda: self.kill(rig),
                                         also=lambda: self.look(rig, graph=False))
        self.watchdog.start()

    def look(self, rig, graph=True):
        """New findings from the simulator's call log (service calls, users of its /gazebo/*
        topics) and, with `graph`, the master's graph (subscriptions to /gazebo/* topics
        nobody serves, a node that registered but never connected); a finding no rule
        allows ends the run's processes at once (the run has failed). From the watchdog's
        thread (the log alone: a look at the master wakes it, and lockstep waits for the
        master) and from the rig's, before the world runs and as the controller stops: one
        look at a time."""
        with self._looking:
            self._look(rig, graph)

    def _look(self, rig, graph):
        sim_time = (rig.recorder.sim_time if rig.recorder is not None else None) or 0.0
        calls, self.calls_from = gazebo_calls.read(rig._call_log(), self.calls_from)
        new = rules.service_findings(calls, self.scenario.allow,
                                     (self.scenario.x, self.scenario.y), ignore=(NODE,))
        users = rules.logged_topic_users(calls, ignore=(NODE, SIMULATOR))
        if graph:
            code, _, state = self.master.getSystemState(NODE)
            if code == 1:
                users += [(kind, topic, node, sim_time) for kind, topic, node in
                          sorted(rules.graph_findings(state, ignore=(NODE, SIMULATOR)))]
        for kind, topic, node, when in users:
            if (kind, topic, node) not in self.seen:
                self.seen.add((kind, topic, node))
                new.append(rules.topic_finding(kind, topic, node, when))
        self.findings += new
        if not self.broken and rules.verdict(new):
            self.broken = True
            self.kill(rig)

    def finish(self, rig):
        """After the controller's stop: the last look, the rest of the run's processes
        stopped by PID."""
        if self.watchdog is not None:
            self.watchdog.stop()
            self.peak_mib = round(self.watchdog.peak_mib, 1)
        self.leftovers = self.kill(rig)
        if self.master is not None:
            forget_nodes(self.master, keep=(NODE, SIMULATOR))


def forget_nodes(master, keep):
    """Unregisters from the master every node other than `keep` (stale_nodes.unregister): a
    run's nodes stopped with SIGKILL (the watchdog, the end by PID) never unregister, and the
    next run's rules would see their subscriptions."""
    code, _, state = master.getSystemState(NODE)
    if code != 1:
        return
    nodes = {node for listing in state for _, names in listing for node in names} - set(keep)
    for node in sorted(nodes):
        found = master.lookupNode(NODE, node)
        stale_nodes.unregister(master, node, found[2] if found[0] == 1 else "", state)


def _size(path):
    try:
        return os.path.getsize(path)
    except OSError:
        return 0


def grade_run(scenario, options):
    """Dask task: one graded run (GradedScenario and GradeOptions as dicts); the record."""
    return run_on(GradeRig, GradedScenario.from_dict(scenario), GradeOptions(**options))


def options_dict(options):
    return asdict(options)
