"""The class's report, a self-contained static site (no network, no external file):
  index.html              the spec and turning convention it was graded with; the class
                          table: student, each task's score (coloured: full, part, none),
                          total, rank, one short reason per failed task (the full text in
                          its tooltip and on the student's page); click a column's head to
                          sort by it (again: reverse)
  students/<student>.html the turning convention; each task's runs: the trajectory over the
                          world, the metrics, what the grader left out of their launch files
                          and why, what it called after the start, the rule findings and the
                          end of the controller's log
  runs/<run_id>.svg       a run's trajectory over the world (obstacles at scan height)
  grades.csv              scoring.csv_text: one row per student, for a gradebook
  results.json            the spec, each student's scores and every run's record
"""
import html
import json
import math
import os

from ..running.processes import log_tail
from . import replay_view, scoring

STYLE = """body{font-family:sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:.25em .5em;text-align:left}
th{background:#eee;cursor:pointer}td.n{text-align:right}.fail{color:#a00}.ok{color:#070}
.run{border:1px solid #ccc;margin:1em 0;padding:.5em}.run img{float:left;margin-right:1em}
.run:after{content:"";display:block;clear:both}pre{background:#f6f6f6;padding:.5em;
overflow-x:auto;max-height:20em}td.full{background:#dfd}td.part{background:#ffe9c0}
td.none{background:#fdd}td.why{font-size:90%}td.why div{max-width:26em;white-space:nowrap;
overflow:hidden;text-overflow:ellipsis}.note{color:#555}"""
SORT = """function sortBy(th){var t=th.closest('table'),b=t.tBodies[0],i=th.cellIndex,
d=th.dataset.dir==='asc'?-1:1;th.dataset.dir=d===1?'asc':'desc';
var r=Array.from(b.rows);r.sort(function(x,y){var a=x.cells[i].dataset.v||x.cells[i].textContent,
c=y.cells[i].dataset.v||y.cells[i].textContent,p=parseFloat(a),q=parseFloat(c);
if(!isNaN(p)&&!isNaN(q))return d*(p-q);return d*a.localeCompare(c);});
r.forEach(function(row){b.appendChild(row);});}
document.querySelectorAll('th').forEach(function(th){th.addEventListener('click',
function(){sortBy(th);});});"""
SIZE = 320                      # [px] of a trajectory picture's longer side


def _page(title, body, up=""):
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>%s</title>"
            "<link rel=\"icon\" href=\"data:,\"><style>%s</style></head><body>\n%s\n"
            "<script>%s</script></body></html>\n" % (html.escape(title), STYLE, body, SORT))


def _outlines(world, cache={}):
    if world not in cache:
        from ..analysis.scene import SCAN_HEIGHT, Scene
        try:
            scene = Scene.of_world(world)
        except Exception:           # a missing world: pictures without obstacles
            cache[world] = []
        else:
            try:
                cache[world] = scene.outlines(SCAN_HEIGHT)
            finally:
                scene.close()
    return cache[world]


def svg(outlines, record, goal=None):
    """The run's path over the world's outlines, as SVG text (y up, 1 m = the same in x, y)."""
    points = [(p[1], p[2]) for p in record.get("path") or []]
    xs, ys = [record["x"]], [record["y"]]
    for o in outlines:
        if o.kind == "circle":
            xs += [o.center[0] - o.radius, o.center[0] + o.radius]
            ys += [o.center[1] - o.radius, o.center[1] + o.radius]
        else:
            xs += [p[0] for p in o.points]
            ys += [p[1] for p in o.points]
    xs += [p[0] for p in points]
    ys += [p[1] for p in points]
    if goal:
        xs.append(goal[0])
        ys.append(goal[1])
    x0, x1, y0, y1 = min(xs) - 1, max(xs) + 1, min(ys) - 1, max(ys) + 1
    scale = SIZE / max(x1 - x0, y1 - y0)
    width, height = (x1 - x0) * scale, (y1 - y0) * scale

    def at(x, y):
        return "%.1f,%.1f" % ((x - x0) * scale, (y1 - y) * scale)
    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="%.0f" height="%.0f" '
             'viewBox="0 0 %.1f %.1f">' % (width, height, width, height),
             '<rect width="100%" height="100%" fill="#fff"/>']
    for o in outlines:
        if o.kind == "circle":
            cx, cy = at(*o.center).split(",")
            parts.append('<circle cx="%s" cy="%s" r="%.1f" fill="#999"/>'
                         % (cx, cy, o.radius * scale))
        else:
            parts.append('<polygon points="%s" fill="#999"/>'
                         % " ".join(at(*p) for p in o.points))
    if goal:
        gx, gy = at(*goal).split(",")
        parts.append('<circle cx="%s" cy="%s" r="6" fill="none" stroke="#06c" '
                     'stroke-width="2"/>' % (gx, gy))
    if len(points) >= 2:
        parts.append('<polyline points="%s" fill="none" stroke="%s" stroke-width="2"/>' % (
            " ".join(at(*p) for p in points), "#080" if record.get("success") else "#c00"))
    sx, sy = at(record["x"], record["y"]).split(",")
    parts.append('<circle cx="%s" cy="%s" r="4" fill="#000"/>' % (sx, sy))
    if points:
        ex, ey = at(*points[-1]).split(",")
        parts.append('<rect x="%.1f" y="%.1f" width="7" height="7" fill="#000"/>'
                     % (float(ex) - 3.5, float(ey) - 3.5))
    parts.append("</svg>\n")
    return "\n".join(parts)


