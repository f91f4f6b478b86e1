"""Evaluates a controller over many runs, in parallel on Dask:

  scripts/evaluate.sh [--controller "rosrun motion_plan obstacle_avoidance.py" | PATH]
                      [--task wander|goal|wall] [--goal X Y] [--world world02 ...]
                      [--start X Y YAW ... | --grid STEP | --random N [--pose-seed S]]
                      [--seeds 0 ...] [--duration 60] [--workers N | --scheduler tcp://H:P]
                      [--output output/evaluate] [--no-reuse] [--bag] [--pictures] [--fresh]
  scripts/evaluate.sh --bench [--bench-runs 20] [--duration 60]
  scripts/evaluate.sh --bench-memory [--bench-runs 200] [--duration 5]

Runs every combination of world x start x seed (lockstep, headless, as fast as the machine
allows; see m2wr_tools.batch.rig for what one run does), then writes <output>/results.json and
results.csv (one record a run: scenario, success and why, time to goal, distance, minimum
clearance, contact events and time in contact, time stuck, path, final pose, wall time,
real-time factor, the controller's exit status and log), prints the summary table, and draws
<output>/trajectories_<world>.png and starts_<world>.png. Runs already in results.json are
skipped (resume); --fresh starts over.

Start poses: --start (repeatable), a --grid over free space, or --random N free poses drawn
with --pose-seed; free = the robot's centre at least --margin m from every obstacle (the
world file's geometry at scan height). Default: the tutorial's (0, 8, 0).

--bench: the same --bench-runs runs (random free starts in world02, the tutorial's
obstacle_avoidance.py, --duration s each) with 1 and 2 workers, each with and without
simulator reuse; prints runs/min (the whole batch's, and once the workers are up), the
speed-up, the per-run overhead with reuse (median share of a run's wall time, and its
stages), the median CPU a run of each process (simulator, controller, worker, master,
roslaunch, the driver's scheduler) and the cores used while stepping, and the memory of
the workers and simulators over the runs (figures printed, not asserted).

--bench-memory: --bench-runs runs (default 200) of --duration s (default 5) on one worker
with reuse; prints the resident memory of the worker, its simulator and its controller
zygote at runs 1, 50, 100, 150, 200 and the slope [MiB per 100 runs] after run 20.

Python controllers are forked from a warm process (m2wr_tools.running.zygote: rospy already
imported; the script itself still starts afresh each run), and so are `roslaunch PKG FILE`
controllers, whose Python nodes are forked in turn (m2wr_tools.running.warm_launch);
--cold-start starts them as plain processes.

Exit status: 0 when the batch finished (failed runs included); 1 when it could not run;
2 for bad arguments; 130 when interrupted.
"""
import json
import math
import os
import shlex
import statistics
import sys
import time

from . import results
from ..analysis.metrics import TASKS, Task
from ..names import DEFAULT_START, DEFAULT_WORLD, TUTORIAL_CONTROLLER
from ..paths import ROOT
from .rig import RunOptions
from .scenarios import FREE_MARGIN, check_starts, combinations, grid_starts, random_starts
from ..tool_exit import BadInput, exit_status
from .. import usage


