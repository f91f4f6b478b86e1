"""The class's batch: every submission staged, every (student, task, run) checked and then
run on Dask by the batch runner with the grader's task (runner.grade_run), progress per
student, and the records gathered per student and task.

A run that cannot start is failed here with its reason and never sent to a worker: a
submission with nothing to grade, a task whose world does not exist, a command whose package
or script the student's folder lacks (m2wr_tools.running.commands, as rosrun/roslaunch would look in
it). Every other student is graded all the same.

Folders under the output: stage/<student>/ (the packages as graded; root-only when
isolating), batch/ (the batch runner's results.json for resume, logs, each run's log).
"""
import os
import stat
import sys

from ..batch.cluster import run_batch
from ..running.commands import check
from ..analysis.metrics import Task
from . import classroom, sandbox
from .runner import GradedScenario, GradeOptions, GradeRig, grade_run
from ..paths import ROOT


def _world_problem(world, cache={}):
    if world not in cache:
        from pybullet_gazebo.engine.sdf_world import WorldFileError
        from ..paths import world_path
        try:
            world_path(world)
            cache[world] = None
        except WorldFileError as err:
            cache[world] = "the task's world: %s" % str(err).replace(
                "pass world:=NAME with NAME one of", "set the task's `world:` to one of")
    return cache[world]


def _record(scenario, reason):
    """The record of a run failed before it started."""
    return {"run_id": scenario.run_id, "scenario": scenario.as_dict(),
            "world": scenario.world_label, "x": scenario.x, "y": scenario.y,
            "yaw": scenario.yaw, "seed": scenario.seed, "task": scenario.task_name,
            "student": scenario.student, "index": scenario.index, "success": False,
            "reason": reason, "findings": [], "path": []}


class GradeError(RuntimeError):
    """The class cannot be graded as set up (the message says what to change)."""


def _private(folder, isolating):
    os.makedirs(folder, exist_ok=True)
    if isolating:
        os.chmod(folder, 0o700)


def plan(spec, submissions, output):
    """(scenarios to run, records of runs failed before starting, shadowed package names)."""
    stage_root = os.path.join(output, "stage")
    _private(stage_root, sandbox.isolating())
    shadowed = {t.command[1] for t in spec.tasks if len(t.command) > 1}
    staged = {}
    for sub in submissions:
        if sub.problem is None:
            folder = os.path.join(stage_root, sub.student)
            shadowed.update(classroom.stage(sub, folder))
            staged[sub.student] = folder
    todo, failed = [], []
    for sub in submissions:
        for task in spec.tasks:
            problem = sub.problem or _world_problem(task.world)
            if problem is None:
                env = classroom.overlay_env(os.environ, staged[sub.student], shadowed)
                try:
                    check(task.command, env)
                except ValueError as err:     # named by the student's folder, not ours
                    problem = str(err).replace(staged[sub.student], sub.student)
            for index, start, seed in task.runs:
                scenario = GradedScenario(
                    world=task.world, x=start[0], y=start[1], yaw=start[2], seed=seed,
                    duration=task.duration, controller=task.command,
                    task=Task(kind=task.kind, goal=task.goal, tolerance=task.tolerance,
                              min_distance=task.min_distance),
                    student=sub.student, task_name=task.name, index=index,
                    packages=staged.get(sub.student, ""), allow=task.allow,
                    legacy_mode=task.legacy_mode, after_start=task.after_start)
                if problem is None:
                    todo.append(scenario)
                else:
                    failed.append(_record(scenario, problem))
    # The cluster hands runs out in this order. A worker keeps its simulator for the next run
    # of the same world, seed and turning convention (the rig's simulator_key) and relaunches
    # it when they change: student by student that would be at nearly every run, so the runs
    # go simulator by simulator, in the spec's order, each one's students by name.
    simulators = {}
    for scenario in todo:
        simulators.setdefault(GradeRig.simulator_key(scenario), len(simulators))
    todo.sort(key=lambda scenario: simulators[GradeRig.simulator_key(scenario)])
    return todo, failed, tuple(sorted(shadowed))


def grade_class(spec, submissions, args, say):
    """{student: {"submission": Submission, "records": [record...]}} of the whole class."""
    output = args.output
    _private(output, sandbox.isolating())
    if sandbox.isolating():
        closed = sandbox.closed_to_others(ROOT)
        if closed:
            raise GradeError(
                "the runs' users cannot reach the project at %s: %s is closed to other users "
                "(mode %s), so a run could not find m2wr_description or the project's Python; "
                "chmod o+x %s, or keep the project where others may pass (not in a private "
                "home folder)" % (ROOT, closed, oct(os.stat(closed).st_mode & 0o777), closed))
        mode = os.stat(args.class_dir).st_mode
        if mode & (stat.S_IROTH | stat.S_IXOTH):
            say("warning: %s is readable by other users: a submission could read the others "
                "through it; chmod o-rwx it (runs start as unprivileged users)" % args.class_dir)
    else:
        say("warning: not root, so runs start as your own user: limits, watchdog and stop by "
            "PID hold, but a submission can read what you can (see the README's isolation)")
    todo, failed, shadowed = plan(spec, submissions, output)
    say("%d students x %d tasks: %d runs to grade, %d failed before starting" % (
        len(submissions), len(spec.tasks), len(todo), len(failed)))
    by_student = {}
    for scenario in todo:
        by_student.setdefault(scenario.student, []).append(scenario.run_id)
    done = {}

    def progress(record, bar):
        student = record.get("student") or record["run_id"].split("__")[0]
        done.setdefault(student, []).append(record)
        if len(done[student]) == len(by_student.get(student, ())):
            passed = sum(1 for r in done[student] if r.get("success"))
            bar.write("[grade] %s: %d runs graded, %d passed" % (student, len(done[student]),
                                                                 passed), file=sys.stderr)
    options = GradeOptions(output=os.path.join(output, "batch"),
                           warm_start=not getattr(args, "cold_start", False),
                           shadowed=shadowed, cpu_s=spec.limits.cpu_s,
                           memory_mib=spec.limits.memory_mib,
                           processes=spec.limits.processes, file_mib=spec.limits.file_mib,
                           replay=True)
    records = run_batch(todo, options, scheduler=args.scheduler, workers=args.workers,
                        resume=not args.fresh, progress=not args.no_progress, say=say,
                        task=grade_run, on_record=progress) if todo else []
    wanted = {s.run_id: s for s in todo}
    graded = {sub.student: {"submission": sub, "records": []} for sub in submissions}
    for record in list(records) + failed:
        scenario = wanted.get(record["run_id"])
        if scenario is not None:        # a run the cluster lost has no student fields
            record.setdefault("student", scenario.student)
            record["task"] = scenario.task_name
            record.setdefault("index", scenario.index)
        graded[record["student"]]["records"].append(record)
    for entry in graded.values():
        entry["records"].sort(key=lambda r: (r["task"], r["index"]))
    return graded
