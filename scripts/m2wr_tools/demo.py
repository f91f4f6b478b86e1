"""The tutorial's episode 5, end to end: m2wr in world02 driven by obstacle_avoidance.py.

  scripts/demo.sh [--world world02] [--x 0 --y 8 --yaw 0] [--duration 120] [--seed 0]
                  [--gui] [--web [--web-port 8090] [--web-host 127.0.0.1]] [--realtime] [--bag] [--output output/]

Steps: its own ROS master on a free localhost port -> `roslaunch my_worlds
launch_world.launch` (paused; headless, real_time_factor 0 and lockstep unless --realtime or
--gui or --web, which run at real time) -> `roslaunch m2wr_description spawn.launch x:= y:= yaw:=` ->
`rosrun motion_plan obstacle_avoidance.py` (the tutorial's program, unchanged) -> physics
unpaused for --duration seconds of sim time, with a progress line every ~2 s of wall time ->
physics paused, everything stopped (SIGINT, then SIGTERM/SIGKILL; no process left behind) ->
a top-down picture <output>/demo_<world>.png, a replay of the run in the browser view
<output>/demo_<world>_replay.html (opens from disk: the robot, its path and its laser over a
time slider; m2wr_tools.analysis.replays), a summary printed and written to
<output>/demo_<world>.json, and with --bag <output>/demo_<world>.bag (/m2wr/laser/scan,
/odom, /cmd_vel). Child logs and ROS logs go to <output>/logs/demo/.

Exit status: 0 on success; 1 when a step fails (the message names the step and shows the
failing program's own error); 2 for bad arguments; 130 when interrupted.
"""
import json
import math
import os
import sys
import time

from .running import processes
from .analysis import metrics, summary
from .running.processes import raise_on_signals
from .names import (COMMAND_TOPIC, CONTROLLER_NODE, DEFAULT_START, DEFAULT_WORLD, ODOM_TOPIC,
                    PAUSE_SERVICE, ROBOT_DESCRIPTION_PARAM, SCAN_TOPIC, SIMULATOR_NODE,
                    UNPAUSE_SERVICE)
from .paths import ROOT
from .running.session import Session, SessionError
from .tool_exit import exit_status
from . import usage

BAG_TOPICS = (SCAN_TOPIC, ODOM_TOPIC, COMMAND_TOPIC)
PROGRESS_PERIOD = 2.0       # [s] wall
CLEARANCE_RANGE = 50.0      # [m] obstacles farther than this count as none
DEFAULT_CLOCK_HZ = 20.0     # [Hz] sim; the simulator also publishes /clock with every scan


def parse_args(argv):
    parser = usage.parser("scripts/demo.sh", __doc__, examples=[
        "scripts/demo.sh                          # episode 5: world02, m2wr at (0, 8), 120 s",
        "scripts/demo.sh --web                    # the same at real time, watched in a browser",
        "scripts/demo.sh --world world01 --x 0 --y 0 --duration 60 --bag"])
    parser.add_argument("--world", default=DEFAULT_WORLD,
                        help="world01, world02 or a path to a .world file")
    parser.add_argument("--x", type=float, default=DEFAULT_START[0], help="start x [m]")
    parser.add_argument("--y", type=float, default=DEFAULT_START[1], help="start y [m]; 8 is the tutorial's "
                        "`spawn.launch y:=8`")
    parser.add_argument("--yaw", type=float, default=DEFAULT_START[2], help="start heading [rad]")
    parser.add_argument("--duration", type=float, default=120.0,
                        help="sim time to run the controller [s]")
    parser.add_argument("--seed", type=int, default=0, help="seed of the laser noise")
    parser.add_argument("--gui", action="store_true",
                        help="open pybullet's window (needs a display); runs at real time")
    parser.add_argument("--web", action="store_true",
                        help="watch the run live in a browser on http://127.0.0.1:WEB_PORT/ "
                        "(no display needed); runs at real time")
    parser.add_argument("--web-port", type=int, default=8090,
                        help="TCP port of the live page with --web")
    parser.add_argument("--web-host", default="127.0.0.1",
                        help="address of the live page with --web: 127.0.0.1 is this machine "
                        "only; 0.0.0.0 in a container whose port is published")
    parser.add_argument("--realtime", action="store_true",
                        help="run at real time (real_time_factor 1, no lockstep) instead of "
                        "as fast as possible in lockstep")
    parser.add_argument("--bag", action="store_true",
                        help="record /m2wr/laser/scan, /odom, /cmd_vel to <output>/demo_<world>.bag")
    parser.add_argument("--output", default=os.path.join(ROOT, "output"),
                        help="folder for the picture, summary, bag and logs (default: output/)")
    parser.add_argument("--clock-hz", type=float, default=DEFAULT_CLOCK_HZ,
                        help="/clock rate [Hz of sim time] passed to the simulator as "
                        "pub_clock_frequency; the simulator's own default is 100")
    args = parser.parse_args(argv)
    for name in ("x", "y", "yaw", "duration", "clock_hz"):
        if not math.isfinite(getattr(args, name)):
            parser.error("--%s must be a finite number" % name.replace("_", "-"))
    if args.duration <= 0:
        parser.error("--duration must be > 0 seconds of sim time")
    if args.clock_hz <= 0:
        parser.error("--clock-hz must be > 0")
    return args