def parse_args(argv):
    parser = usage.parser("scripts/evaluate.sh", __doc__, examples=[
        "scripts/evaluate.sh --random 40 --duration 60    # obstacle_avoidance.py, 40 free starts",
        "scripts/evaluate.sh --controller my_controller.py --grid 2 --seeds 0 1 --world world01",
        "scripts/evaluate.sh --controller ~/go_to_point.py --task goal --goal 2 -3"])
    parser.add_argument("--controller", default=" ".join(TUTORIAL_CONTROLLER),
                        help="the controller: a command line (rosrun/roslaunch ...) or a path "
                        "to a script")
    parser.add_argument("--task", choices=TASKS, default="wander",
                        help="wander: no contact and --min-distance travelled over the "
                        "duration; goal: reach --goal within --tolerance; wall: follow a wall")
    parser.add_argument("--goal", type=float, nargs=2, metavar=("X", "Y"),
                        help="goal [m] of the goal task (set as the des_pos_x/des_pos_y params)")
    parser.add_argument("--tolerance", type=float, default=0.3, help="goal radius [m]")
    parser.add_argument("--min-distance", type=float, default=1.0,
                        help="wander/wall: least distance [m] a successful run travels")
    parser.add_argument("--world", action="append", help="world01, world02 or a .world path "
                        "(repeatable) (default: world02)")
    parser.add_argument("--start", type=float, nargs=3, action="append",
                        metavar=("X", "Y", "YAW"), help="a start pose [m m rad] (repeatable) "
                        "(default: the tutorial's 0 8 0)")
    parser.add_argument("--grid", type=float, metavar="STEP",
                        help="starts on a grid of STEP m over free space (heading 0)")
    parser.add_argument("--random", type=int, metavar="N", help="N random free start poses")
    parser.add_argument("--pose-seed", type=int, default=0,
                        help="seed of the --random poses")
    parser.add_argument("--margin", type=float, default=FREE_MARGIN,
                        help="free space: least distance [m] of a start from any obstacle")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0],
                        help="simulator seeds (laser noise), one run each (default: 0)")
    parser.add_argument("--duration", type=float, default=None,
                        help="sim time of a run [s] (default: 60; 5 with --bench-memory)")
    parser.add_argument("--workers", type=int, help="LocalCluster workers (default: one per core)")
    parser.add_argument("--scheduler", help="address of an existing Dask scheduler, e.g. "
                        "tcp://127.0.0.1:8786 (its workers need this project set up, "
                        "scripts/env.sh sourced and --nthreads 1) (default: a LocalCluster on "
                        "this machine)")
    parser.add_argument("--output", default=os.path.join(ROOT, "output", "evaluate"),
                        help="folder of results, pictures and logs (default: output/evaluate)")
    parser.add_argument("--no-reuse", action="store_true",
                        help="relaunch the simulator for every run")
    parser.add_argument("--bag", action="store_true", help="a rosbag per run in <output>/runs/")
    parser.add_argument("--pictures", action="store_true",
                        help="the demo's picture per run in <output>/runs/")
    parser.add_argument("--replays", action="store_true",
                        help="a replay per run in the browser view, <output>/runs/<run>.html "
                        "(opens from disk: the robot, its path and laser over a time slider)")
    parser.add_argument("--fresh", action="store_true",
                        help="ignore the runs already in <output>/results.json")
    parser.add_argument("--connect-timeout", type=float, default=20.0,
                        help="wall seconds for the controller to publish cmd_vel")
    parser.add_argument("--run-timeout", type=float, default=0.0,
                        help="wall seconds a run may take (default: 60 + 2 x duration)")
    parser.add_argument("--lockstep-timeout", type=float, default=30.0,
                        help="wall seconds the simulator waits for a controller that is still "
                        "at work before it steps on without it (the world launch's "
                        "lockstep_timeout; default: 30, so that a loaded machine does not "
                        "make a controller's answer late; the run summary counts each)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--bench", action="store_true", help="the batch benchmark (see above)")
    parser.add_argument("--bench-memory", action="store_true",
                        help="the memory benchmark (see above)")
    parser.add_argument("--bench-runs", type=int, default=None,
                        help="runs of the benchmark (default: 20; 200 with --bench-memory)")
    parser.add_argument("--cold-start", action="store_true",
                        help="start Python controllers and roslaunch as plain processes, "
                        "not from the warm zygote")
    args = parser.parse_args(argv)
    if args.duration is None:
        args.duration = 5.0 if args.bench_memory else 60.0
    if args.bench_runs is None:
        args.bench_runs = 200 if args.bench_memory else 20
    if args.bench_runs < 1:
        parser.error("--bench-runs must be >= 1")
    if not (math.isfinite(args.duration) and args.duration > 0):
        parser.error("--duration must be > 0 seconds of sim time")
    if args.workers is not None and args.workers < 1:
        parser.error("--workers must be >= 1")
    if sum(x is not None for x in (args.start, args.grid, args.random)) > 1:
        parser.error("pass one of --start, --grid, --random")
    if args.random is not None and args.random < 1:
        parser.error("--random must be >= 1")
    if args.task == "goal" and args.goal is None:
        parser.error("--task goal needs --goal X Y")
    if args.scheduler and not args.scheduler.startswith(("tcp://", "tls://", "inproc://")):
        parser.error("--scheduler must be an address like tcp://127.0.0.1:8786")
    args.world = args.world or [DEFAULT_WORLD]
    return args


