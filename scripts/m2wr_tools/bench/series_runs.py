"""The series' later programs, written the way the series and its learners write them
(motion_plan's test fixtures in test/series_style/: their own rospy.Rate(20) loops, bang-bang
turns, nothing tuned for this simulator), run in lockstep and at real time, with what a
learner would see: reached or not, sim time to the goal, contact events, where it ended.

    python -m m2wr_tools.bench.series_runs --program go_to_point --goal -3 7 \\
        [--start 0 8 0] [--world world02] [--modes lockstep real-time] [--repeat 1]
        [--rate 20] [--duration 60] [--clock-hz 100] [--json PATH]

A run: the world paused (world launch defaults but headless, legacy_mode:=true: the
series' programs turn as REP 103 says, contacts:=true), m2wr spawned at the start, the
program's launch file started and connected; then, still paused, the behaviour is switched
on (go_to_point, follow_wall; bug2 switches its own, and puts the robot at its start with
/gazebo/set_model_state, which the simulator's call log must show first), the clock of the
run starts (sim time now), physics unpauses, and /odom is watched until the robot is within `tolerance` of the
goal or `duration` of sim time has passed. The same steps in both modes, so that the only
difference is the pacing: lockstep (real_time_factor 0) or real time (real_time_factor 1).
"""
import json
import math
import os
import sys
import threading
import time
from dataclasses import asdict, dataclass, field
from typing import Optional, Tuple

from ..running import gazebo_calls
from ..running.gazebo import call_empty
from ..names import PAUSE_SERVICE, UNPAUSE_SERVICE, WORLD_PROPERTIES_SERVICE
from ..running.processes import raise_on_signals
from ..running.session import Session, SessionError
from ..tool_exit import exit_status
from .. import usage

# program -> (launch file in motion_plan/test/series_style, the switch service the run calls
# or None when the program switches its own behaviours, its nodes' connections to the
# simulator [(node, topic)] that must be up before physics starts: a cmd_vel published
# before the simulator has connected to its publisher is lost, in Gazebo too, and the
# simulator's service its program calls as it starts, which must have been called before
# physics starts, or None: bug 2 puts the robot at its start with set_model_state, and a
# run that unpaused first would start wherever the robot was by then)
PROGRAMS = {
    "go_to_point": ("series_go_to_point.launch", "/go_to_point_switch",
                    [("/go_to_point", "/odom"), ("/go_to_point", "/cmd_vel")], None),
    "follow_wall": ("series_follow_wall.launch", "/wall_follower_switch",
                    [("/follow_wall", "/m2wr/laser/scan"), ("/follow_wall", "/cmd_vel")], None),
    "bug2": ("series_bug2.launch", None,
             [("/go_to_point", "/odom"), ("/go_to_point", "/cmd_vel"),
              ("/follow_wall", "/m2wr/laser/scan"), ("/follow_wall", "/cmd_vel"),
              ("/bug2", "/odom"), ("/bug2", "/m2wr/laser/scan")],
             ("/bug2", "/gazebo/set_model_state")),
}
MODES = ("lockstep", "real-time")


@dataclass
class SeriesRun:
    program: str
    goal: Optional[Tuple[float, float]] = None       # [m]; None: no goal (follow_wall)
    start: Tuple[float, float, float] = (0.0, 8.0, 0.0)   # x [m], y [m], yaw [rad]
    world: str = "world02"
    mode: str = "lockstep"
    duration: float = 60.0          # [s] sim
    rate: float = 20.0              # [Hz] the program's loop
    clock_hz: float = 100.0         # [Hz] sim: /clock (the world launch's default)
    tolerance: float = 0.3          # [m]
    launch_args: Tuple[str, ...] = field(default_factory=tuple)


class Watcher:
    """The run's eyes: /odom (pose, distance), /gazebo/contacts (touch events), /clock."""

    def __init__(self):
        import rospy
        from gazebo_msgs.msg import ContactsState
        from nav_msgs.msg import Odometry
        from rosgraph_msgs.msg import Clock
        self.lock = threading.Lock()
        self.goal = None
        self.tolerance = 0.3
        self.reset()
        rospy.Subscriber("/odom", Odometry, self._on_odom, queue_size=100)
        rospy.Subscriber("/gazebo/contacts", ContactsState, self._on_contacts, queue_size=100)
        rospy.Subscriber("/clock", Clock, self._on_clock, queue_size=1)

    def reset(self, goal=None, tolerance=0.3):
        with self.lock:
            self.goal, self.tolerance = goal, tolerance
            self.pose = None                # (t [s sim], x, y)
            self.reached_at = None          # [s sim]
            self.reached_pose = None        # (x, y) [m] then
            self.distance = 0.0             # [m] driven
            self.touching = set()
            self.contact_events = 0
            self.touches = []               # [(t [s sim], x, y, what)]: each contact's start
            self.sim_time = None

    def _on_clock(self, msg):
        self.sim_time = msg.clock.to_sec()

    def _on_odom(self, msg):
        t = msg.header.stamp.to_sec()
        x, y = msg.pose.pose.position.x, msg.pose.pose.position.y
        with self.lock:
            if self.pose is not None:
                self.distance += math.hypot(x - self.pose[1], y - self.pose[2])
            self.pose = (t, x, y)
            if self.goal is not None and self.reached_at is None \
                    and math.hypot(x - self.goal[0], y - self.goal[1]) < self.tolerance:
                self.reached_at, self.reached_pose = t, (x, y)

    def _on_contacts(self, msg):
        touching = {(s.collision1_name, s.collision2_name) for s in msg.states}
        with self.lock:
            started = touching - self.touching
            self.contact_events += len(started)
            where = self.pose[1:] if self.pose else (float("nan"), float("nan"))
            self.touches.extend((msg.header.stamp.to_sec(), where[0], where[1], " & ".join(pair))
                                for pair in sorted(started))
            self.touching = touching