def world_label(world):
    base = os.path.basename(world.rstrip("/"))
    return base[:-len(".world")] if base.endswith(".world") else base


_T0 = time.monotonic()


def say(text):
    print("[demo %5.1fs] %s" % (time.monotonic() - _T0, text), flush=True)


def run(args, session, paths):
    """The ROS part; returns what the offline part needs."""
    import rospy
    from .running.gazebo import call_empty, model_poses
    from .running.recorder import Recorder

    realtime = args.realtime or args.gui or args.web
    say("starting a ROS master on a free port")
    uri = session.start_master()
    session.join()
    say("master %s (logs in %s)" % (uri, session.log_dir))
    rospy.init_node("m2wr_demo", disable_signals=True)
    # it records and measures: lockstep need not wait for it (docs/lockstep.md)
    from pybullet_gazebo.ros.lockstep import rospy_hooks
    rospy_hooks.watch_only()
    recorder = Recorder()

    say("simulator: %s, %s" % (args.world, "real time" if realtime
                                else "as fast as possible, lockstep"))
    session.start_episode(args.world, (args.x, args.y, args.yaw), lockstep=not realtime,
                          real_time_factor=1.0 if realtime else 0.0, seed=args.seed,
                          pub_clock_frequency=args.clock_hz, gui=args.gui, say=say,
                          extra=["web:=true", "web_port:=%d" % args.web_port,
                                 "web_host:=%s" % args.web_host] if args.web else ())
    if args.web:
        say("watch it on http://%s:%d/" % ("127.0.0.1" if args.web_host == "0.0.0.0"
                                           else args.web_host, args.web_port))
    urdf = rospy.get_param(ROBOT_DESCRIPTION_PARAM)
    if args.bag:
        session.start_bag(paths["bag"], BAG_TOPICS)
        _wait_for_bag(session)
    say("m2wr spawned, obstacle_avoidance.py connected; running")

    start = recorder.sim_time or 0.0
    recorder.fire_at(start + args.duration)
    call_empty(UNPAUSE_SERVICE)
    wall_start = time.monotonic()
    last_wall, last_sim = wall_start, start
    watch = ["world", "controller"] + (["rosbag"] if args.bag else [])
    while not recorder.reached.wait(PROGRESS_PERIOD):
        session.check_running(watch)
        now_wall, now_sim = time.monotonic(), recorder.sim_time or start
        say(summary.progress_line(now_sim - start, args.duration,
                                  summary.real_time_factor(now_sim - last_sim, now_wall - last_wall),
                                  recorder.current_case()))
        last_wall, last_sim = now_wall, now_sim
    call_empty(PAUSE_SERVICE)
    wall = time.monotonic() - wall_start
    poses = model_poses()
    time.sleep(0.3)          # the last queued messages arrive (physics is paused)
    recorder.unregister()
    end = recorder.sim_time
    say(summary.progress_line(end - start, args.duration, summary.real_time_factor(
        end - start, wall), recorder.current_case()) + "  (run done)")
    return dict(recorder=recorder, urdf=urdf, start=start, end=end, wall=wall, poses=poses)


def _wait_for_bag(session, timeout=15.0):
    """Until rosbag record is connected to the publishers of every topic it records (the
    simulator's scan and odometry, the controller's cmd_vel), so the bag starts at 0 s."""
    import rosgraph
    master = rosgraph.Master("/m2wr_demo")
    publishers = {SCAN_TOPIC: SIMULATOR_NODE, ODOM_TOPIC: SIMULATOR_NODE,
                  COMMAND_TOPIC: CONTROLLER_NODE}
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        session.check_running(["rosbag"])
        _, subscribers, _ = master.getSystemState()
        recorders = {n for _, nodes in subscribers for n in nodes if n.startswith("/record")}
        if any(all(session.connected(publishers[t], t, r) for t in BAG_TOPICS) for r in recorders):
            return
        time.sleep(0.1)
    raise SessionError("rosbag record did not connect to %s within %.0f s; see %s"
                       % (", ".join(BAG_TOPICS), timeout, session.child("rosbag").log_path))


