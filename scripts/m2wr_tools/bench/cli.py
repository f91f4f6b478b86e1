"""Benchmark of the stand-in running the tutorial's episode 5 (world02, m2wr at (0, 8),
obstacle_avoidance.py), printed side by side and written to <output>/bench.json.

  scripts/bench.sh [--seconds 15] [--soak MINUTES] [--clock-hz 20] [--output output/]
  scripts/bench.sh --listeners-only ROUNDS [--seconds 15] [--watch-rate HZ]
  scripts/bench.sh --loop-program-only [ROUNDS] [--seconds 15]
  scripts/bench.sh --web-only ROUNDS [--pages 1] [--seconds 15]

Figures:
  whole loop        real-time factor of simulator + obstacle_avoidance.py, headless, with
                    real_time_factor 0: free-running (lockstep false) and in lockstep, at the
                    demo's /clock rate and at the simulator's default 100 Hz; CPU time of
                    the simulator and of the controller per sim second; how often the robot
                    touched a model (free-running, the controller's answers come late in sim
                    time and the robot hits barriers: the reason lockstep exists)
  loop program      the same lockstep loop with obstacle_avoidance.py's rules driven by a
                    rospy.Rate(20) loop of their own (m2wr_tools/bench/loop_avoidance.py), at the
                    demo's /clock rate (the batch runner's) and at the simulator's default
                    100 Hz (the world launch's): its x real time over obstacle_avoidance.py's
                    at the same clock (target >= 0.9)
  --loop-program-only  just obstacle_avoidance.py, the loop program, and obstacle_avoidance.py
                    beside a behaviour spinning while switched off (switched_off_beside.py,
                    as bug 0-2 run the series' go to point; target >= 0.8) in lockstep, in
                    turn, ROUNDS times (default 3) at each of the two clock rates: each
                    round's ratios and their medians (the machine's speed drifts between two
                    measurements; in turn, a round's three see the same machine)
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
                    rviz and a Gazebo tool would add), with the simulator's default
                    watch_rate (model_states and joint_states at most ~30-50 per wall second)
                    and with watch_rate:=0 (every message at its sim-time rate, as before the
                    limit); printed as ratios to the loop without, and the loop's ratio to
                    World.step alone, all from the same run. What the listeners stand for:
                    robot_state_publisher is rviz's setup's own (C++); `rostopic hz /tf`
                    stands for rviz's TF listener and `rostopic hz /joint_states` for a joint
                    monitor (both Python: per message they cost more than rviz's C++); the
                    /gazebo/model_states reader for a Gazebo tool or a learner's script. They
                    are watchers (clock_topic.py): /clock at Gazebo's rate but at most
                    max(watch_rate, /clock rate) per wall second. Not included: rviz's
                    drawing: rviz itself (m2wr.rviz, Xvfb, Mesa's software GL) draws at 30 fps
                    whatever the simulator sends, and costs more than all the stand-ins
                    together (docs/performance.md).
  --listeners-only  just the lockstep loop without and with the listeners, ROUNDS times in
                    turn: each round's ratio and the median, CPU per sim s of the simulator,
                    the controller and each listener (the most robust figure on a shared
                    machine: compare the listeners' CPU between builds)
  --web-only        the lockstep loop without and with the live web page (web:=true) and
                    --pages pages watching it, ROUNDS times in turn (m2wr_tools.bench.web)
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
With DirectPublisher, time in TCPROSTransport.write_data (socket.sendall) is mostly a
subscriber being woken: a loopback send wakes the reader, which on 2 busy cores often runs on
the simulator's core while the simulator waits. With the listeners attached (before
clock_topic.py) that line was 24 % of the main thread, half of it /clock to the 4 listeners.
`-f raw` writes one line per stack: grep the main thread's (they start with "<module>
(gazebo_world") and sum by function.
"""
import json
import math
import os
import platform
import statistics
import sys

