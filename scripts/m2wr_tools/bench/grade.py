"""The grader's benchmark: a class of N students graded with the default spec (episodes 5-10),
its wall time and runs per minute, and the grader's own overhead per run beside the batch
runner's on the same controller.

The class is made here: each student a copy of the series' final `motion_plan` as a learner
on Noetic hands it in (the grader's fixture scripts/test/fixtures/series_class/noa: the
behaviours start switched off, go to point spins while off, bug 0-2 switch them and place
m2wr, the turning signs flipped for the default spec's convention; the tutorial's
obstacle_avoidance.py beside them), so every task of the default spec is handed in and its
runs end where the series' do (bug 0-2 at their goals). Per task it prints the runs, the sim
seconds a wall second of one worker while the world stepped (the sim stage) and over whole
runs (start, stop, measure and replay included).

Overhead [s wall] is a run's wall time less the part in which the world ran (the record's
overhead_s, see m2wr_tools.batch.rig: resetting the world, starting and stopping the controller,
measuring) plus, for the grader, what it adds around the run (grader_s: the student's files
copied in and out, the rules' last look, the end by PID). Medians: a worker's first run also
starts its simulator. The comparison is like for like: the class graded again on the spec's
obstacle-avoider task alone (ep5, 60 s in world02, one seed), so that both workers run the
same light controller as the batch runner's do, then the batch runner on the same program
through scripts/evaluate.sh, from as many random free starts as the class had students, each
run's replay made by both (the grader's report shows it; its cost is the stage replay_s); the
two in turn for --rounds rounds (the machine's speed drifts by more than the grader costs
between minutes), each round's ratio printed and the ratio of all rounds' medians the
figure. (In the whole class the other worker runs go to point, the wall follower and bug 2
beside an ep5 run, which slowed its start by 10-30 ms and moved the ratio between 0.91 and
1.28.)

    scripts/bench.sh --grade [--students 30] [--workers 2] [--rounds 2] [--output output/]

Prints the figures and writes <output>/bench_grade.json.
"""
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

from ..paths import ROOT
from .. import usage

SERIES_PACKAGE = os.path.join(ROOT, "scripts", "test", "fixtures", "series_class", "noa",
                              "motion_plan")
TUTORIAL = os.path.join(ROOT, "catkin_ws", "src", "motion_plan", "scripts",
                        "obstacle_avoidance.py")
PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>motion_plan</name>
  <version>0.0.0</version>
  <description>{student}'s programs for the series' episodes 5-10</description>
  <maintainer email="{student}@example.com">{student}</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <exec_depend>rospy</exec_depend>
  <exec_depend>std_srvs</exec_depend>
  <exec_depend>gazebo_msgs</exec_depend>
  <exec_depend>tf</exec_depend>