def _number(value, unit=""):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    return ("%.2f %s" % (value, unit)).strip() if isinstance(value, float) else str(value)


def turning(legacy_mode):
    """The turning convention in a teacher's words."""
    if legacy_mode:
        return ("legacy_mode true: Kinetic's diff drive, a positive angular.z turns m2wr "
                "counter-clockwise (REP 103), as the series' own code of episodes 6-10 is "
                "written")
    return ("legacy_mode false: Gazebo Noetic's diff drive, a positive angular.z turns m2wr "
            "clockwise, as episode 5's page relies on")


def _conventions(spec):
    """The turning convention(s) of the spec's tasks, as one HTML sentence."""
    modes = spec.legacy_modes
    if len(modes) == 1:
        return "Turning: <b>%s</b>." % html.escape(turning(modes[0]))
    return "Turning: %s." % "; ".join("<b>legacy_mode %s</b> for %s" % (
        str(mode).lower(), ", ".join(html.escape(t.name) for t in spec.tasks
                                     if t.legacy_mode == mode)) for mode in modes)


def _run_notes(r):
    """What the grader changed about the run: its launch files' parts left out, its
    after_start steps."""
    parts = []
    if r.get("left_out"):
        parts.append("<p>Left out of the launch files (the grader's world runs the task):"
                     "</p><ul>%s</ul>" % "".join(
                         "<li><code>%s</code> in %s: %s</li>" % (
                             html.escape(left["element"]), html.escape(left["file"]),
                             html.escape(left["why"])) for left in r["left_out"]))
    if r.get("after_start"):
        parts.append("<p>After the start: %s.</p>" % html.escape("; ".join(r["after_start"])))
    return "".join(parts)


def _student_page(spec, student, entry, row, output=None):
    sub = entry["submission"]
    parts = ['<p><a href="../index.html">class table</a></p>',
             "<h1>%s</h1>" % html.escape(student),
             "<p class=\"note\">Graded on %s. %s</p>" % (
                 html.escape(os.path.basename(spec.path)), _conventions(spec)),
             "<p>Total <b>%.2f</b> of %.2f, rank %d. Handed in: %s.</p>" % (
                 row["total"], spec.points, row["rank"], html.escape(
                     ", ".join(n for n, _ in sub.packages) + " (package)" if sub.packages
                     else "%d loose scripts" % len(sub.scripts) if sub.scripts
                     else "nothing gradable"))]
    if sub.problem:
        parts.append('<p class="fail">%s</p>' % html.escape(sub.problem))
    for task in spec.tasks:
        runs = [r for r in entry["records"] if r.get("task") == task.name]
        parts.append("<h2>%s: %.2f of %.2f</h2><p><code>%s</code>, %s task in %s, %g s, "
                     "legacy_mode %s%s%s</p>"
                     % (html.escape(task.name), row["scores"][task.name], task.points,
                        html.escape(" ".join(task.command)), task.kind,
                        html.escape(task.world), task.duration,
                        str(task.legacy_mode).lower(),
                        "; after the start: %s" % html.escape(", ".join(
                            s.describe() for s in task.after_start)) if task.after_start else "",
                        (": " + html.escape(task.description)) if task.description else ""))
        for r in runs:
            picture = ('<img src="../runs/%s.svg" alt="trajectory of run %d">'
                       % (html.escape(r["run_id"]), r["index"]))
            if output is not None:
                picture += replay_view.embed(r, output)
            metrics = "".join("<tr><td>%s</td><td>%s</td></tr>" % (k, html.escape(v)) for k, v in (
                ("start", "(%.2f, %.2f, %.2f rad), seed %d" % (r["x"], r["y"], r["yaw"],
                                                              r["seed"])),
                ("distance", _number(r.get("distance_m"), "m")),
                ("min clearance", _number(r.get("min_clearance_m"), "m")),
                ("contact events", _number(r.get("contact_events"))),
                ("time to goal", _number(r.get("time_to_goal_s"), "s")),
                ("time stuck", _number(r.get("time_stuck_s"), "s")),
                ("controller exit", str(r.get("controller_exit") or "n/a"))))
            findings = "".join("<li class=\"%s\">%s (%s)</li>" % (
                "ok" if f["allowed"] else "fail", html.escape(_finding(f)),
                html.escape(f["why"])) for f in r.get("findings") or [])
            log = log_tail(r["controller_log"], 30) if r.get("controller_log") else ""
            parts.append(
                '<div class="run" id="run%d-%s">%s<h3>run %d: <span class="%s">%s</span></h3>'
                '<p>%s</p>%s<table>%s</table><p>Rule findings: %s</p>'
                "<details><summary>controller log (last 30 lines)</summary><pre>%s</pre>"
                "</details></div>" % (
                    r["index"], html.escape(task.name), picture, r["index"],
                    "ok" if r.get("success") else "fail",
                    "passed" if r.get("success") else "failed", html.escape(r.get("reason", "")),
                    _run_notes(r), metrics, ("<ul>%s</ul>" % findings) if findings else "none",
                    html.escape(log) or "(no log)"))
    return _page("%s: grades" % student, "\n".join(parts))


