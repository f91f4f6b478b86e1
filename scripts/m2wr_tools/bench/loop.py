"""The benchmark's ROS figures: the whole loop (simulator + the tutorial's controller) in
lockstep and free-running, the scan/answer check, launch to first scan, and the soak. The
bench's own node listens on /clock, /gazebo/contacts, and while counting on the scan,
/cmd_vel and /rosout."""
import os
import re
import sys
import threading
import time

from . import arithmetic
from ..running import processes
from .arithmetic import fmt
from ..running.gazebo import call_empty
from ..names import (CLOCK_TOPIC, COMMAND_TOPIC, CONTACTS_TOPIC, CONTROLLER_NODE, DEFAULT_START,
                    DEFAULT_WORLD, JOINT_STATES_TOPIC, MODEL_STATES_TOPIC, PAUSE_SERVICE,
                    ROSOUT_TOPIC, SCAN_TOPIC, SIMULATOR_NODE, SPAWN_SERVICE, TF_TOPIC,
                    UNPAUSE_SERVICE)
from ..running.session import SessionError
from ..analysis.summary import is_case

WORLD, START = DEFAULT_WORLD, DEFAULT_START
SCAN_PERIOD = 0.05                   # [s] sim: m2wr's laser runs at 20 Hz
BENCH_NODE = "/m2wr_bench"


def say(text):
    print("[bench] %s" % text, flush=True)


class Listener:
    """The bench's ears: /clock and the robot's touches always; scans (with stamps) and
    cmd_vel while counting."""

    def __init__(self):
        import rospy
        from gazebo_msgs.msg import ContactsState
        from rosgraph_msgs.msg import Clock
        self.sim_time = None
        self.touches = 0                    # times the robot started touching a model
        self.first_scan_wall = None
        self._scan_event = threading.Event()
        self._subs = []
        self.scan_stamps, self.answers, self.callbacks = [], 0, 0
        rospy.Subscriber(CLOCK_TOPIC, Clock, self._on_clock, queue_size=1)
        self._touching = set()
        rospy.Subscriber(CONTACTS_TOPIC, ContactsState, self._on_contacts, queue_size=1000)

    def _on_clock(self, msg):
        self.sim_time = msg.clock.to_sec()

    def _on_contacts(self, msg):
        touching = {(s.collision1_name, s.collision2_name) for s in msg.states}
        self.touches += len(touching - self._touching)
        self._touching = touching

    def count(self, scans=True, commands=True):
        import rospy
        from geometry_msgs.msg import Twist
        from rosgraph_msgs.msg import Log
        from sensor_msgs.msg import LaserScan
        self.stop_counting()
        self.scan_stamps, self.answers, self.callbacks = [], 0, 0
        self.first_scan_wall = None
        self._scan_event.clear()
        if scans:
            self._subs.append(rospy.Subscriber(SCAN_TOPIC, LaserScan, self._on_scan,
                                               queue_size=10000))
        if commands:
            self._subs.append(rospy.Subscriber(COMMAND_TOPIC, Twist, self._on_command,
                                               queue_size=10000, tcp_nodelay=True))
            self._subs.append(rospy.Subscriber(ROSOUT_TOPIC, Log, self._on_log, queue_size=10000))

    def snapshot(self):
        """(scans heard, cmd_vel answers, controller case lines) so far."""
        return len(self.scan_stamps), self.answers, self.callbacks

    def stop_counting(self):
        for sub in self._subs:
            sub.unregister()
        self._subs = []

    def _on_scan(self, msg):
        if self.first_scan_wall is None:
            self.first_scan_wall = time.monotonic()
            self._scan_event.set()
        self.scan_stamps.append(msg.header.stamp.to_sec())

    def _on_command(self, _msg):
        self.answers += 1

    def _on_log(self, msg):
        # one case line per scan obstacle_avoidance.py's callback handled
        if msg.name == CONTROLLER_NODE and is_case(msg.msg):
            self.callbacks += 1

    def wait_first_scan(self, timeout):
        return self._scan_event.wait(timeout)

    def wait_sim(self, timeout=10.0):
        deadline = time.monotonic() + timeout
        start = self.sim_time
        while time.monotonic() < deadline:
            if self.sim_time is not None and self.sim_time != start:
                return self.sim_time
            time.sleep(0.01)
        raise SessionError("sim time did not advance within %.0f s" % timeout)