def sim_time_now():
    """The simulator's sim time [s], paused or not (/gazebo/get_world_properties)."""
    import rospy
    from gazebo_msgs.srv import GetWorldProperties
    rospy.wait_for_service(WORLD_PROPERTIES_SERVICE, timeout=10.0)
    return rospy.ServiceProxy(WORLD_PROPERTIES_SERVICE, GetWorldProperties)().sim_time


def wait_until(condition, timeout, what, check=lambda: None, evidence=lambda: ""):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        check()
        time.sleep(0.02)
    raise SessionError("%s within %.0f s%s" % (what, timeout, evidence()))


def connection_evidence(session, nodes):
    """What the nodes are connected to, and the end of the controller's log: for an error
    message that says why a connection was not made."""
    lines = [session.describe_connections(node) for node in nodes]
    controller = session.child("controller")
    if controller is not None:
        lines.append("the controller's log (%s) ends:\n%s" % (controller.log_path,
                                                               controller.log_tail(15)))
    return "\n" + "\n".join(lines)


def run_once(session, watcher, run: SeriesRun, wall_limit=600.0):
    """One run (the session's master up, rospy initialised); returns its record."""
    import rospy
    from std_srvs.srv import SetBool
    launch_file, switch, connections, start_call = PROGRAMS[run.program]
    lockstep = run.mode == "lockstep"
    call_log = os.path.join(session.log_dir, gazebo_calls.FILE_NAME)
    if os.path.exists(call_log):
        os.remove(call_log)
    session.master().setParam("/series_runs", gazebo_calls.PARAM, call_log)
    session.launch_world(run.world, real_time_factor=0.0 if lockstep else 1.0,
                         lockstep=lockstep, paused=True, pub_clock_frequency=run.clock_hz,
                         contacts=True, extra=("legacy_mode:=true",),
                         # as the batch runner: a loaded machine may starve a controller
                         # past the default 1 s, and a step past would make runs differ
                         lockstep_timeout=30.0)
    try:
        session.wait_for_simulator()
        session.spawn_in_process(*run.start)
        goal = run.goal or (0.0, 0.0)
        args = ["roslaunch", "--sigint-timeout=5", "motion_plan",
                launch_file] + list(run.launch_args)
        if run.program != "follow_wall":
            args += ["des_x:=%g" % goal[0], "des_y:=%g" % goal[1]]
        if run.program == "go_to_point":
            args.append("rate:=%g" % run.rate)
        if run.program == "bug2":
            args += ["initial_x:=%g" % run.start[0], "initial_y:=%g" % run.start[1]]
        session._start("controller", args)
        for node, topic in connections:
            wait_until(lambda: session.connected(node, topic, "/gazebo"), 60.0,
                       "%s did not connect to the simulator on %s" % (node, topic),
                       lambda: session.check_running(["world", "controller"]),
                       lambda: connection_evidence(session, [node, "/gazebo"]))
        if start_call is not None:
            node, service = start_call
            wait_until(lambda: gazebo_calls.called(gazebo_calls.read(call_log)[0], service,
                                                   by=node), 60.0,
                       "%s did not call %s" % start_call,
                       lambda: session.check_running(["world", "controller"]))
        watcher.reset(run.goal, run.tolerance)
        if switch is not None:
            rospy.wait_for_service(switch, timeout=30.0)
            rospy.ServiceProxy(switch, SetBool)(True)
        t0 = sim_time_now()
        wall0 = time.monotonic()
        call_empty(UNPAUSE_SERVICE)
        wait_until(lambda: watcher.reached_at is not None or (
            watcher.sim_time is not None and watcher.sim_time - t0 >= run.duration),
            wall_limit, "the run did not end", lambda: session.check_running(
                ["world", "controller"]))
        wall = time.monotonic() - wall0
        call_empty(PAUSE_SERVICE)
        with watcher.lock:
            sim = (watcher.reached_at or watcher.sim_time) - t0
            pose = watcher.pose
            record = {
                "reached": watcher.reached_at is not None,
                "time_to_goal_s": watcher.reached_at - t0 if watcher.reached_at else None,
                "contact_events": watcher.contact_events,
                "touches": [[t - t0, x, y, what] for t, x, y, what in watcher.touches],
                "distance_m": watcher.distance,
                "end": list(watcher.reached_pose) if watcher.reached_pose else
                [pose[1], pose[2]] if pose else None,
                "sim_s": sim, "wall_s": wall,
                "x_real_time": sim / wall if wall > 0 else None,
            }
    finally:
        session.stop(["controller", "world"])
    record.update(asdict(run))
    return record


