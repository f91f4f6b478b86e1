"""Benchmark of the series' bug runs (episodes 8-10) on the stand-in: the project's bug-2
controller (motion_plan standin_bug2.launch: bug2 + go-to-point + wall-follower nodes, each
publishing from its own 20 Hz rospy.Rate loop) takes m2wr from (0, 8) to the goal in lockstep
at real_time_factor 0, as the bug2_*.test rostests run it.

  scripts/bench.sh --bug [--worlds world02 world03] [--output output/]
  (or: python -m m2wr_tools.bench.bug ...)

Prints per world: sim time and wall time from the robot's placement to `goal reached`, their
ratio (x real time), whether lockstep ever timed out (`no cmd_vel within` in the simulator's
log), the contact events (touch onsets from /gazebo/contacts), CPU seconds of the simulator
and of the controllers' launch per sim second, and the load average before and after (the
machine is shared: compare figures only within one run). Writes <output>/bench_bug.json.
The bench's own node does not use sim time (it never hears /clock): it reads sim times from
the stamps of the controller's log lines, so it adds no wake-up per /clock.
"""
import json
import os
import re
import sys
import threading
import time

from ..running import processes
from ..running.processes import raise_on_signals
from ..names import CONTACTS_TOPIC, ROSOUT_TOPIC, SIMULATOR_NODE, SPAWN_LAUNCH
from ..running.session import Session, SessionError
from ..tool_exit import exit_status
from .. import usage

# world: (legacy_mode, the controllers' turn_sign, goal), as bug2_world02/03.test run them
RUNS = {
    "world02": ("true", 1, (0.0, -4.0)),
    "world03": ("false", -1, (0.0, -3.0)),
}
START = (0.0, 8.0)
BUG_NODE = "/bug2"
LOCKSTEP_TIMEOUT = "no cmd_vel within"     # the simulator's warning when lockstep gave up
DEFAULT_SIM_LIMIT = 250.0                  # [s] sim: a run that has not arrived by then fails
DEFAULT_WALL_LIMIT = 300.0                 # [s] wall


def say(text):
    print("[bench_bug] %s" % text, flush=True)


class RunWatch:
    """The bench's ears: the bug controller's log lines (stamped with sim time) and the touch
    onsets /gazebo/contacts reports."""

    def __init__(self):
        import rospy
        from gazebo_msgs.msg import ContactsState
        from rosgraph_msgs.msg import Log
        self.lock = threading.Lock()
        self.lines = []                    # (wall [s], sim [s], text) of BUG_NODE
        self.contact_events = []           # (sim [s], robot, model)
        self.lockstep_timeouts = []        # wall [s] each `no cmd_vel within` was heard
        self._touching = set()
        self._subs = [rospy.Subscriber(ROSOUT_TOPIC, Log, self._on_log, queue_size=1000),
                      rospy.Subscriber(CONTACTS_TOPIC, ContactsState, self._on_contacts,
                                       queue_size=1000)]

    def _on_log(self, msg):
        if LOCKSTEP_TIMEOUT in msg.msg:
            with self.lock:                # the simulator logs in wall time: note when heard
                self.lockstep_timeouts.append(time.monotonic())
            say("  simulator: %s" % msg.msg)
        elif msg.name == BUG_NODE:
            with self.lock:
                self.lines.append((time.monotonic(), msg.header.stamp.to_sec(), msg.msg))
            say("  %7.2f s sim  %s" % (msg.header.stamp.to_sec(), msg.msg))

    def _on_contacts(self, msg):
        touching = {(s.collision1_name, s.collision2_name) for s in msg.states}
        with self.lock:
            for robot, model in sorted(touching - self._touching):
                self.contact_events.append((msg.header.stamp.to_sec(), robot, model))
            self._touching = touching

    def first(self, prefix):
        with self.lock:
            for line in self.lines:
                if line[2].startswith(prefix):
                    return line
        return None

    def close(self):
        for sub in self._subs:
            sub.unregister()