from . import arithmetic
from ..running.processes import raise_on_signals
from .engine import engine_figures
from .loop import (BUSY_PROGRAM, LOOP_PROGRAM, WORLD, START, Listener, launch_to_first_scan,
                         measure_loop,
                         say, soak)
from .arithmetic import fmt
from ..paths import ROOT
from ..running.session import Session, SessionError
from ..tool_exit import exit_status
from .. import usage

SIMULATOR_DEFAULT_CLOCK_HZ = 100.0
UNLIMITED = "listeners, watch_rate 0"
LOOP = "loop program"       # suffix of the loop program's columns (loop_avoidance.py)
BUSY = "beside a busy loop"  # obstacle_avoidance.py beside a switched-off behaviour


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
        ("  listeners' CPU per sim s [ms]", [fmt(loops[n]["cpu_ms_per_sim_s"].get("listeners"),
                                                 "%.0f") for n in names]),
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
        arithmetic.table(names, [(label, *cells) for label, cells in rows])]
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
        "  the same beams by Bullet's rayTestBatch %6.3f ms" % engine["scan"]["bullet_ray_test_ms_mean"],
    ]
    lockstep = loops.get("lockstep", {}).get("x_real_time")
    watched = loops.get("lockstep + listeners", {}).get("x_real_time")
    unlimited = loops.get(UNLIMITED, {}).get("x_real_time")
    step_alone = engine["engine_step"]["x_real_time"]
    lines += [
        "ratios (same run):",
        "  lockstep loop with listeners / without   %s %% (target >= 90 %%)" % (
            fmt(100.0 * watched / lockstep if lockstep and watched else None, "%.0f")),
        "    the same with watch_rate 0 (no limit)  %s %%" % (
            fmt(100.0 * unlimited / lockstep if lockstep and unlimited else None, "%.0f")),
        "  lockstep loop / World.step alone         %s %% (target >= 60 %%)" % (
            fmt(100.0 * lockstep / step_alone if lockstep and step_alone else None, "%.0f")),
    ]
    for label, ratio in loop_program_ratios(loops):
        lines.append("  loop program / obstacle_avoidance.py, %s  %s (target >= 0.9)"
                     % (label, fmt(ratio, "%.2f")))
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


def whole_bench(session, listener, args, figures):
    """The loop figures of a full run (everything but the engine's)."""
    loops = figures["loop"]
    loops["free-running"] = measure_loop(session, listener, "free-running", False,
                                         args.clock_hz, args.seconds, args.check_seconds)
    loops["lockstep"] = measure_loop(session, listener, "lockstep", True, args.clock_hz,
                                     args.seconds, args.check_seconds)
    loops["lockstep + listeners"] = measure_loop(
        session, listener, "lockstep + listeners", True, args.clock_hz, args.seconds,
        args.check_seconds, watchers=True)
    loops[UNLIMITED] = measure_loop(
        session, listener, UNLIMITED, True, args.clock_hz, args.seconds,
        args.check_seconds, watchers=True, extra=("watch_rate:=0",))
    if args.clock_hz != SIMULATOR_DEFAULT_CLOCK_HZ:
        loops["lockstep /clock %g Hz" % SIMULATOR_DEFAULT_CLOCK_HZ] = measure_loop(
            session, listener, "lockstep /clock %g Hz" % SIMULATOR_DEFAULT_CLOCK_HZ, True,
            SIMULATOR_DEFAULT_CLOCK_HZ, args.seconds, args.check_seconds)
    loop_program_columns(session, listener, args, loops)
    figures["launch"] = launch_to_first_scan(session, listener, args.clock_hz)
    if args.soak > 0:
        figures["soak"] = soak(session, listener, args.soak, args.clock_hz)


