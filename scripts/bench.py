#!/usr/bin/env python3
"""Benchmark of the stand-in running the tutorial's episode 5 (world02, m2wr at (0, 8),
obstacle_avoidance.py), printed side by side and written to <output>/bench.json.

  scripts/bench.sh [--seconds 15] [--soak MINUTES] [--clock-hz 20] [--output output/]

Figures:
  whole loop        real-time factor of simulator + obstacle_avoidance.py, headless, with
                    real_time_factor 0: free-running (lockstep false) and in lockstep, at the
                    demo's /clock rate and at the simulator's default 100 Hz; CPU time of
                    the simulator and of the controller per sim second; how often the robot
                    touched a model (free-running, the controller's answers come late in sim
                    time and the robot hits barriers: the reason lockstep exists)
  lockstep check    scans published vs cmd_vel answers over a window that starts and ends
                    paused (so no answer is in flight at either edge)
  physics alone     the engine only (no ROS), world02 + m2wr: Bullet's stepSimulation, and
                    World.step with the robot's drive, odometry and laser: steps/s, x real time
  one scan          RaySensor.measure of the 720-beam laser in world02, mean over many
  launch to scan    wall time from `roslaunch my_worlds launch_world.launch` to the first
                    /m2wr/laser/scan, spawn.launch started right after it (own master up)
  peak memory       VmHWM of the simulator process after the lockstep run
  --soak MINUTES    lockstep loop for MINUTES of wall time: scan rate in sim time, missing
                    scans, simulator RSS at start and end (growth %), ERROR lines in the logs
  listeners         the lockstep loop again with a /gazebo/model_states subscriber,
                    robot_state_publisher and /tf and /joint_states subscribers attached (what
                    rviz and a Gazebo tool would add); printed as a ratio to the loop without,
                    and the loop's ratio to World.step alone, both from the same run
The machine is shared: the load average before and after is recorded with the figures.

Where the simulator's time goes (profile recipe): run the loop (scripts/demo.sh, or
`roslaunch my_worlds launch_world.launch gui:=false real_time_factor:=0 lockstep:=true`, spawn
and the controller), then sample the simulator's main thread in wall time:
  pip install py-spy   (not a dependency of the project)
  py-spy record --idle --nonblocking -d 20 -f speedscope -o sim.json -p $(pgrep -f gazebo_world)
and open sim.json in https://www.speedscope.app, thread "MainThread". --idle matters: without
it, rospy's threads blocked in select/recv are not counted and the main thread's own waits
(lockstep, time.sleep(0) in a queued publisher's write_data) are missed. Figures of issue 16
(before DirectPublisher): Bullet's step 28 %, ray casting 13 %, /clock 14 %, scan 10 %,
waiting for the controller 23 %; about 20 % was rospy's queued publish's time.sleep(0).
"""
import argparse
import json
import math
import os
import platform
import re
import signal
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

from demo_lib import benchmath, processes                     # noqa: E402
from demo_lib.benchmath import fmt                             # noqa: E402
from demo_lib.session import Session, SessionError             # noqa: E402
from demo_lib.summary import is_case                            # noqa: E402

WORLD = "world02"
START = (0.0, 8.0, 0.0)              # x [m], y [m], yaw [rad]: the tutorial's spawn y:=8
SCAN_PERIOD = 0.05                   # [s] sim: m2wr's laser runs at 20 Hz
SIMULATOR_DEFAULT_CLOCK_HZ = 100.0


class Interrupted(Exception):
    pass


def say(text):
    print("[bench] %s" % text, flush=True)