def run_world(session, world, sim_limit, wall_limit):
    legacy_mode, turn_sign, goal = RUNS[world]
    say("%s: simulator lockstep, real_time_factor 0, /clock 20 Hz, legacy_mode %s; bug 2 "
        "from (%g, %g) to (%g, %g)" % (world, legacy_mode, START[0], START[1], *goal))
    load_before = os.getloadavg()
    watch = RunWatch()
    session._start("world", [
        "roslaunch", "--sigint-timeout=10", "--sigterm-timeout=3", "my_worlds", "world.launch",
        "world:=%s" % world, "gui:=false", "legacy_mode:=%s" % legacy_mode, "lockstep:=true",
        "real_time_factor:=0", "pub_clock_frequency:=20", "contacts:=true"])
    session._start("spawn", ["roslaunch", *SPAWN_LAUNCH, "y:=%g" % START[1]])
    session.wait_for_simulator()
    if session.children["spawn"].wait(60.0) is None:
        raise SessionError("spawning m2wr did not finish within 60 s")
    controllers = session._start("controller", [
        "roslaunch", "motion_plan", "standin_bug2.launch", "initial_x:=%g" % START[0],
        "initial_y:=%g" % START[1], "des_x:=%g" % goal[0], "des_y:=%g" % goal[1],
        "turn_sign:=%d" % turn_sign])
    simulator_pid = None
    deadline = time.monotonic() + 60.0
    while watch.first("robot placed") is None:
        if time.monotonic() > deadline or not controllers.running():
            raise SessionError("the bug controller did not place the robot within 60 s; see %s"
                               % controllers.log_path)
        time.sleep(0.02)
    placed = watch.first("robot placed")
    simulator_pid = session.node_pid(SIMULATOR_NODE)
    controller_pids = [p for p in (session.node_pid(n) for n in
                                   ("/bug2", "/go_to_point", "/wall_follower")) if p]
    cpu_start = (processes.cpu_seconds(simulator_pid),
                 sum(processes.cpu_seconds(p) for p in controller_pids))
    reached, last_report = None, time.monotonic()
    while True:
        reached = watch.first("goal reached")
        now = time.monotonic()
        if reached is not None or now - placed[0] > wall_limit or not controllers.running():
            break
        latest = watch.lines[-1][1] if watch.lines else placed[1]
        if latest - placed[1] > sim_limit:
            break
        if now - last_report > 10.0:
            say("  ... %.0f s wall since placement" % (now - placed[0]))
            last_report = now
        time.sleep(0.02)
    cpu_end = (processes.cpu_seconds(simulator_pid),
               sum(processes.cpu_seconds(p) for p in controller_pids))
    end = reached if reached is not None else (time.monotonic(), None, None)
    watch.close()
    world_log = session.children["world"].log_path
    session.stop(["controller", "spawn", "world"])
    run_summary = None
    with open(world_log, errors="replace") as log:
        timeouts = 0
        for line in log:
            timeouts += LOCKSTEP_TIMEOUT in line
            if "run summary:" in line:
                run_summary = line.split("run summary:", 1)[1].strip()
    say("  simulator's run summary (start to stop): %s" % run_summary)
    for name in ("world", "spawn", "controller"):      # keep each world's logs
        path = os.path.join(session.log_dir, name + ".log")
        if os.path.exists(path):
            os.replace(path, os.path.join(session.log_dir, "%s_%s.log" % (world, name)))
    during = [t for t in watch.lockstep_timeouts if placed[0] <= t <= end[0]]
    wall = end[0] - placed[0]
    figures = {"world": world, "goal": goal, "legacy_mode": legacy_mode,
               "reached": reached is not None, "wall_s": wall,
               "lockstep_timeouts": timeouts,            # in the simulator's whole log
               "lockstep_timeouts_during_run": len(during),
               "simulator_run_summary": run_summary,
               "contact_events": len([e for e in watch.contact_events if e[0] >= placed[1]]),
               "contacts": [list(e) for e in watch.contact_events][:10],
               "load_before": load_before[0], "load_after": os.getloadavg()[0]}
    if reached is not None:
        sim = reached[1] - placed[1]
        match = re.search(r"([0-9.]+) m from", reached[2])
        figures.update(sim_s=sim, x_real_time=sim / wall if wall > 0 else None,
                       goal_distance_m=float(match.group(1)) if match else None)
        if simulator_pid is not None and all(c is not None for c in cpu_end + cpu_start):
            figures["cpu_ms_per_sim_s"] = {
                "simulator": 1000.0 * (cpu_end[0] - cpu_start[0]) / sim,
                "controllers": 1000.0 * (cpu_end[1] - cpu_start[1]) / sim}
    return figures