def wait_counting(session, timeout=10.0):
    """Until the bench hears the simulator's scans and the controller's cmd_vel."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if session.connected(SIMULATOR_NODE, SCAN_TOPIC, BENCH_NODE) \
                and session.connected(CONTROLLER_NODE, COMMAND_TOPIC, BENCH_NODE):
            return
        time.sleep(0.05)
    raise SessionError("the bench's counters did not connect within %.0f s" % timeout)


# obstacle_avoidance.py's rules on a rospy.Rate(20) loop of their own (loop_avoidance.py)
LOOP_PROGRAM = (sys.executable, "-m", "m2wr_tools.bench.loop_avoidance")
# obstacle_avoidance.py beside a behaviour spinning while switched off (switched_off_beside.py)
BUSY_PROGRAM = (sys.executable, "-m", "m2wr_tools.bench.switched_off_beside")


def start_loop(session, lockstep, clock_hz, extra=(), controller=None):
    """Simulator (paused) + m2wr + obstacle_avoidance.py (or `controller`, an argv)
    connected, ready to unpause; `extra`: more arguments of the world's launch file."""
    more = {} if controller is None else {"controller": controller}
    session.start_episode(WORLD, START, lockstep=lockstep, real_time_factor=0.0, seed=0,
                          pub_clock_frequency=clock_hz, extra=extra, **more)
    return session.node_pid(SIMULATOR_NODE), session.children["controller"].pid


# "rviz-like" listeners: a /gazebo/model_states subscriber, robot_state_publisher on
# /joint_states (it publishes the wheels' TF), and subscribers of /tf and /joint_states.
# `rostopic hz` takes messages raw (AnyMsg), so they cost the simulator's publishing, not
# their own deserializing. None reads the scan or /odom: they are watchers, and get /clock
# limited in wall time (clock_topic.py).
WATCHERS = {
    "watch_model_states": ["rostopic", "hz", MODEL_STATES_TOPIC],
    "robot_state_publisher": ["rosrun", "robot_state_publisher", "robot_state_publisher"],
    "watch_tf": ["rostopic", "hz", TF_TOPIC],
    "watch_joint_states": ["rostopic", "hz", JOINT_STATES_TOPIC],
}


def start_watchers(session):
    for name, argv in WATCHERS.items():
        session._start(name, argv)
    time.sleep(3.0)                      # they connect while physics is paused


def watchers_cpu(pids):
    """CPU seconds each listener process has used so far, by name."""
    return {name: processes.cpu_seconds(pid) or 0.0 for name, pid in pids.items()}


def stop_loop(session):
    session.stop([n for n in WATCHERS if n in session.children]
                 + ["controller", "spawn", "world"])