</package>
"""
COMPARED_TASK = "ep5_avoid"      # the default spec's obstacle avoider ...
DURATION = 60.0                  # [s sim] ... and its duration


def write_one_task_spec(path, task):
    """The default spec with only `task` in it, written to `path`."""
    import yaml
    from ..grade.spec import DEFAULT_SPEC
    with open(DEFAULT_SPEC) as source:
        spec = yaml.safe_load(source)
    spec["tasks"] = [t for t in spec["tasks"] if t["name"] == task]
    with open(path, "w") as out:
        yaml.safe_dump(spec, out, sort_keys=False)


def make_class(folder, students):
    """`students` packages under `folder` (made afresh), named student01..."""
    shutil.rmtree(folder, ignore_errors=True)
    names = ["student%02d" % (i + 1) for i in range(students)]
    for name in names:
        package = os.path.join(folder, name, "motion_plan")
        shutil.copytree(SERIES_PACKAGE, package)          # the fixture's links followed
        with open(os.path.join(package, "package.xml"), "w") as out:
            out.write(PACKAGE_XML.format(student=name))
    os.chmod(folder, 0o700)
    return names


def per_task(records):
    """{task: figures} of the runs that ran the world: how many and how many passed, sim
    seconds, and sim seconds a wall second of one worker while the world stepped and over
    whole runs."""
    tasks = {}
    for r in records:
        if r.get("stages") and r.get("sim_time_s"):
            tasks.setdefault(r["task"], []).append(r)
    figures = {}
    for task, runs in sorted(tasks.items()):
        sim = sum(r["sim_time_s"] for r in runs)
        stepping = sum(r["stages"]["sim_s"] for r in runs)
        wall = sum(r["wall_time_s"] for r in runs)
        figures[task] = {"runs": len(runs), "passed": sum(1 for r in runs if r.get("success")),
                         "sim_s": round(sim, 1),
                         "x_real_time_stepping": round(sim / stepping, 1) if stepping else None,
                         "x_real_time_whole_runs": round(sim / wall, 1) if wall else None}
    return figures


def _run(argv, what):
    started = time.monotonic()
    print("[bench_grade] %s: %s" % (what, " ".join(argv)), flush=True)
    done = subprocess.run(argv, cwd=ROOT)
    if done.returncode != 0:
        raise SystemExit("[bench_grade] %s failed (exit %d)" % (what, done.returncode))
    return time.monotonic() - started


def _records(results_path):
    with open(results_path) as source:
        data = json.load(source)
    return [r for student in data["students"].values() for r in student["runs"]]


def _median(values):
    values = [v for v in values if v is not None]
    return round(statistics.median(values), 3) if values else None


def _overheads(records, task=None):
    """Each run's overhead [s wall]: the rig's (overhead_s) and, for a graded run, what the
    grader adds around it (grader_s)."""
    return [r["overhead_s"] + (r.get("grader_s") or 0.0) for r in records
            if (task is None or r.get("task") == task) and r.get("overhead_s") is not None]


def _stage_medians(records):
    names = sorted({k for r in records for k in (r.get("stages") or {})})
    return {k: _median([(r.get("stages") or {}).get(k) for r in records]) for k in names}


def bench(args):
    output = os.path.abspath(args.output)
    os.makedirs(output, exist_ok=True)
    class_dir = os.path.join(output, "bench_grade_class")
    names = make_class(class_dir, args.students)
    grade_out = os.path.join(output, "bench_grade")
    workers = ["--workers", str(args.workers)] if args.workers else []
    wall = _run([sys.executable, "-m", "m2wr_tools.grade.cli", class_dir, "--output", grade_out,
                 "--fresh"] + workers, "grading %d students" % len(names))
    records = _records(os.path.join(grade_out, "results.json"))
    graded = [r for r in records if r.get("overhead_s") is not None]
    # like for like: the class on the obstacle avoider alone, then the batch runner on it,
    # in turn for `rounds` rounds (the machine's speed drifts between minutes)
    alone_spec = os.path.join(output, "bench_grade_%s.yaml" % COMPARED_TASK)
    write_one_task_spec(alone_spec, COMPARED_TASK)
    ep5, batch, rounds = [], [], []
    for index in range(args.rounds):
        suffix = "_%d" % (index + 1)
        alone_out = os.path.join(output, "bench_grade_%s%s" % (COMPARED_TASK, suffix))
        _run([sys.executable, "-m", "m2wr_tools.grade.cli", class_dir, "--spec", alone_spec,
              "--output", alone_out, "--fresh", "--no-progress"] + workers,
             "round %d of %d: grading the class on %s alone"
             % (index + 1, args.rounds, COMPARED_TASK))
        graded_alone = [r for r in _records(os.path.join(alone_out, "results.json"))
                        if r.get("overhead_s") is not None]
        # one seed (a new seed relaunches the simulator, as the class's runs never do),
        # starts drawn at random in the free space: as many runs as the class had students
        evaluate_out = os.path.join(output, "bench_grade_evaluate%s" % suffix)
        _run([sys.executable, "-m", "m2wr_tools.batch.evaluate", "--controller", TUTORIAL,
              "--task", "wander", "--world", "world02", "--duration", str(DURATION),
              "--seeds", "0", "--random", str(max(2, len(names))), "--pose-seed", str(index),
              "--replays", "--output", evaluate_out, "--fresh", "--no-progress"] + workers,
             "round %d of %d: the batch runner on the same controller"
             % (index + 1, args.rounds))
        with open(os.path.join(evaluate_out, "results.json")) as source:
            batched = [r for r in json.load(source)["runs"] if r.get("overhead_s") is not None]
        pair = (_median(_overheads(graded_alone)), _median(_overheads(batched)))
        rounds.append({"grader_overhead_s_median": pair[0], "batch_overhead_s_median": pair[1],
                       "ratio": round(pair[0] / pair[1], 2) if all(pair) else None})
        print("[bench_grade] round %d: overhead a run [s wall, median] grader %s, batch runner "
              "%s: %s" % (index + 1, pair[0], pair[1], rounds[-1]["ratio"]), flush=True)
        ep5 += graded_alone
        batch += batched
    figures = {
        "students": len(names), "runs": len(records), "graded_runs": len(graded),
        "workers": args.workers, "wall_s": round(wall, 1),
        "runs_per_minute": round(len(records) / wall * 60.0, 2),
        "grader_overhead_s_median": _median(_overheads(graded)),
        "grader_overhead_s_median_ep5": _median(_overheads(ep5)),
        "grader_s_median_ep5": _median([r.get("grader_s") for r in ep5]),
        "batch_overhead_s_median": _median(_overheads(batch)),
        "grader_stages_ep5": _stage_medians(ep5),
        "batch_stages": _stage_medians(batch),
        "date": time.strftime("%Y-%m-%d %H:%M"), "load": os.getloadavg()[0],
        "cores": os.cpu_count(), "rounds": rounds, "tasks": per_task(records),
    }
    ratio = None
    if figures["grader_overhead_s_median_ep5"] and figures["batch_overhead_s_median"]:
        ratio = figures["grader_overhead_s_median_ep5"] / figures["batch_overhead_s_median"]
    figures["overhead_ratio_ep5"] = round(ratio, 2) if ratio else None
    with open(os.path.join(output, "bench_grade.json"), "w") as out:
        json.dump(figures, out, indent=1)
    print("[bench_grade] %(students)d students, %(runs)d runs (%(graded_runs)d ran the world) "
          "in %(wall_s).0f s with %(workers)s workers: %(runs_per_minute).1f runs a minute"
          % dict(figures, workers=args.workers or os.cpu_count()))
    for task, f in figures["tasks"].items():
        print("[bench_grade]   %-16s %3d runs, %3d passed, %6.0f s of sim: x real time a worker "
              "%5.1f while stepping, %5.1f over whole runs"
              % (task, f["runs"], f["passed"], f["sim_s"], f["x_real_time_stepping"] or 0.0,
                 f["x_real_time_whole_runs"] or 0.0))
    print("[bench_grade] overhead a run [s wall, median of all rounds]: %s in the whole class; "
          "on the obstacle avoider alone grader %s (of which its own files, last look and end "
          "%s), batch runner %s: ratio %s (target <= 1.10)"
          % (figures["grader_overhead_s_median"], figures["grader_overhead_s_median_ep5"],
             figures["grader_s_median_ep5"], figures["batch_overhead_s_median"],
             figures["overhead_ratio_ep5"]))
    print("[bench_grade] stages [s, median]: grader ep5 %s; batch %s"
          % (figures["grader_stages_ep5"], figures["batch_stages"]))
    return figures


def main(argv=None):
    parser = usage.parser("scripts/bench.sh --grade", __doc__, examples=[
        "scripts/bench.sh --grade                 # 30 students, one worker per core",
        "scripts/bench.sh --grade --students 4 --rounds 1 --output /tmp/grade-bench"],
        exit_statuses="Exit status: 0 when the figures were measured; 1 when the grader or "
        "the batch runner failed\n(the step is named); 2 for bad arguments; 130 when "
        "interrupted.")
    parser.add_argument("--students", type=int, default=30,
                        help="students in the class made for the benchmark")
    parser.add_argument("--workers", type=int, default=None,
                        help="Dask workers of the grader and the batch runner "
                        "(default: one per core)")
    parser.add_argument("--rounds", type=int, default=2,
                        help="rounds of the like-for-like comparison, grader and batch runner "
                             "in turn; the ratio is of all rounds' runs")
    parser.add_argument("--output", default=os.path.join(ROOT, "output"),
                        help="folder for bench_grade.json, the class, its report and logs "
                        "(default: output/)")
    args = parser.parse_args(argv)
    try:
        bench(args)
    except KeyboardInterrupt:
        print("[bench_grade] interrupted", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