def loop_program_columns(session, listener, args, loops):
    """The loop program in lockstep at the batch runner's /clock rate (--clock-hz) and at the
    world launch's default, each beside obstacle_avoidance.py's column of the same clock."""
    for clock_hz in sorted({args.clock_hz, SIMULATOR_DEFAULT_CLOCK_HZ}):
        name = "lockstep%s, %s" % ("" if clock_hz == args.clock_hz else " /clock %g Hz"
                                   % clock_hz, LOOP)
        loops[name] = measure_loop(session, listener, name, True, clock_hz, args.seconds,
                                   args.check_seconds, controller=LOOP_PROGRAM)


def loop_program_ratios(loops):
    """[(label, loop program x real time / obstacle_avoidance.py's)] for each clock rate."""
    ratios = []
    for name, result in loops.items():
        if name.endswith(", " + LOOP):
            answering = loops.get(name[:-len(", " + LOOP)], {}).get("x_real_time")
            ratios.append((name[:-len(", " + LOOP)], result["x_real_time"] / answering
                           if answering and result["x_real_time"] else None))
    return ratios


def loop_program_rounds(session, listener, args):
    """--loop-program-only: obstacle_avoidance.py, the loop program and the busy-loop pair in
    lockstep, in turn, at --clock-hz and at the simulator's default; [{clock label:
    {"answering": result, "loop": result, "busy loop": result, "load": ...}}] one dict per
    round."""
    rounds = []
    for index in range(args.loop_program_only):
        say("round %d of %d" % (index + 1, args.loop_program_only))
        pairs = {}
        for clock_hz in sorted({args.clock_hz, SIMULATOR_DEFAULT_CLOCK_HZ}):
            label = "/clock %g Hz" % clock_hz
            pairs[label] = {
                "answering": measure_loop(session, listener, "lockstep, " + label, True,
                                          clock_hz, args.seconds, args.check_seconds),
                "loop": measure_loop(session, listener, "lockstep, %s, %s" % (label, LOOP),
                                     True, clock_hz, args.seconds, args.check_seconds,
                                     controller=LOOP_PROGRAM),
                "busy loop": measure_loop(session, listener, "lockstep, %s, %s" % (label, BUSY),
                                          True, clock_hz, args.seconds, args.check_seconds,
                                          controller=BUSY_PROGRAM),
                "load": "%.2f" % os.getloadavg()[0]}
        rounds.append(pairs)
    return rounds


def loop_program_report(figures):
    lines = []
    rounds = figures["loop_program_rounds"]
    for kind, target in (("loop", 0.9), ("busy loop", 0.8)):
        lines += ["", "%s / obstacle_avoidance.py in lockstep, round by round (load before "
                  "%s; target >= %g):" % (LOOP if kind == "loop" else BUSY,
                                          figures["machine"]["load_before"], target)]
        for label in (rounds[0] if rounds else {}):
            ratios = []
            for index, pairs in enumerate(rounds):
                if kind not in pairs[label]:
                    continue
                answering = pairs[label]["answering"]["x_real_time"]
                other = pairs[label][kind]["x_real_time"]
                ratio = other / answering if answering and other else None
                if ratio is not None:
                    ratios.append(ratio)
                lines.append("  %s, round %d: %s / %s = %s; load %s" % (
                    label, index + 1, fmt(other, "%.1fx"), fmt(answering, "%.1fx"),
                    fmt(ratio, "%.2f"), pairs[label]["load"]))
            if ratios:
                lines.append("  %s: median %.2f, lowest %.2f" % (
                    label, statistics.median(ratios), min(ratios)))
    return "\n".join(lines)


def listener_rounds(session, listener, args):
    """--listeners-only: the lockstep loop without and with listeners, in turn."""
    extra = () if args.watch_rate is None else ("watch_rate:=%g" % args.watch_rate,)
    rounds = []
    for index in range(args.listeners_only):
        say("round %d of %d" % (index + 1, args.listeners_only))
        without = measure_loop(session, listener, "lockstep", True, args.clock_hz,
                               args.seconds, args.check_seconds, extra=extra)
        watched = measure_loop(session, listener, "lockstep + listeners", True, args.clock_hz,
                               args.seconds, args.check_seconds, watchers=True, extra=extra)
        rounds.append({"without": without, "with": watched,
                       "load": "%.2f" % os.getloadavg()[0]})
    return rounds