def measure_loop(session, listener, name, lockstep, clock_hz, seconds, check_seconds, warmup=2.0,
                 watchers=False, extra=(), controller=None):
    say("%s: simulator real_time_factor 0, lockstep %s, /clock %g Hz%s%s%s" % (
        name, str(lockstep).lower(), clock_hz, ", with listeners" if watchers else "",
        "".join(", " + arg for arg in extra),
        ", %s" % " ".join(controller[2:]) if controller else ""))
    sim_pid, ctrl_pid = start_loop(session, lockstep, clock_hz, extra, controller)
    try:
        if watchers:
            start_watchers(session)
        call_empty(UNPAUSE_SERVICE)
        time.sleep(warmup)
        session.check_running(["world", "controller"])
        watcher_pids = {n: session.children[n].pid for n in WATCHERS} if watchers else {}
        sim0, wall0, touches0 = listener.wait_sim(), time.monotonic(), listener.touches
        cpu0 = (processes.cpu_seconds(sim_pid), processes.cpu_seconds(ctrl_pid),
                watchers_cpu(watcher_pids))
        time.sleep(seconds)
        sim1, wall1, touches1 = listener.wait_sim(), time.monotonic(), listener.touches
        cpu1 = (processes.cpu_seconds(sim_pid), processes.cpu_seconds(ctrl_pid),
                watchers_cpu(watcher_pids))
        session.check_running(["world", "controller"])
        sim_s, wall_s = sim1 - sim0, wall1 - wall0
        per_sim_s = (lambda seconds: 1e3 * seconds / sim_s if sim_s > 0 else None)
        each_listener = {n: per_sim_s(cpu1[2][n] - cpu0[2][n]) for n in watcher_pids}
        # the scan/answer count: a window that starts and ends paused, with the counters
        # connected beforehand (/rosout is latched: its last line arrives on connecting)
        listener.count()
        wait_counting(session)
        call_empty(PAUSE_SERVICE)
        time.sleep(1.0)                       # answers in flight arrive
        before = listener.snapshot()
        call_empty(UNPAUSE_SERVICE)
        time.sleep(check_seconds)
        call_empty(PAUSE_SERVICE)
        time.sleep(1.0)
        after = listener.snapshot()
        listener.stop_counting()
        scans, answers, handled = (a - b for a, b in zip(after, before))
        edge = 0 if controller is None else 1     # a loop program (see every_scan_handled)
        missing = arithmetic.missing_periods(listener.scan_stamps[before[0]:after[0]], SCAN_PERIOD)
        peak = processes.peak_rss_kib(sim_pid)
        with open(session.children["world"].log_path, errors="replace") as log:
            timeouts = sum("lockstep: " in line and "still at work" in line for line in log)
    finally:
        stop_loop(session)
    result = {
        "lockstep": lockstep, "pub_clock_frequency_hz": clock_hz, "launch_args": list(extra),
        "x_real_time": arithmetic.rate(sim_s, wall_s), "sim_s": sim_s, "wall_s": wall_s,
        "robot_touches": touches1 - touches0,
        "cpu_ms_per_sim_s": {
            "simulator": 1e3 * (cpu1[0] - cpu0[0]) / sim_s if sim_s > 0 else None,
            "controller": 1e3 * (cpu1[1] - cpu0[1]) / sim_s if sim_s > 0 else None,
            "listeners": per_sim_s(sum(cpu1[2].values()) - sum(cpu0[2].values()))
            if watchers else None,
            "each_listener": each_listener},
        "check": {"scans_published": scans + missing, "scans_heard": scans,
                  "handled_by_controller": handled, "cmd_vel_answers": answers,
                  "missing_scans": missing,
                  "every_scan_received": arithmetic.every_scan_handled(scans, handled, missing,
                                                                      edge),
                  "verdict": arithmetic.lockstep_verdict(scans, handled, answers, missing, edge),
                  "lockstep_timeout_warnings": timeouts},
        "simulator_peak_rss_mib": peak / 1024.0 if peak else None,
    }
    say("  %.1fx real time (%.1f s sim in %.1f s wall); controller got every scan: %s" % (
        result["x_real_time"], sim_s, wall_s, result["check"]["verdict"]))
    say("  CPU per sim s [ms]: simulator %s, controller %s%s; load %.2f" % (
        fmt(result["cpu_ms_per_sim_s"]["simulator"], "%.1f"),
        fmt(result["cpu_ms_per_sim_s"]["controller"], "%.1f"),
        "".join(", %s %s" % (n, fmt(v, "%.1f")) for n, v in each_listener.items()),
        os.getloadavg()[0]))
    return result


