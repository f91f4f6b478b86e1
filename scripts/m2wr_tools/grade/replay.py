"""`grade.sh --replay STUDENT TASK RUN`: one graded run again, on this machine, as it was
graded (the same scenario: world, start, seed, duration, command, the student's staged
packages, rules and limits; lockstep), drawn to <output>/replay/<run_id>.png, with its
metrics printed beside the graded record's and its record in <output>/replay/<run_id>.json;
the last line says whether every measure is the graded one to the last digit. --gui opens
the simulator's window and runs at real time (lockstep still: the same physics)."""
import json
import os

from ..running import processes
from .runner import GradedScenario, GradeOptions, GradeRig

COMPARED = (("success", "success", ""), ("reason", "reason", ""),
            ("distance_m", "distance", "m"), ("min_clearance_m", "min clearance", "m"),
            ("contact_events", "contact events", ""), ("time_to_goal_s", "time to goal", "s"),
            ("final_x", "final x", "m"), ("final_y", "final y", "m"))


def find(output, student, task, index):
    """(scenario dict, record, batch options dict) of a graded run; ValueError naming what
    is there when it is not."""
    path = os.path.join(output, "results.json")
    if not os.path.isfile(path):
        raise ValueError("%s not found: grade the class first (scripts/grade.sh CLASS_DIR "
                         "--output %s)" % (path, output))
    with open(path) as source:
        students = json.load(source)["students"]
    if student not in students:
        raise ValueError("no student '%s' in %s; the students are %s" % (
            student, path, ", ".join(sorted(students))))
    runs = students[student]["runs"]
    tasks = sorted({r["task"] for r in runs})
    mine = [r for r in runs if r["task"] == task]
    if not mine:
        raise ValueError("%s has no task '%s'; the tasks are %s" % (student, task,
                                                                     ", ".join(tasks)))
    record = next((r for r in mine if r["index"] == index), None)
    if record is None:
        raise ValueError("%s's task %s has runs %s, not %d" % (
            student, task, ", ".join(str(r["index"]) for r in mine), index))
    if "distance_m" not in record and not record.get("controller_log"):
        raise ValueError("run %d of %s's %s never started (%s): nothing to replay" % (
            index, student, task, record.get("reason")))
    with open(os.path.join(output, "batch", "results.json")) as source:
        options = json.load(source)["batch"]["options"]
    return record["scenario"], record, options


def replay(output, student, task, index, gui=False, say=print):
    try:
        scenario, graded, options = find(output, student, task, index)
    except ValueError as err:
        say("replay: %s" % err)
        return 2
    options = GradeOptions(**dict(options, output=os.path.join(output, "replay"), gui=gui,
                                  real_time_factor=1.0 if gui else 0.0, picture=True))
    scenario = GradedScenario.from_dict(scenario)
    say("replaying %s's %s run %d: %s from (%.2f, %.2f, %.2f), seed %d, %g s%s" % (
        student, task, index, " ".join(scenario.controller), scenario.x, scenario.y,
        scenario.yaw, scenario.seed, scenario.duration, ", with the window" if gui else ""))
    old = processes.raise_on_signals()
    rig = GradeRig()
    try:
        record = rig.run(scenario, options)
    finally:
        rig.close()
        for signum, handler in old.items():
            import signal
            signal.signal(signum, handler)
    path = os.path.join(options.output, "%s.json" % scenario.run_id)
    with open(path, "w") as out:
        json.dump(record, out, indent=1, sort_keys=True)
    print("%-16s %-28s %s" % ("", "graded", "replayed"))
    for key, label, unit in COMPARED:
        print("%-16s %-28s %s" % (label, _text(graded.get(key), unit), _text(record.get(key),
                                                                             unit)))
    say("picture %s, record %s" % (record.get("picture"), path))
    differ = differences(graded, record)
    say("the replay differs from the graded run in: %s" % ", ".join(differ) if differ else
        "the replay is the graded run: every measure equal to the last digit")
    return 0


def differences(graded, replayed):
    """The measures (COMPARED, and the rules' findings) in which two records differ. Of a
    run the rules ended while the world ran, only the verdict: its processes were stopped
    when the grader's look (every 0.1 s of wall time) found what they did, and how far the
    robot got by then is the machine's timing, not the program's."""
    keys = [key for key, _, _ in COMPARED] + ["findings"]
    if str(graded.get("reason", "")).startswith("rules:"):
        keys = ["success", "reason", "findings"]
    return [key for key in keys if graded.get(key) != replayed.get(key)]


def _text(value, unit):
    if isinstance(value, float):
        return "%.3f %s" % (value, unit)
    return str(value)[:60]