def rounds_report(figures):
    lines = ["", "lockstep loop with listeners / without, round by round (load before %s):"
             % figures["machine"]["load_before"]]
    ratios = []
    for index, pair in enumerate(figures["listener_rounds"]):
        without, watched = pair["without"], pair["with"]
        ratio = 100.0 * watched["x_real_time"] / without["x_real_time"] \
            if without["x_real_time"] and watched["x_real_time"] else None
        if ratio is not None:
            ratios.append(ratio)
        cpu0, cpu1 = without["cpu_ms_per_sim_s"], watched["cpu_ms_per_sim_s"]
        lines.append("  round %d: %sx -> %sx = %s %%; CPU per sim s [ms] simulator %s -> %s, "
                     "controller %s -> %s, listeners %s (%s); load %s" % (
                         index + 1, fmt(without["x_real_time"]), fmt(watched["x_real_time"]),
                         fmt(ratio, "%.0f"), fmt(cpu0["simulator"], "%.1f"),
                         fmt(cpu1["simulator"], "%.1f"), fmt(cpu0["controller"], "%.1f"),
                         fmt(cpu1["controller"], "%.1f"), fmt(cpu1["listeners"], "%.1f"),
                         ", ".join("%s %s" % (n, fmt(v, "%.1f"))
                                   for n, v in cpu1["each_listener"].items()), pair["load"]))
    if ratios:
        lines.append("  median: %.0f %% (target >= 90 %%)" % statistics.median(ratios))
    return "\n".join(lines)