def controller_argv(text):
    """The controller's command line: a script path runs with this venv's python (if .py)
    or as it is; anything else is split like a shell would."""
    path = os.path.abspath(os.path.expanduser(text))
    if os.path.isfile(path):
        return (sys.executable, path) if path.endswith(".py") else (path,)
    argv = tuple(shlex.split(text))
    if not argv:
        raise ValueError("--controller is empty; pass a command line or a script path")
    if len(argv) == 1 and (os.sep in text or text.endswith(".py")):
        raise ValueError("--controller %s: no such file; pass the path of an existing "
                         "script, or a command line such as 'rosrun motion_plan "
                         "obstacle_avoidance.py'" % text)
    return argv


def check_worlds(worlds):
    """ValueError naming the first world that has no world file, with the known ones."""
    from pybullet_gazebo.engine.sdf_world import WorldFileError
    from ..paths import world_path
    for world in worlds:
        try:
            world_path(world)
        except WorldFileError as err:
            raise ValueError("--world %s: %s" % (world, str(err).replace("world:=NAME",
                                                                          "--world NAME")))


def build_scenarios(args, outlines_of):
    """The batch's scenarios; ValueError naming a bad world, controller or start."""
    from ..running.commands import check
    check_worlds(args.world)
    controller = controller_argv(args.controller)
    check(controller, os.environ)
    task = Task(kind=args.task, goal=tuple(args.goal) if args.goal else None,
                tolerance=args.tolerance, min_distance=args.min_distance)

    def starts_of(world):
        outlines = outlines_of(world)
        if args.grid is not None:
            return grid_starts(outlines, args.grid, margin=args.margin)
        if args.random is not None:
            return random_starts(outlines, args.random, args.pose_seed, margin=args.margin)
        starts = [tuple(s) for s in args.start] if args.start else [DEFAULT_START]
        check_starts(outlines, starts, margin=args.margin)
        return starts
    return combinations(args.world, starts_of, args.seeds, args.duration, controller, task)


class _Outlines:
    """The worlds' obstacle outlines at scan height, loaded once each (DIRECT client)."""

    def __init__(self):
        self.cache = {}

    def __call__(self, world):
        if world not in self.cache:
            from ..analysis.scene import SCAN_HEIGHT, Scene
            scene = Scene.of_world(world)
            try:
                self.cache[world] = scene.outlines(SCAN_HEIGHT)
            finally:
                scene.close()
        return self.cache[world]


def say(text):
    print("[evaluate] %s" % text, flush=True)


def report(args, records, outlines_of, scenarios):
    label = os.path.basename(scenarios[0].controller[-1]) if scenarios else ""
    print(results.summary_table(records, title="%s, task %s, %g s sim each" % (
        label, args.task, args.duration)), flush=True)
    from ..analysis import batch_picture
    pictures = []
    for world in args.world:
        label_world = scenarios[0].world_label if len(args.world) == 1 else \
            os.path.basename(world).replace(".world", "")
        runs = [r for r in records if r["scenario"]["world"] == world]
        if not runs:
            continue
        title = "%s in %s: %d runs, %d succeeded (%s task, %g s)" % (
            label, label_world, len(runs), sum(1 for r in runs if r.get("success")),
            args.task, args.duration)
        pictures.append(batch_picture.trajectories(
            os.path.join(args.output, "trajectories_%s.png" % label_world),
            outlines_of(world), runs, title))
        pictures.append(batch_picture.starts(
            os.path.join(args.output, "starts_%s.png" % label_world), outlines_of(world),
            runs, title))
    for path in pictures:
        say("picture %s" % path)
    replays = [r for r in records if r.get("replay") and os.path.isfile(r["replay"])]
    if replays:
        from pybullet_gazebo.web import site
        for r in replays:
            site.write_replay_file(os.path.join(args.output, "runs"), r["run_id"], r["replay"])
        say("replays: %d pages %s" % (len(replays), os.path.join(args.output, "runs", "*.html")))
    say("results %s and results.csv" % os.path.join(args.output, "results.json"))