def describe(record):
    goal = "to (%g, %g)" % tuple(record["goal"]) if record["goal"] else "no goal"
    outcome = ("reached in %.2f s" % record["time_to_goal_s"]) if record["reached"] else \
        ("not reached in %.0f s" % record["sim_s"] if record["goal"] else
         "%.0f s" % record["sim_s"])
    return ("%s %s from (%g, %g), %s, %g Hz: %s, %d contact event(s), %.1f m driven, ends at "
            "(%.2f, %.2f); %.1fx real time" % (
                record["program"], goal, record["start"][0], record["start"][1],
                record["mode"], record["rate"], outcome, record["contact_events"],
                record["distance_m"], record["end"][0], record["end"][1],
                record["x_real_time"]))


class SeriesSession:
    """A master and this process's rospy node for a series of runs."""

    def __init__(self, log_dir):
        self.session = Session(log_dir, name="series_runs")
        self.watcher = None

    def __enter__(self):
        self.session.start_master()
        self.session.join()
        import rospy
        rospy.init_node("series_runs", disable_signals=True)
        self.watcher = Watcher()
        return self

    def run(self, run: SeriesRun):
        return run_once(self.session, self.watcher, run)

    def __exit__(self, *exc):
        self.session.shut_down("series_runs")


def main(argv=None):
    parser = usage.parser("python -m m2wr_tools.bench.series_runs", __doc__, examples=[
        "python -m m2wr_tools.bench.series_runs --program go_to_point --goal -3 7",
        "python -m m2wr_tools.bench.series_runs --program bug2 --goal 7 0 --start 0 0 0 "
        "--modes lockstep",
        "python -m m2wr_tools.bench.series_runs --program follow_wall --duration 120 "
        "--json walls.json"],
        exit_statuses="Exit status: 0 when every run was made (reached or not: the lines "
        "say); 1 when a run could not\nstart; 2 for bad arguments; 130 when interrupted.")
    parser.add_argument("--program", choices=sorted(PROGRAMS), default="go_to_point",
                        help="the series-style program to run (motion_plan's "
                        "test/series_style/, launched by its series_<program>.launch)")
    parser.add_argument("--goal", type=float, nargs=2, metavar=("X", "Y"),
                        help="the goal [m], needed by go_to_point and bug2 (reached: within "
                        "0.3 m)")
    parser.add_argument("--start", type=float, nargs=3, metavar=("X", "Y", "YAW"),
                        default=(0.0, 8.0, 0.0), help="m2wr's start pose [m m rad] "
                        "(default: 0 8 0)")
    parser.add_argument("--world", default="world02", help="world01, world02, world03 or a "
                        ".world path")
    parser.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES),
                        help="the pacings to run, in this order (default: lockstep real-time)")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each mode")
    parser.add_argument("--rate", type=float, default=20.0,
                        help="the program's own loop rate [Hz], its launch file's rate:=")
    parser.add_argument("--duration", type=float, default=60.0,
                        help="sim time a run may take to reach the goal [s]")
    parser.add_argument("--clock-hz", type=float, default=100.0,
                        help="/clock rate [Hz of sim time]; 100 is the world launch's own")
    parser.add_argument("--arg", action="append", default=[], metavar="NAME:=VALUE",
                        help="an argument of the program's launch file (e.g. d:=1.5); "
                        "repeatable")
    parser.add_argument("--output", default=os.path.join("output", "series_runs"),
                        help="folder for the logs")
    parser.add_argument("--json", help="also write the runs' records to this file (a list) "
                        "(default: none)")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.program != "follow_wall" and args.goal is None:
        parser.error("--goal X Y is needed for %s" % args.program)
    if args.world.endswith(".world"):
        # roslaunch runs the simulator from another folder: a path relative to the user's
        # shell would not be found there
        args.world = os.path.abspath(args.world)
    raise_on_signals()
    records = []

    def runs():
        with SeriesSession(os.path.join(args.output, "logs")) as series:
            for mode in args.modes:
                for _ in range(args.repeat):
                    record = series.run(SeriesRun(
                        args.program, tuple(args.goal) if args.goal else None,
                        tuple(args.start), args.world, mode, args.duration, args.rate,
                        args.clock_hz, launch_args=tuple(args.arg)))
                    records.append(record)
                    print(describe(record), flush=True)
                    if args.json:
                        with open(args.json, "w") as out:
                            json.dump(records, out, indent=1)
    return exit_status("series_runs", runs, interrupted="everything it started is stopped",
                       known=(SessionError,))


if __name__ == "__main__":
    sys.exit(main())
