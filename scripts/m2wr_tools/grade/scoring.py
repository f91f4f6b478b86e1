"""Scores from the graded runs: a task gives points x (runs passed / runs), a student's total
is the sum, ranks go by total (equal totals share a rank: 1, 2, 2, 4). What a teacher reads:
  rows(spec, graded)   one dict per student, sorted by name: scores, total, rank, failures
  write_csv(path, ...) grades.csv, one row per student, for a gradebook import: student,
                       one column per task, total, max, rank, failures; numbers with two
                       decimals, rows by student name, so grading twice gives the same bytes
  table(spec, graded)  the same as text for the terminal
  short_failures(spec, records)
                       the class table's cell: one short line per failed task (its runs'
                       reasons deduplicated, the first words), with the full text
  goal_hint(record, goal, legacy_mode, turns=None)
                       why a goal run did not get there, from its path, in a teacher's words
  turns_in_place(track, goal)
                       how far a run turned on the spot away from its goal and toward it
"""
import csv
import io
import math
import re

SEE_LOG = re.compile(r";? see /\S+")
MISSED = re.compile(r"^did not reach the goal \([^)]*\) within [0-9.]+ m: (.+)$")
# a controller that could not start ("controller '<its command line>': <why>"): the command
# is in the task's head, the why is what the teacher needs; a package's folder is on the page
UNSTARTED = re.compile(r"^controller '[^']*': (?:package '[^']*' \([^)]*\) has )?([^;]+)")
SHORT = 60                     # [characters] of a reason in the class table
NO_NEARER = 0.2                # [m] a path that never came this much nearer its goal
AWAY = 120.0                   # [deg] off the goal's bearing at the end: facing away
TURN_STEP = 0.1                # [s] sim: turns_in_place looks at the track this often
IN_PLACE = 0.05                # [m/s] slower than this, a turning robot turns on the spot
TURNING = 0.5                  # [rad/s] turning faster than this: a go to point's turn (the
                               # series' turns at 0.7 rad/s; its wall follower's at 0.3, either
                               # way of the goal, is left out)
BAND = (15.0, 165.0)           # [deg] off the goal's bearing: a turn there has a side
TURNED_AWAY = 30.0             # [deg] turned away on the spot, at least, ...
AWAY_SHARE = 0.8               # ... and this share of its turns on the spot with a side


def task_score(task, records):
    if not records:
        return 0.0
    return task.points * sum(1 for r in records if r.get("success")) / len(records)


def failures(task, records):
    """"task run N: reason" of each failed run, in run order: the reason's first line
    without the log's path (the student's page links the log; the gradebook stays the same
    wherever the output is)."""
    return ["%s run %d: %s" % (task.name, r.get("index", 0), SEE_LOG.sub(
        "", (r.get("reason") or "failed").splitlines()[0]).rstrip(":").rstrip(";"))
            for r in records if not r.get("success")]


def _first_line(record):
    return SEE_LOG.sub("", (record.get("reason") or "failed").splitlines()[0]).rstrip(
        ":").rstrip(";")


def short_failures(spec, records):
    """[(task name, short reason, full reasons)] of each failed task, in spec order: the
    distinct reasons of its failed runs (first lines, without log paths), the first one cut
    to SHORT characters at a word (a missed goal: what went wrong, from goal_hint; a controller
    that cannot start: why, without its command line), "(N runs)" when more than one run
    failed and "+N other reasons" when they differ."""
    out = []
    for task in spec.tasks:
        failed = [r for r in records if r.get("task") == task.name and not r.get("success")]
        if not failed:
            continue
        reasons = []
        for r in failed:
            if _first_line(r) not in reasons:
                reasons.append(_first_line(r))
        short = reasons[0]
        missed = MISSED.match(short)
        unstarted = UNSTARTED.match(short)
        if missed:          # the goal's figures are in the task's head: say what went wrong
            short = "did not reach the goal: " + missed.group(1).split(":")[0]
        elif unstarted:
            short = "cannot start: " + unstarted.group(1)
        if len(short) > SHORT:
            short = short[:SHORT].rsplit(" ", 1)[0].rstrip(",;:") + "\u2026"
        if len(failed) > 1:
            short += " (%d runs)" % len(failed)
        if len(reasons) > 1:
            short += ", +%d other reason%s" % (len(reasons) - 1, "s" if len(reasons) > 2 else "")
        out.append((task.name, short, reasons))
    return out


def _wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