def launch_to_first_scan(session, listener, clock_hz, timeout=60.0):
    say("launch to first scan: roslaunch world, spawn.launch at once, until the first scan")
    listener.count(scans=True, commands=False)
    t0 = time.monotonic()
    try:
        session.launch_world(WORLD, gui=False, real_time_factor=0.0, lockstep=True, seed=0,
                             paused=False, pub_clock_frequency=clock_hz)
        session.start_spawn(*START)
        service_up = None
        deadline = t0 + timeout
        while time.monotonic() < deadline and not listener.wait_first_scan(0.02):
            if service_up is None and session.service_offered(SPAWN_SERVICE):
                service_up = time.monotonic() - t0
            session.check_running(["world"])
        if listener.first_scan_wall is None:
            raise SessionError("no %s within %.0f s of the launch" % (SCAN_TOPIC, timeout))
        session.finish_spawn()
        first = listener.first_scan_wall - t0
    finally:
        listener.stop_counting()
        stop_loop(session)
    say("  first scan %.2f s after roslaunch (simulator's services up at %s s)"
        % (first, fmt(service_up, "%.2f")))
    return {"first_scan_s": first, "simulator_ready_s": service_up}


def soak(session, listener, minutes, clock_hz):
    say("soak: lockstep loop for %g min of wall time" % minutes)
    started = time.time()
    sim_pid, _ = start_loop(session, True, clock_hz)
    try:
        listener.count(scans=True, commands=True)
        wait_counting(session)
        time.sleep(1.0)                       # the latched /rosout line arrives
        before = listener.snapshot()
        call_empty(UNPAUSE_SERVICE)
        time.sleep(5.0)
        rss0, sim0, wall0 = processes.rss_kib(sim_pid), listener.sim_time, time.monotonic()
        deadline = wall0 + 60.0 * minutes
        while time.monotonic() < deadline:
            time.sleep(min(30.0, max(0.0, deadline - time.monotonic())))
            session.check_running(["world", "controller"])
            say("  soak: %.0f s sim, simulator RSS %.1f MiB" % (
                listener.sim_time or 0.0, (processes.rss_kib(sim_pid) or 0) / 1024.0))
        rss1, sim1, wall1 = processes.rss_kib(sim_pid), listener.sim_time, time.monotonic()
        call_empty(PAUSE_SERVICE)
        time.sleep(1.0)
        listener.stop_counting()
        after = listener.snapshot()
        stamps = listener.scan_stamps[before[0]:after[0]]
        answers, handled = after[1] - before[1], after[2] - before[2]
    finally:
        stop_loop(session)
    errors = error_lines(session.log_dir, since=started)
    result = {
        "minutes": minutes, "sim_s": sim1 - sim0,
        "x_real_time": arithmetic.rate(sim1 - sim0, wall1 - wall0),
        "scans": len(stamps), "handled_by_controller": handled, "cmd_vel_answers": answers,
        "scan_rate_hz_sim": arithmetic.stamp_rate(stamps),
        "missing_scans": arithmetic.missing_periods(stamps, SCAN_PERIOD),
        "simulator_rss_mib": {"start": rss0 / 1024.0 if rss0 else None,
                              "end": rss1 / 1024.0 if rss1 else None,
                              "growth_percent": arithmetic.growth_percent(rss0, rss1)},
        "error_lines": len(errors), "first_errors": errors[:10],
    }
    say("  soak: %.0f s sim, scans at %s Hz sim, RSS %s -> %s MiB (%s %%), %d ERROR lines" % (
        result["sim_s"], fmt(result["scan_rate_hz_sim"], "%.3f"),
        fmt(result["simulator_rss_mib"]["start"]), fmt(result["simulator_rss_mib"]["end"]),
        fmt(result["simulator_rss_mib"]["growth_percent"], "%+.1f"), len(errors)))
    return result


_ERROR = re.compile(r"\[ERROR\]|\bERROR\b|Traceback")


def error_lines(folder, since=0.0):
    """'file: line' for each ERROR (or Traceback) line in the logs under folder written to
    at or after `since` (time.time()); earlier runs' logs stay in the folder."""
    found = []
    for base, _, files in os.walk(folder):
        for name in sorted(files):
            path = os.path.join(base, name)
            if not name.endswith(".log") or os.path.getmtime(path) < since:
                continue
            with open(path, errors="replace") as log:
                for line in log:
                    if _ERROR.search(line):
                        found.append("%s: %s" % (os.path.relpath(path, folder), line.strip()))
    return found