def bench(args):
    """Runs/min for 1 and 2 workers with and without reuse on the same runs."""
    from .cluster import run_batch
    outlines_of = _Outlines()
    args.world, args.random, args.start, args.grid = [DEFAULT_WORLD], args.bench_runs, None, None
    scenarios = build_scenarios(args, outlines_of)
    figures = {}
    for workers, reuse in ((1, True), (2, True), (1, False), (2, False)):
        name = "%d worker%s, %s" % (workers, "s" if workers > 1 else "",
                                    "reuse" if reuse else "relaunch")
        out = os.path.join(args.output, "bench", "w%d_%s" % (workers, "reuse" if reuse else "relaunch"))
        say("bench: %s, %d runs of %g s" % (name, len(scenarios), args.duration))
        t, driver = time.monotonic(), os.times()
        records = run_batch(scenarios, RunOptions(output=out, reuse=reuse,
                                                  warm_start=not args.cold_start),
                            workers=workers, resume=False, progress=not args.no_progress,
                            say=say)
        wall = time.monotonic() - t
        driver = (os.times().user + os.times().system - driver.user - driver.system)
        overheads = [r["overhead_s"] / r["wall_time_s"] for r in records
                     if r.get("overhead_s") is not None and r.get("reused")]
        figures[name] = {"runs": len(records), "wall_s": wall,
                         "runs_per_min": 60.0 * len(records) / wall,
                         "failed": sum(1 for r in records if not r.get("success")),
                         "overhead_share_median": statistics.median(overheads) if overheads else None,
                         "overhead_s_median": statistics.median(
                             [r["overhead_s"] for r in records if r.get("overhead_s") is not None
                              and r.get("reused")] or [math.nan]),
                         "stages_median": _stage_medians(records),
                         "cpu_median": _cpu_medians(records),
                         "steady_runs_per_min": _steady_rate(records),
                         "driver_cpu_s_per_run": driver / max(1, len(records)),
                         "memory": _memory(records)}
        say("  %.2f runs/min" % figures[name]["runs_per_min"])
    print("\nbatch benchmark: %d runs of %g s sim (world02, obstacle_avoidance.py, lockstep, "
          "%s start), %d cores, load average %s" % (
              len(scenarios), args.duration, "cold" if args.cold_start else "warm",
              os.cpu_count(), " ".join("%.2f" % x for x in os.getloadavg())))
    for name, f in figures.items():
        overhead = "" if f["overhead_share_median"] is None else \
            "  overhead with reuse %.2f s = %.0f %% of a run (median)" % (
                f["overhead_s_median"], 100 * f["overhead_share_median"])
        print("  %-22s %6.2f runs/min  (%.0f s wall, %d failed)%s" % (
            name, f["runs_per_min"], f["wall_s"], f["failed"], overhead))
    for name, f in figures.items():
        if f["stages_median"] and "reuse" in name:
            print("  stages %-22s %s (median s; overhead = all but sim)" % (name, "  ".join(
                "%s %.3f" % (k[:-2], v) for k, v in f["stages_median"].items())))
    for name, f in figures.items():
        if f["cpu_median"] and "reuse" in name:
            cpu = f["cpu_median"]
            print("  cpu %-25s %s  driver (scheduler, client) %.2f  = %.2f s a run (median "
                  "CPU s; the controller with its exit)" % (name, "  ".join(
                      "%s %.2f" % (k, v) for k, v in cpu["per_run"].items()),
                      f["driver_cpu_s_per_run"],
                      sum(cpu["per_run"].values()) + f["driver_cpu_s_per_run"]))
            print("  cpu %-25s while stepping: %s = %.2f cores over sim's wall time" % (
                "", "  ".join("%s %.2f" % (k, v) for k, v in cpu["stepping"].items()),
                cpu["stepping_cores"]))
    for mode in ("reuse", "relaunch"):
        one, two = figures["1 worker, %s" % mode], figures["2 workers, %s" % mode]
        steady = "" if not (one["steady_runs_per_min"] and two["steady_runs_per_min"]) else \
            "   (after each worker's first run: %.1f and %.1f runs/min, %.2fx)" % (
                one["steady_runs_per_min"], two["steady_runs_per_min"],
                two["steady_runs_per_min"] / one["steady_runs_per_min"])
        print("  speed-up 2 vs 1 worker, %-8s %.2fx%s" % (
            mode, two["runs_per_min"] / one["runs_per_min"], steady))
    for name, f in figures.items():
        for worker, m in f["memory"].items():
            print("  memory %-22s %s: worker %s MiB, simulator %s MiB (first -> last of %d runs)"
                  % (name, worker, m["worker"], m["simulator"], m["runs"]))
    path = os.path.join(args.output, "bench", "bench.json")
    with open(path, "w") as out:
        json.dump(figures, out, indent=1)
    say("figures written to %s" % path)
    return 0