def turns_in_place(track, goal):
    """(degrees turned away from the goal, degrees turned toward it) while the robot turned on
    the spot fast (slower than IN_PLACE, turning faster than TURNING), counted where the goal was
    between BAND[0] and BAND[1] deg off its heading (facing the goal or right away from it, a
    turn has no side), from `track`: rows (sim time [s], x, y, yaw [rad]), every TURN_STEP s.
    A go to point turns toward its goal; written for the other turning convention, it turns
    away from it, each time it is switched on, until it faces away."""
    away = toward = 0.0
    last = None
    for row in track:
        t, x, y, yaw = (float(v) for v in row[:4])
        if last is not None and t - last[0] < TURN_STEP - 1e-9:
            continue
        if last is not None:
            dt = t - last[0]
            turn = _wrap(yaw - last[3])
            if math.hypot(x - last[1], y - last[2]) < IN_PLACE * dt and \
                    abs(turn) > TURNING * dt:
                off = _wrap(math.atan2(goal[1] - last[2], goal[0] - last[1]) - last[3])
                if BAND[0] < abs(math.degrees(off)) < BAND[1]:
                    if (turn > 0) == (off > 0):
                        toward += abs(math.degrees(turn))
                    else:
                        away += abs(math.degrees(turn))
        last = (t, x, y, yaw)
    return round(away, 1), round(toward, 1)


def goal_hint(record, goal, legacy_mode, turns=None):
    """Why a goal run that ended short did not get there, from its path and end pose, or "":
    turned away (never nearer than at its start, ending facing away from the goal; or, given
    `turns` (turns_in_place's), turning on the spot away from the goal far more than toward
    it, as a bug program's go to point does each time it is switched on: what a program
    written for the other turning convention does), never nearer, or how near it came."""
    path = [(p[1], p[2]) for p in record.get("path") or []]
    end = (record.get("final_x"), record.get("final_y"))
    if end[0] is None or not path:
        return ""
    path.append(end)
    start = math.hypot(goal[0] - record["x"], goal[1] - record["y"])
    nearest = min(math.hypot(goal[0] - x, goal[1] - y) for x, y in path)
    bearing = math.atan2(goal[1] - end[1], goal[0] - end[0])
    off = abs(math.degrees(math.atan2(math.sin(bearing - record.get("final_yaw", 0.0)),
                                      math.cos(bearing - record.get("final_yaw", 0.0)))))
    convention = ("as a program written for the other turning convention does (this task: "
                  "legacy_mode %s)" % str(bool(legacy_mode)).lower())
    if nearest > start - NO_NEARER and off > AWAY:
        return ("turned away from the goal: never nearer than at its start (%.2f m), it ended "
                "facing %.0f deg off the goal's direction, %s" % (start, off, convention))
    if turns is not None:
        away, toward = turns
        if away >= TURNED_AWAY and away >= AWAY_SHARE * (away + toward):
            return ("turned away from the goal: on the spot it turned %.0f deg away from the "
                    "goal's direction and %.0f deg toward it (it came within %.2f m of the "
                    "goal, ended %.2f m away), %s" % (away, toward, nearest, math.hypot(
                        goal[0] - end[0], goal[1] - end[1]), convention))
    if nearest > start - NO_NEARER:
        return "never nearer the goal than at its start (%.2f m)" % start
    return "came within %.2f m of it, ended %.2f m away" % (
        nearest, math.hypot(goal[0] - end[0], goal[1] - end[1]))


def rows(spec, graded):
    out = []
    for student in sorted(graded):
        records = graded[student]["records"]
        row = {"student": student, "scores": {}, "failures": [],
               "problem": graded[student]["submission"].problem}
        for task in spec.tasks:
            mine = [r for r in records if r.get("task") == task.name]
            row["scores"][task.name] = round(task_score(task, mine), 2)
            row["failures"] += failures(task, mine)
        row["total"] = round(sum(row["scores"].values()), 2)
        out.append(row)
    totals = sorted((r["total"] for r in out), reverse=True)
    for row in out:
        row["rank"] = totals.index(row["total"]) + 1
    return out


def csv_text(spec, graded):
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["student"] + [t.name for t in spec.tasks] + ["total", "max", "rank",
                                                                   "failures"])
    for row in rows(spec, graded):
        writer.writerow([row["student"]] + ["%.2f" % row["scores"][t.name] for t in spec.tasks]
                        + ["%.2f" % row["total"], "%.2f" % spec.points, row["rank"],
                           " | ".join(row["failures"])])
    return buffer.getvalue()


def table(spec, graded):
    lines = ["%-16s %s %8s %5s" % ("student", " ".join("%10s" % t.name[:10] for t in spec.tasks),
                                    "total", "rank")]
    for row in rows(spec, graded):
        lines.append("%-16s %s %8.2f %5d" % (row["student"][:16], " ".join(
            "%10.2f" % row["scores"][t.name] for t in spec.tasks), row["total"], row["rank"]))
        for failure in row["failures"][:3]:
            lines.append("    %s" % failure[:150])
        if len(row["failures"]) > 3:
            lines.append("    ... %d more failed runs" % (len(row["failures"]) - 3))
    return "\n".join(lines)