def analyse(args, data, paths):
    """The offline part: clearance, picture, summary."""
    import numpy as np
    from .analysis import picture, replays
    from .analysis.scene import SCAN_HEIGHT, Scene   # (pybullet: not for --help)
    from pybullet_gazebo.engine.transforms import Pose

    recorder, start = data["recorder"], data["start"]
    # the run's first --duration seconds: the recorder pauses physics on wall time, a few
    # steps past that, as many as the machine's speed lets through; cut there, the figures
    # of two lockstep runs are the same
    end = min(data["end"], start + args.duration)
    scene = Scene.of_world(args.world, data["urdf"])
    try:
        scene.set_model_poses({n: p for n, p in data["poses"].items() if n != scene.robot_name})
        track = np.array([p for p in recorder.poses if start - 1e-9 <= p[0] <= end + 1e-9]) \
            .reshape(-1, 8)
        robot_poses = [Pose(tuple(row[1:4]), tuple(row[4:8])) for row in track]
        yaws = np.array([pose.rpy[2] for pose in robot_poses])
        nearest = min(scene.clearance(robot_poses, max_distance=CLEARANCE_RANGE),
                      key=lambda c: c.distance) \
            if robot_poses else None
        collisions = summary.collision_onsets(recorder.contacts)

        def xy_at(t):
            k = int(np.argmin(np.abs(track[:, 0] - t)))
            return track[k, 1], track[k, 2], k
        beams = None
        scan = recorder.last_scan
        if scan is not None and len(track):
            _, _, k = xy_at(scan.header.stamp.to_sec())
            sensor = scene.frame_pose(robot_poses[k], scan.header.frame_id)
            beams = picture.beam_segments(sensor.position[:2], sensor.rpy[2], scan.angle_min,
                                          scan.angle_increment, scan.ranges)
        outlines = scene.outlines(SCAN_HEIGHT)
        replay = replays.write(os.path.dirname(paths["replay"]),
                               os.path.basename(paths["replay"])[:-len(".html")], scene,
                               data["urdf"], track, "%s: m2wr, obstacle_avoidance.py" % (
                                   world_label(args.world)))
    finally:
        scene.close()
    title = "%s: m2wr from (%.2f, %.2f) m, yaw %.0f deg; obstacle_avoidance.py for %.0f s sim" % (
        world_label(args.world), args.x, args.y, math.degrees(args.yaw), end - start)
    picture.draw(paths["picture"], outlines, track[:, 0] - start, track[:, 1], track[:, 2], yaws,
                 beams=beams, collisions=[xy_at(c.sim_time)[:2] for c in collisions] if len(track) else [],
                 title=title)
    result = summary.RunSummary(
        world=world_label(args.world), start=(args.x, args.y, args.yaw), sim_time=end - start,
        wall_time=data["wall"], distance=metrics.distance_travelled(track[:, 1:3]),
        collisions=collisions,
        cases=summary.case_durations(recorder.cases, start, end), picture=paths["picture"],
        bag=paths["bag"] if args.bag else "", replay=replay)
    end_pose = data["poses"].get(scene.robot_name)
    if len(track):                  # where the reported run ends (its last recorded pose)
        result.end = (float(track[-1, 1]), float(track[-1, 2]), float(yaws[-1]))
    elif end_pose is not None:
        result.end = (float(end_pose.position[0]), float(end_pose.position[1]),
                      float(end_pose.rpy[2]))
    if nearest is not None and math.isfinite(nearest.distance):
        result.min_clearance = nearest.distance
        result.min_clearance_model = nearest.model
        result.min_clearance_time = float(track[nearest.index, 0] - start)
    return result


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out = os.path.abspath(args.output)
    label = world_label(args.world)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as err:
        sys.stderr.write("demo: cannot create the output folder %s: %s\n" % (out, err.strerror))
        return 1
    paths = {"picture": os.path.join(out, "demo_%s.png" % label),
             "summary": os.path.join(out, "demo_%s.json" % label),
             "bag": os.path.join(out, "demo_%s.bag" % label),
             "replay": os.path.join(out, "demo_%s_replay.html" % label)}
    session = Session(os.path.join(out, "logs", "demo"), name="m2wr_demo")

    raise_on_signals()

    ran = []

    def demo_run():
        ran.append(run(args, session, paths))
    try:            # catch_all: a ROS call failed: say which, then clean up
        status = exit_status("demo", demo_run, interrupted="stopping everything",
                             known=(SessionError,), catch_all=True)
    finally:
        say("stopping everything it started")
        session.shut_down("demo")
        left = processes.leftovers(session.master_uri) if session.master_uri else []
        if left:
            sys.stderr.write("demo: processes still running after the clean-up:\n%s\n"
                             % processes.describe(left))
            status = status or 1
        else:
            say("all stopped (%s); no process left" % ", ".join(
                "%s %s" % kv for kv in session.stop_report.items()))
    if status != 0:
        return status
    try:
        result = analyse(args, ran[0], paths)
    except Exception as err:
        sys.stderr.write("demo: the analysis of the run failed: %s: %s\n" % (type(err).__name__, err))
        return 1
    with open(paths["summary"], "w") as dump:
        json.dump(result.as_dict(), dump, indent=2)
    print(result.text(), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