def _stage_medians(records):
    """{stage: median [s]} over the runs that reused their simulator."""
    stages = [r["stages"] for r in records if r.get("reused") and r.get("stages")]
    names = [n for n in ("reset_s", "controller_start_s", "sim_s", "measure_s", "stop_s")
             if any(n in s for s in stages)]
    return {n: statistics.median([s[n] for s in stages if n in s]) for n in names}


def _steady_rate(records):
    """Runs per wall minute once the workers are up: each worker's runs after its first
    (which carries the start of its master, simulator and zygote) over the wall time from
    its first run's end to its last's, summed over the workers; None with too few runs."""
    ends = {}
    for r in records:
        if r.get("finished_at"):
            ends.setdefault(r.get("worker"), []).append(r["finished_at"])
    rates = [(len(t) - 1) / (max(t) - min(t)) for t in ends.values()
             if len(t) > 1 and max(t) > min(t)]
    return 60.0 * sum(rates) if rates else None


def _cpu_medians(records):
    """Median CPU [s] a run of each process (rig's cpu_s; the controller is the zygote's
    figure, its children's exits included), the CPU while physics stepped (stage sim_s),
    and the cores that used over sim_s's wall time, over the runs with reuse."""
    runs = [r for r in records if r.get("reused") and r.get("cpu_s") and r.get("stages")]
    if not runs:
        return {}

    def per_run(r):
        total = dict(r["cpu_s"]["total"])
        zygote, live = total.pop("zygote", None), total.pop("controller", 0.0)
        total["controller"] = zygote if zygote is not None else live
        return total
    names = ("simulator", "controller", "worker", "master", "roslaunch")
    stepping = [r["cpu_s"]["stages"].get("sim_s", {}) for r in runs]
    return {
        "per_run": {n: statistics.median([per_run(r).get(n, 0.0) for r in runs]) for n in names},
        "stepping": {n: statistics.median([s.get(n, 0.0) for s in stepping])
                     for n in ("simulator", "controller", "worker", "master")},
        "stepping_cores": statistics.median([sum(s.values()) / r["stages"]["sim_s"]
                                             for s, r in zip(stepping, runs)
                                             if r["stages"].get("sim_s")]),
    }


def bench_memory(args):
    """Resident memory of one worker, its simulator and zygote over many short runs."""
    from .cluster import run_batch
    outlines_of = _Outlines()
    args.world, args.random, args.start, args.grid = [DEFAULT_WORLD], args.bench_runs, None, None
    scenarios = build_scenarios(args, outlines_of)
    out = os.path.join(args.output, "bench_memory")
    say("memory bench: %d runs of %g s on 1 worker with reuse" % (len(scenarios), args.duration))
    t = time.monotonic()
    records = run_batch(scenarios, RunOptions(output=out, reuse=True,
                                              warm_start=not args.cold_start),
                        workers=1, resume=False, progress=not args.no_progress, say=say)
    wall = time.monotonic() - t
    runs = sorted(records, key=lambda r: r.get("finished_at", 0))
    table = memory_table(runs)
    print("\nmemory benchmark: %d runs of %g s sim on 1 worker with reuse (%s start), "
          "%.0f s wall, %d failed, load average %s" % (
              len(runs), args.duration, "cold" if args.cold_start else "warm", wall,
              sum(1 for r in runs if not r.get("success")),
              " ".join("%.2f" % x for x in os.getloadavg())))
    print(table["text"])
    path = os.path.join(out, "memory.json")
    with open(path, "w") as dump:
        json.dump({k: v for k, v in table.items() if k != "text"}, dump, indent=1)
    say("figures written to %s" % path)
    return 0