def report(runs, load):
    lines = ["", "bug 2 from (0, 8), lockstep, real_time_factor 0 (load average %s)" % load,
             "%-9s %-8s %9s %9s %12s %9s %9s %14s" % ("world", "reached", "sim [s]", "wall [s]",
                                                      "x real time", "timeouts*", "contacts",
                                                      "CPU sim/ctl ms per sim s")]
    for f in runs:
        cpu = f.get("cpu_ms_per_sim_s")
        lines.append("%-9s %-8s %9s %9.1f %12s %9d %9d %14s" % (
            f["world"], "yes" if f["reached"] else "NO",
            "%.1f" % f["sim_s"] if "sim_s" in f else "-", f["wall_s"],
            "%.1f" % f["x_real_time"] if f.get("x_real_time") else "-",
            f["lockstep_timeouts_during_run"], f["contact_events"],
            "%.0f / %.0f" % (cpu["simulator"], cpu["controllers"]) if cpu else "-"))
    lines.append("* lockstep time-outs (`%s`) between placement and goal; the simulator's "
                 "whole log: %s" % (LOCKSTEP_TIMEOUT, ", ".join(
                     "%s %d" % (f["world"], f["lockstep_timeouts"]) for f in runs)))
    return "\n".join(lines)


def parse_args(argv):
    parser = usage.parser("scripts/bench.sh --bug", __doc__, examples=[
        "scripts/bench.sh --bug                   # both worlds",
        "scripts/bench.sh --bug --worlds world03 --output /tmp/bug"],
        exit_statuses="Exit status: 0 when every run reached its goal; 1 when one did not or "
        "could not run; 2 for\nbad arguments; 130 when interrupted.")
    parser.add_argument("--worlds", nargs="+", default=list(RUNS), choices=list(RUNS),
                        help="the worlds to run bug 2 in, each from its own start to its goal "
                        "(default: %s)" % " ".join(RUNS))
    parser.add_argument("--sim-limit", type=float, default=DEFAULT_SIM_LIMIT,
                        help="sim time a run may take [s]")
    parser.add_argument("--wall-limit", type=float, default=DEFAULT_WALL_LIMIT,
                        help="wall time a run may take [s]")
    parser.add_argument("--output", default="output",
                        help="folder for bench_bug.json and logs")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out = os.path.abspath(args.output)
    os.makedirs(out, exist_ok=True)
    session = Session(os.path.join(out, "logs", "bench_bug"), name="m2wr_bench_bug")

    raise_on_signals()
    runs = []
    load = "%.2f %.2f %.2f" % os.getloadavg()

    def bench_runs():
        session.start_master()
        session.join()
        import rospy
        # before any world sets /use_sim_time: this node keeps wall time and never hears /clock
        rospy.init_node("m2wr_bench_bug", disable_signals=True)
        for world in args.worlds:
            runs.append(run_world(session, world, args.sim_limit, args.wall_limit))
        return 0 if all(r["reached"] for r in runs) else 1
    try:
        status = exit_status("bench_bug", bench_runs, interrupted="stopping everything",
                             known=(SessionError,))
    finally:
        session.shut_down("bench_bug")
    load = "%s before, %.2f %.2f %.2f after" % ((load,) + os.getloadavg())
    path = os.path.join(out, "bench_bug.json")
    with open(path, "w") as dump:
        json.dump({"load": load, "runs": runs, "status": "ok" if status == 0 else "failed"},
                  dump, indent=2, default=str)
    if runs:
        print(report(runs, load), flush=True)
    say("figures written to %s" % path)
    return status


if __name__ == "__main__":
    sys.exit(main())