# --- the engine alone --------------------------------------------------------------------
def engine_figures(steps=2000, scans=300):
    """Physics and scan costs of world02 + m2wr in a DIRECT client, no ROS."""
    import pybullet
    import rospkg
    import xacro
    from pybullet_utils.bullet_client import BulletClient
    from pybullet_gazebo.engine.ray_sensor import RaySensor
    from pybullet_gazebo.engine.sdf_world import find_world, load_world, model_path_from_env
    from pybullet_gazebo.engine.transforms import Pose
    from pybullet_gazebo.engine.world import World

    rospack = rospkg.RosPack()
    world_path = find_world(WORLD, os.path.join(rospack.get_path("my_worlds"), "worlds"))
    spec = load_world(world_path, model_path_from_env(
        os.path.join(rospack.get_path("pybullet_gazebo"), "models")))
    urdf = xacro.process_file(os.path.join(rospack.get_path("m2wr_description"), "urdf",
                                           "m2wr.xacro")).toxml()
    step = 0.005      # [s] the simulator's default max_step_size
    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        world = World(client, spec, step, warn=lambda _m: None)
        robot = world.spawn_urdf("m2wr", urdf, Pose.from_xyz_rpy(START[0], START[1], 0.5,
                                                                 0, 0, START[2]))
        for _ in range(200):            # lands on its wheels
            world.step()
        for component in robot.parts:
            if hasattr(component, "set_command"):
                component.set_command(0.0, 0.3)      # turning on the spot: wheels in contact
        t = time.perf_counter()
        for _ in range(steps):
            client.stepSimulation()
        physics = time.perf_counter() - t
        t = time.perf_counter()
        for _ in range(steps):
            world.step()
        engine = time.perf_counter() - t
        sensor = next(c for c in robot.parts if isinstance(c, RaySensor))
        t = time.perf_counter()
        for _ in range(scans):
            sensor.measure(world.sim_time)
        scan = (time.perf_counter() - t) / scans
    finally:
        client.disconnect()
    return {
        "physics_only": {"steps_per_s": steps / physics, "x_real_time": steps * step / physics,
                         "us_per_step": 1e6 * physics / steps, "steps": steps},
        "engine_step": {"steps_per_s": steps / engine, "x_real_time": steps * step / engine,
                        "us_per_step": 1e6 * engine / steps, "steps": steps,
                        "what": "World.step: physics + diff drive + odometry 20 Hz + laser 20 Hz"},
        "scan": {"ms_mean": 1e3 * scan, "scans": scans, "beams": 720},
        "step_size_s": step,
    }


# --- the ROS loop --------------------------------------------------------------------------
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
        rospy.Subscriber("/clock", Clock, self._on_clock, queue_size=1)
        self._touching = set()
        rospy.Subscriber("/gazebo/contacts", ContactsState, self._on_contacts, queue_size=1000)

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
            self._subs.append(rospy.Subscriber("/m2wr/laser/scan", LaserScan, self._on_scan,
                                               queue_size=10000))
        if commands:
            self._subs.append(rospy.Subscriber("/cmd_vel", Twist, self._on_command,
                                               queue_size=10000, tcp_nodelay=True))
            self._subs.append(rospy.Subscriber("/rosout", Log, self._on_log, queue_size=10000))

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
        if msg.name == "/reading_laser" and is_case(msg.msg):
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


def call_empty(name):
    import rospy
    from std_srvs.srv import Empty
    rospy.wait_for_service(name, timeout=10.0)
    rospy.ServiceProxy(name, Empty)()