MEMORY_KEYS = (("worker", "worker_rss_mib"), ("simulator", "simulator_rss_mib"),
               ("zygote", "zygote_rss_mib"))


def memory_table(runs, marks=(1, 50, 100, 150, 200), warm_up=20):
    """The RSS [MiB] of each process at the run numbers `marks` (1-based, in finishing
    order) and its least-squares slope [MiB per 100 runs] over the runs after `warm_up`."""
    import numpy as np
    marks = [m for m in marks if m <= len(runs)] or [len(runs)]
    if marks[-1] != len(runs):
        marks.append(len(runs))
    lines = ["  %-10s %s   slope after run %d" % ("RSS MiB", "".join(
        "%9s" % ("run %d" % m) for m in marks), warm_up)]
    data = {"marks": marks, "slopes_mib_per_100_runs": {}, "rss_mib": {}}
    for label, key in MEMORY_KEYS:
        values = [r.get(key) for r in runs]
        if not any(values):
            continue
        at = ["%9s" % ("%.1f" % values[m - 1] if values[m - 1] else "n/a") for m in marks]
        points = [(i, v) for i, v in enumerate(values) if v and i >= warm_up]
        slope = None
        if len(points) >= 2:
            x, y = np.array(points, dtype=float).T
            slope = float(np.polyfit(x, y, 1)[0]) * 100.0
        data["slopes_mib_per_100_runs"][label] = slope
        data["rss_mib"][label] = values
        lines.append("  %-10s %s   %s" % (label, "".join(at), "n/a" if slope is None
                                           else "%+.2f MiB per 100 runs" % slope))
    data["text"] = "\n".join(lines)
    return data


def _memory(records):
    by_worker = {}
    for r in sorted(records, key=lambda r: r.get("finished_at", 0)):
        by_worker.setdefault(r.get("worker", "?"), []).append(r)
    out = {}
    for worker, runs in by_worker.items():
        def span(key):
            values = [r.get(key) for r in runs if r.get(key)]
            return "%.0f -> %.0f" % (values[0], values[-1]) if values else "n/a"
        out[worker] = {"worker": span("worker_rss_mib"), "simulator": span("simulator_rss_mib"),
                       "runs": len(runs)}
    return out


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    args.output = os.path.abspath(args.output)
    return exit_status("evaluate", lambda: evaluate(args), interrupted=(
        "every process of the batch stopped; the runs done are in %s (run the same command "
        "again to resume)" % os.path.join(args.output, "results.json")))


def evaluate(args):
    from .cluster import run_batch
    os.makedirs(args.output, exist_ok=True)
    if args.bench:
        return bench(args)
    if args.bench_memory:
        return bench_memory(args)
    outlines_of = _Outlines()
    try:
        scenarios = build_scenarios(args, outlines_of)
    except ValueError as err:
        raise BadInput(err) from None
    say("%d runs: %d world(s) x %d start(s) x %d seed(s), %g s of sim time each" % (
        len(scenarios), len(args.world), len(scenarios) // max(1, len(args.world) * len(args.seeds)),
        len(args.seeds), args.duration))
    options = RunOptions(output=args.output, reuse=not args.no_reuse, bag=args.bag,
                         picture=args.pictures, replay=args.replays,
                         connect_timeout=args.connect_timeout,
                         lockstep_timeout=args.lockstep_timeout,
                         run_timeout=args.run_timeout, warm_start=not args.cold_start)
    records = run_batch(scenarios, options, scheduler=args.scheduler, workers=args.workers,
                        resume=not args.fresh, progress=not args.no_progress, say=say)
    report(args, records, outlines_of, scenarios)
    return 0


if __name__ == "__main__":
    sys.exit(main())