def _finding(f):
    from .rules import describe
    return describe(f)


def _score_class(score, points):
    return "full" if points and score >= points else "part" if score > 0 else "none"


def _index(spec, table_rows, graded):
    head = "".join("<th>%s</th>" % h for h in (
        ["student"] + ["%s (%g)" % (html.escape(t.name), t.points) for t in spec.tasks]
        + ["total (%g)" % spec.points, "rank", "failure reasons"]))
    body = []
    for row in table_rows:
        student = html.escape(row["student"])
        cells = ['<td data-v="%s"><a href="students/%s.html">%s</a></td>' % (
            student, student, student)]
        cells += ['<td class="n %s">%.2f</td>' % (_score_class(row["scores"][t.name], t.points),
                                                  row["scores"][t.name]) for t in spec.tasks]
        short = scoring.short_failures(spec, graded[row["student"]]["records"])
        if row["problem"]:
            why = '<div title="%s">%s</div>' % (html.escape(row["problem"]),
                                                html.escape(row["problem"][:scoring.SHORT]))
        else:
            why = "".join('<div title="%s"><a href="students/%s.html#run0-%s">%s</a>: %s</div>'
                          % (html.escape("\n".join(full)), student, html.escape(name),
                             html.escape(name), html.escape(text))
                          for name, text, full in short)
        cells += ['<td class="n %s">%.2f</td>' % (_score_class(row["total"], spec.points),
                                                  row["total"]),
                  '<td class="n">%d</td>' % row["rank"],
                  '<td class="why" data-v="%d">%s</td>' % (len(short), why)]
        body.append("<tr>%s</tr>" % "".join(cells))
    tasks = "".join("<li><b>%s</b> (%g points): <code>%s</code>, %s in %s, %d run%s of %g s, "
                    "legacy_mode %s%s%s</li>"
                    % (html.escape(t.name), t.points, html.escape(" ".join(t.command)), t.kind,
                       html.escape(t.world), len(t.runs), "" if len(t.runs) == 1 else "s",
                       t.duration,
                       str(t.legacy_mode).lower(),
                       (", allows " + ", ".join(t.allow)) if t.allow else "",
                       ", after the start: " + html.escape(", ".join(
                           s.describe() for s in t.after_start)) if t.after_start else "")
                    for t in spec.tasks)
    return _page("Class grades", "<h1>Class grades</h1><p>Spec <b>%s</b> (%s). %s</p>"
                 "<p class=\"note\">Click a column's head to sort; a reason's full text is in "
                 "its tooltip and on the student's page.</p><table id=\"grades\"><thead><tr>%s"
                 "</tr></thead><tbody>%s</tbody></table><h2>Tasks</h2><ul>%s</ul>" % (
                     html.escape(os.path.basename(spec.path)), html.escape(spec.path),
                     _conventions(spec), head, "\n".join(body), tasks))


def _write(path, text):
    with open(path, "w", encoding="utf-8") as out:
        out.write(text)


def write(output, spec, graded):
    os.makedirs(os.path.join(output, "students"), exist_ok=True)
    os.makedirs(os.path.join(output, "runs"), exist_ok=True)
    table_rows = scoring.rows(spec, graded)
    goals = {t.name: t.goal for t in spec.tasks}
    worlds = {t.name: t.world for t in spec.tasks}
    for row in table_rows:
        entry = graded[row["student"]]
        for r in entry["records"]:
            _write(os.path.join(output, "runs", r["run_id"] + ".svg"),
                   svg(_outlines(worlds[r["task"]]), r, goals.get(r["task"])))
        replay_view.write_replays(output, entry["records"])
        _write(os.path.join(output, "students", row["student"] + ".html"),
               _student_page(spec, row["student"], entry, row, output))
    _write(os.path.join(output, "index.html"), _index(spec, table_rows, graded))
    _write(os.path.join(output, "grades.csv"), scoring.csv_text(spec, graded))
    data = {"spec": spec.path, "points": spec.points,
            "tasks": [{"name": t.name, "command": list(t.command), "kind": t.kind,
                       "world": t.world, "points": t.points, "runs": len(t.runs),
                       "legacy_mode": t.legacy_mode,
                       "after_start": [s.as_dict() for s in t.after_start]}
                      for t in spec.tasks],
            "students": {row["student"]: dict(row, runs=graded[row["student"]]["records"])
                         for row in table_rows}}
    _write(os.path.join(output, "results.json"), json.dumps(data, indent=1, default=str))