def parse_args(argv):
    parser = usage.parser("scripts/bench.sh", __doc__, examples=[
        "scripts/bench.sh                         # every figure of episode 5",
        "scripts/bench.sh --loop-program-only 5   # the loop program's ratio, 5 rounds",
        "scripts/bench.sh --bug --help            # the series' bug-2 runs: their own options",
        "scripts/bench.sh --grade --help          # a class graded: its own options"],
        exit_statuses="Exit status: 0 when the figures were measured (targets are printed, "
        "not asserted); 1 when a\nrun could not start; 2 for bad arguments; 130 when "
        "interrupted.")
    parser.add_argument("--seconds", type=float, default=15.0,
                        help="wall seconds of each real-time-factor measurement (default: 15)")
    parser.add_argument("--check-seconds", type=float, default=5.0,
                        help="wall seconds of each scan/answer count (default: 5)")
    parser.add_argument("--clock-hz", type=float, default=20.0,
                        help="/clock rate the demo uses [Hz sim] (default: 20)")
    parser.add_argument("--soak", type=float, default=0.0, metavar="MINUTES",
                        help="also run a soak of MINUTES of wall time (default: none)")
    parser.add_argument("--listeners-only", type=int, default=0, metavar="ROUNDS",
                        help="only the lockstep loop without and with listeners, ROUNDS times "
                             "in turn (the listener target's ratio per round and its median); "
                             "no engine, free-running or launch figures (default: off)")
    parser.add_argument("--loop-program-only", type=int, nargs="?", const=3, default=0,
                        metavar="ROUNDS",
                        help="only obstacle_avoidance.py, the loop program and "
                             "obstacle_avoidance.py beside a busy loop in lockstep, in turn, "
                             "ROUNDS times (3 when ROUNDS is left out) at --clock-hz and at 100 Hz: "
                             "each round's ratios and their medians (targets >= 0.9 and >= 0.8) "
                             "(default: off)")
    parser.add_argument("--web-only", type=int, default=0, metavar="ROUNDS",
                        help="only the lockstep loop without and with the live web page watched "
                             "by --pages pages, ROUNDS times in turn (ratio per round, median; "
                             "target >= 90 %%) (default: off)")
    parser.add_argument("--pages", type=int, default=1,
                        help="with --web-only: pages watching at once (default: 1)")
    parser.add_argument("--watch-rate", type=float, default=None, metavar="HZ",
                        help="with --listeners-only: the simulator's ~watch_rate (default: its "
                             "own, 30)")
    parser.add_argument("--output", default=os.path.join(ROOT, "output"),
                        help="folder for bench.json and logs (default: output/)")
    args = parser.parse_args(argv)
    for name in ("seconds", "check_seconds", "clock_hz"):
        if not (math.isfinite(getattr(args, name)) and getattr(args, name) > 0):
            parser.error("--%s must be a number > 0" % name.replace("_", "-"))
    if args.listeners_only < 0:
        parser.error("--listeners-only must be a number of rounds >= 1")
    if args.loop_program_only < 0:
        parser.error("--loop-program-only must be a number of rounds >= 1")
    if args.loop_program_only and args.listeners_only:
        parser.error("--loop-program-only and --listeners-only: one at a time")
    if args.watch_rate is not None and not (math.isfinite(args.watch_rate)
                                            and args.watch_rate >= 0):
        parser.error("--watch-rate must be a number of Hz >= 0 (0: no limit)")
    if args.watch_rate is not None and not args.listeners_only:
        parser.error("--watch-rate goes with --listeners-only (the full run measures both)")
    if not (math.isfinite(args.soak) and args.soak >= 0):
        parser.error("--soak must be a number of minutes >= 0")
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out = os.path.abspath(args.output)
    os.makedirs(out, exist_ok=True)
    session = Session(os.path.join(out, "logs", "bench"), name="m2wr_bench")

    raise_on_signals()

    import pybullet
    figures = {"machine": {"cores": os.cpu_count(), "load_before": "%.2f" % os.getloadavg()[0],
                           "python": platform.python_version(),
                           "pybullet": pybullet.getAPIVersion()},
               "world": WORLD, "start": dict(zip(("x", "y", "yaw"), START)), "loop": {}}

    def bench():
        if not (args.listeners_only or args.loop_program_only or args.web_only):
            say("engine alone (no ROS)")
            figures["engine"] = engine_figures()
            say("  stepSimulation %.1fx, World.step %.1fx real time, scan %.3f ms" % (
                figures["engine"]["physics_only"]["x_real_time"],
                figures["engine"]["engine_step"]["x_real_time"],
                figures["engine"]["scan"]["ms_mean"]))
        session.start_master()
        session.join()
        import rospy
        rospy.init_node("m2wr_bench", disable_signals=True)
        # it records and measures: lockstep need not wait for it (docs/lockstep.md)
        from pybullet_gazebo.ros.lockstep import rospy_hooks
        rospy_hooks.watch_only()
        listener = Listener()
        if args.web_only:
            from .web import web_rounds
            figures["web_rounds"] = web_rounds(session, listener, args)
        elif args.listeners_only:
            figures["listener_rounds"] = listener_rounds(session, listener, args)
        elif args.loop_program_only:
            figures["loop_program_rounds"] = loop_program_rounds(session, listener, args)
        else:
            whole_bench(session, listener, args, figures)

    try:
        status = exit_status("bench", bench, interrupted="stopping everything",
                             known=(SessionError,), catch_all=True)
    finally:
        session.shut_down("bench")
    figures["machine"]["load_after"] = "%.2f" % os.getloadavg()[0]
    figures["status"] = "ok" if status == 0 else "failed"
    path = os.path.join(out, "bench.json")
    with open(path, "w") as dump:
        json.dump(figures, dump, indent=2, default=str)
    if figures.get("listener_rounds"):
        print(rounds_report(figures), flush=True)
    if figures.get("web_rounds"):
        from .web import web_report
        print(web_report(figures), flush=True)
    if "engine" in figures:
        print(report(figures) if figures["loop"] else "", flush=True)
    elif figures.get("loop_program_rounds"):
        print(loop_program_report(figures), flush=True)
    say("figures written to %s" % path)
    return status


if __name__ == "__main__":
    sys.exit(main())