def wait_counting(session, timeout=10.0):
    """Until the bench hears the simulator's scans and the controller's cmd_vel."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if session.connected("/gazebo", "/m2wr/laser/scan", "/m2wr_bench") \
                and session.connected("/reading_laser", "/cmd_vel", "/m2wr_bench"):
            return
        time.sleep(0.05)
    raise SessionError("the bench's counters did not connect within %.0f s" % timeout)


def start_loop(session, lockstep, clock_hz):
    """Simulator (paused) + m2wr + obstacle_avoidance.py connected, ready to unpause."""
    session.launch_world(WORLD, gui=False, real_time_factor=0.0, lockstep=lockstep, seed=0,
                         paused=True, pub_clock_frequency=clock_hz)
    session.wait_for_simulator()
    session.spawn(*START)
    session.start_controller()
    session.wait_for_controller()
    return session.node_pid("/gazebo"), session.children["controller"].pid


# "rviz-like" listeners: a /gazebo/model_states subscriber, robot_state_publisher on
# /joint_states (it publishes the wheels' TF), and subscribers of /tf and /joint_states.
# `rostopic hz` takes messages raw (AnyMsg), so they cost the simulator's publishing, not
# their own deserializing.
WATCHERS = {
    "watch_model_states": ["rostopic", "hz", "/gazebo/model_states"],
    "robot_state_publisher": ["rosrun", "robot_state_publisher", "robot_state_publisher"],
    "watch_tf": ["rostopic", "hz", "/tf"],
    "watch_joint_states": ["rostopic", "hz", "/joint_states"],
}


def start_watchers(session):
    for name, argv in WATCHERS.items():
        session._start(name, argv)
    time.sleep(3.0)                      # they connect while physics is paused


def stop_loop(session):
    session.stop([n for n in WATCHERS if n in session.children]
                 + ["controller", "spawn", "world"])


def measure_loop(session, listener, name, lockstep, clock_hz, seconds, check_seconds, warmup=2.0,
                 watchers=False):
    say("%s: simulator real_time_factor 0, lockstep %s, /clock %g Hz%s" % (
        name, str(lockstep).lower(), clock_hz, ", with listeners" if watchers else ""))
    sim_pid, ctrl_pid = start_loop(session, lockstep, clock_hz)
    try:
        if watchers:
            start_watchers(session)
        call_empty("/gazebo/unpause_physics")
        time.sleep(warmup)
        session.check_running(["world", "controller"])
        sim0, wall0, touches0 = listener.wait_sim(), time.monotonic(), listener.touches
        cpu0 = (processes.cpu_seconds(sim_pid), processes.cpu_seconds(ctrl_pid))
        time.sleep(seconds)
        sim1, wall1, touches1 = listener.wait_sim(), time.monotonic(), listener.touches
        cpu1 = (processes.cpu_seconds(sim_pid), processes.cpu_seconds(ctrl_pid))
        session.check_running(["world", "controller"])
        sim_s, wall_s = sim1 - sim0, wall1 - wall0
        # the scan/answer count: a window that starts and ends paused, with the counters
        # connected beforehand (/rosout is latched: its last line arrives on connecting)
        listener.count()
        wait_counting(session)
        call_empty("/gazebo/pause_physics")
        time.sleep(1.0)                       # answers in flight arrive
        before = listener.snapshot()
        call_empty("/gazebo/unpause_physics")
        time.sleep(check_seconds)
        call_empty("/gazebo/pause_physics")
        time.sleep(1.0)
        after = listener.snapshot()
        listener.stop_counting()
        scans, answers, handled = (a - b for a, b in zip(after, before))
        missing = benchmath.missing_periods(listener.scan_stamps[before[0]:after[0]], SCAN_PERIOD)
        peak = processes.peak_rss_kib(sim_pid)
        with open(session.children["world"].log_path, errors="replace") as log:
            timeouts = sum("lockstep: no cmd_vel" in line for line in log)
    finally:
        stop_loop(session)
    result = {
        "lockstep": lockstep, "pub_clock_frequency_hz": clock_hz,
        "x_real_time": benchmath.rate(sim_s, wall_s), "sim_s": sim_s, "wall_s": wall_s,
        "robot_touches": touches1 - touches0,
        "cpu_ms_per_sim_s": {
            "simulator": 1e3 * (cpu1[0] - cpu0[0]) / sim_s if sim_s > 0 else None,
            "controller": 1e3 * (cpu1[1] - cpu0[1]) / sim_s if sim_s > 0 else None},
        "check": {"scans_published": scans + missing, "scans_heard": scans,
                  "handled_by_controller": handled, "cmd_vel_answers": answers,
                  "missing_scans": missing,
                  "every_scan_received": benchmath.every_scan_handled(scans, handled, missing),
                  "verdict": benchmath.lockstep_verdict(scans, handled, answers, missing),
                  "lockstep_timeout_warnings": timeouts},
        "simulator_peak_rss_mib": peak / 1024.0 if peak else None,
    }
    say("  %.1fx real time (%.1f s sim in %.1f s wall); controller got every scan: %s" % (
        result["x_real_time"], sim_s, wall_s, result["check"]["verdict"]))
    return result


def launch_to_first_scan(session, listener, clock_hz, timeout=60.0):
    say("launch to first scan: roslaunch world, spawn.launch at once, until /m2wr/laser/scan")
    listener.count(scans=True, commands=False)
    t0 = time.monotonic()
    try:
        session.launch_world(WORLD, gui=False, real_time_factor=0.0, lockstep=True, seed=0,
                             paused=False, pub_clock_frequency=clock_hz)
        session.start_spawn(*START)
        service_up = None
        deadline = t0 + timeout
        while time.monotonic() < deadline and not listener.wait_first_scan(0.02):
            if service_up is None and session.service_offered("/gazebo/spawn_urdf_model"):
                service_up = time.monotonic() - t0
            session.check_running(["world"])
        if listener.first_scan_wall is None:
            raise SessionError("no /m2wr/laser/scan within %.0f s of the launch" % timeout)
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
        call_empty("/gazebo/unpause_physics")
        time.sleep(5.0)
        rss0, sim0, wall0 = processes.rss_kib(sim_pid), listener.sim_time, time.monotonic()
        deadline = wall0 + 60.0 * minutes
        while time.monotonic() < deadline:
            time.sleep(min(30.0, max(0.0, deadline - time.monotonic())))
            session.check_running(["world", "controller"])
            say("  soak: %.0f s sim, simulator RSS %.1f MiB" % (
                listener.sim_time or 0.0, (processes.rss_kib(sim_pid) or 0) / 1024.0))
        rss1, sim1, wall1 = processes.rss_kib(sim_pid), listener.sim_time, time.monotonic()
        call_empty("/gazebo/pause_physics")
        time.sleep(1.0)
        listener.stop_counting()
        after = listener.snapshot()
        stamps = listener.scan_stamps[before[0]:after[0]]
        answers, handled = after[1] - before[1], after[2] - before[2]
    finally:
        stop_loop(session)
    errors = error_lines(session.log_dir, since=started)
    result = {
        "minutes": minutes, "sim_s": sim1 - sim0, "x_real_time": benchmath.rate(sim1 - sim0, wall1 - wall0),
        "scans": len(stamps), "handled_by_controller": handled, "cmd_vel_answers": answers,
        "scan_rate_hz_sim": benchmath.stamp_rate(stamps),
        "missing_scans": benchmath.missing_periods(stamps, SCAN_PERIOD),
        "simulator_rss_mib": {"start": rss0 / 1024.0 if rss0 else None,
                              "end": rss1 / 1024.0 if rss1 else None,
                              "growth_percent": benchmath.growth_percent(rss0, rss1)},
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


# --- the report ---------------------------------------------------------------------------
def report(figures):
    loops = figures["loop"]
    names = list(loops)
    rows = [
        ("whole loop, x real time", [fmt(loops[n]["x_real_time"]) for n in names]),
        ("  simulator CPU per sim s [ms]", [fmt(loops[n]["cpu_ms_per_sim_s"]["simulator"], "%.0f")
                                           for n in names]),
        ("  controller CPU per sim s [ms]", [fmt(loops[n]["cpu_ms_per_sim_s"]["controller"], "%.0f")
                                            for n in names]),
        ("robot touched a model (times)", [str(loops[n]["robot_touches"]) for n in names]),
        ("scans published in the check window", [str(loops[n]["check"]["scans_published"])
                                                 for n in names]),
        ("  handled by the controller", [str(loops[n]["check"]["handled_by_controller"])
                                         for n in names]),
        ("  cmd_vel answers heard", [str(loops[n]["check"]["cmd_vel_answers"]) for n in names]),
        ("controller received every scan", [("yes" if loops[n]["check"]["every_scan_received"]
                                             else "no") for n in names]),
        ("simulator peak RSS (VmHWM) [MiB]", [fmt(loops[n]["simulator_peak_rss_mib"])
                                              for n in names]),
    ]
    lines = ["", "m2wr stand-in benchmark (%s, %d cores, load %s before, %s after)" % (
        WORLD, figures["machine"]["cores"], figures["machine"]["load_before"],
        figures["machine"]["load_after"]),
        benchmath.table(names, [(label, *cells) for label, cells in rows])]
    engine = figures["engine"]
    lines += [
        "",
        "physics alone (engine, no ROS, step %g s):" % engine["step_size_s"],
        "  Bullet stepSimulation             %8.0f steps/s  %6.1f x real time" % (
            engine["physics_only"]["steps_per_s"], engine["physics_only"]["x_real_time"]),
        "  World.step (+drive, odom, laser)  %8.0f steps/s  %6.1f x real time" % (
            engine["engine_step"]["steps_per_s"], engine["engine_step"]["x_real_time"]),
        "one 720-beam scan (RaySensor.measure) %6.3f ms mean of %d" % (
            engine["scan"]["ms_mean"], engine["scan"]["scans"]),
    ]
    lockstep = loops.get("lockstep", {}).get("x_real_time")
    watched = loops.get("lockstep + listeners", {}).get("x_real_time")
    step_alone = engine["engine_step"]["x_real_time"]
    lines += [
        "ratios (same run):",
        "  lockstep loop with listeners / without   %s %% (target >= 90 %%)" % (
            fmt(100.0 * watched / lockstep if lockstep and watched else None, "%.0f")),
        "  lockstep loop / World.step alone         %s %% (target >= 60 %%)" % (
            fmt(100.0 * lockstep / step_alone if lockstep and step_alone else None, "%.0f")),
    ]
    launch = figures.get("launch")
    if launch:
        lines.append("launch to first scan                  %6.2f s (simulator ready at %s s)" % (
            launch["first_scan_s"], fmt(launch["simulator_ready_s"], "%.2f")))
    soak_result = figures.get("soak")
    if soak_result:
        rss = soak_result["simulator_rss_mib"]
        lines += [
            "soak (%g min wall, %.0f s sim, %.1fx):" % (soak_result["minutes"], soak_result["sim_s"],
                                                       soak_result["x_real_time"]),
            "  scan rate %s Hz of sim time, %d missing; %d scans, %d handled, %d answers" % (
                fmt(soak_result["scan_rate_hz_sim"], "%.3f"), soak_result["missing_scans"],
                soak_result["scans"], soak_result["handled_by_controller"],
                soak_result["cmd_vel_answers"]),
            "  simulator RSS %s -> %s MiB (%s %%)" % (fmt(rss["start"]), fmt(rss["end"]),
                                                     fmt(rss["growth_percent"], "%+.1f")),
            "  ERROR lines in the logs: %d" % soak_result["error_lines"],
        ]
        lines += ["    " + line for line in soak_result["first_errors"]]
    return "\n".join(lines)


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="bench.sh", description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=15.0,
                        help="wall seconds of each real-time-factor measurement (default 15)")
    parser.add_argument("--check-seconds", type=float, default=5.0,
                        help="wall seconds of each scan/answer count (default 5)")
    parser.add_argument("--clock-hz", type=float, default=20.0,
                        help="/clock rate the demo uses [Hz sim] (default 20)")
    parser.add_argument("--soak", type=float, default=0.0, metavar="MINUTES",
                        help="also run a soak of MINUTES of wall time (default: none)")
    parser.add_argument("--output", default=os.path.join(ROOT, "output"),
                        help="folder for bench.json and logs (default output/)")
    args = parser.parse_args(argv)
    for name in ("seconds", "check_seconds", "clock_hz"):
        if not (math.isfinite(getattr(args, name)) and getattr(args, name) > 0):
            parser.error("--%s must be a number > 0" % name.replace("_", "-"))
    if not (math.isfinite(args.soak) and args.soak >= 0):
        parser.error("--soak must be a number of minutes >= 0")
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out = os.path.abspath(args.output)
    os.makedirs(out, exist_ok=True)
    session = Session(os.path.join(out, "logs", "bench"), name="m2wr_bench")

    def interrupt(signum, _frame):
        raise Interrupted(signal.Signals(signum).name)
    signal.signal(signal.SIGINT, interrupt)
    signal.signal(signal.SIGTERM, interrupt)

    import pybullet
    figures = {"machine": {"cores": os.cpu_count(), "load_before": "%.2f" % os.getloadavg()[0],
                           "python": platform.python_version(),
                           "pybullet": pybullet.getAPIVersion()},
               "world": WORLD, "start": dict(zip(("x", "y", "yaw"), START)), "loop": {}}
    status = 0
    try:
        say("engine alone (no ROS)")
        figures["engine"] = engine_figures()
        say("  stepSimulation %.1fx, World.step %.1fx real time, scan %.3f ms" % (
            figures["engine"]["physics_only"]["x_real_time"],
            figures["engine"]["engine_step"]["x_real_time"], figures["engine"]["scan"]["ms_mean"]))
        session.start_master()
        os.environ.update(ROS_MASTER_URI=session.master_uri, ROS_HOSTNAME="localhost")
        import rospy
        rospy.init_node("m2wr_bench", disable_signals=True)
        listener = Listener()
        loops = figures["loop"]
        loops["free-running"] = measure_loop(session, listener, "free-running", False,
                                             args.clock_hz, args.seconds, args.check_seconds)
        loops["lockstep"] = measure_loop(session, listener, "lockstep", True, args.clock_hz,
                                         args.seconds, args.check_seconds)
        loops["lockstep + listeners"] = measure_loop(
            session, listener, "lockstep + listeners", True, args.clock_hz, args.seconds,
            args.check_seconds, watchers=True)
        if args.clock_hz != SIMULATOR_DEFAULT_CLOCK_HZ:
            loops["lockstep /clock %g Hz" % SIMULATOR_DEFAULT_CLOCK_HZ] = measure_loop(
                session, listener, "lockstep /clock %g Hz" % SIMULATOR_DEFAULT_CLOCK_HZ, True,
                SIMULATOR_DEFAULT_CLOCK_HZ, args.seconds, args.check_seconds)
        figures["launch"] = launch_to_first_scan(session, listener, args.clock_hz)
        if args.soak > 0:
            figures["soak"] = soak(session, listener, args.soak, args.clock_hz)
    except SessionError as err:
        sys.stderr.write("bench: %s\n" % err)
        status = 1
    except Interrupted as err:
        sys.stderr.write("bench: interrupted (%s); stopping everything\n" % err)
        status = 130
    except Exception as err:
        sys.stderr.write("bench: %s: %s\n" % (type(err).__name__, err))
        status = 1
    finally:
        session.shut_down("bench")
    figures["machine"]["load_after"] = "%.2f" % os.getloadavg()[0]
    figures["status"] = "ok" if status == 0 else "failed"
    path = os.path.join(out, "bench.json")
    with open(path, "w") as dump:
        json.dump(figures, dump, indent=2, default=str)
    if "engine" in figures:
        print(report(figures) if figures["loop"] else "", flush=True)
    say("figures written to %s" % path)
    return status


if __name__ == "__main__":
    sys.exit(main())
