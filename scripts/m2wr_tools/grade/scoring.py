"""Scores from the graded runs: a task gives points x (runs passed / runs), a student's total
is the sum, ranks go by total (equal totals share a rank: 1, 2, 2, 4). What a teacher reads:
  rows(spec, graded)   one dict per student, sorted by name: scores, total, rank, failures
  write_csv(path, ...) grades.csv, one row per student, for a gradebook import: student,
                       one column per task, total, max, rank, failures; numbers with two
                       decimals, rows by student name, so grading twice gives the same bytes
  table(spec, graded)  the same as text for the terminal
"""
import csv
import io
import re

SEE_LOG = re.compile(r";? see /\S+")


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
