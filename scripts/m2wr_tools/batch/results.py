"""A batch's results: results.json (every run's record, the batch's options) and results.csv
(one row a run, the path as JSON text), read back for resume, and the summary table.

Fields that depend on the machine (wall time, real-time factor, overhead, worker, memory,
reuse, log paths, cmd_vel messages heard: the count runs on until physics is paused, the
time in each case: the controller stamps its lines with the /clock it last heard) are
listed in MACHINE_FIELDS; every other field is a function of the
scenario alone (lockstep), which `deterministic_view` extracts for comparisons.
"""
import csv
import json
import math
import os
import tempfile

import numpy as np

CSV_FIELDS = [
    "run_id", "world", "x", "y", "yaw", "seed", "task", "success", "reason", "time_to_goal_s",
    "distance_m", "min_clearance_m", "min_clearance_model", "contact_events",
    "time_in_contact_s", "time_stuck_s", "wall_share", "final_x", "final_y", "final_yaw",
    "sim_time_s", "wall_time_s", "real_time_factor", "overhead_s", "cmd_vel_messages",
    "controller_exit", "controller_log", "reused", "worker", "worker_rss_mib",
    "simulator_rss_mib", "bag", "picture", "path",
]
MACHINE_FIELDS = {"wall_time_s", "real_time_factor", "overhead_s", "worker", "worker_rss_mib",
                  "simulator_rss_mib", "zygote_rss_mib", "reused", "controller_log", "bag", "picture", "stages", "cpu_s", "finished_at",
                  "cmd_vel_messages", "cases_s",
                  "controller_exit", "controller_stop"}


def load(folder):
    """{run_id: record} of <folder>/results.json ({} when there is none yet)."""
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return {}
    with open(path) as source:
        data = json.load(source)
    return {r["run_id"]: r for r in data.get("runs", [])}


def write(folder, records, batch):
    """results.json and results.csv, each replaced whole (a reader never sees half a file)."""
    records = sorted(records, key=lambda r: r["run_id"])
    _atomic(os.path.join(folder, "results.json"),
            lambda out: json.dump({"batch": batch, "runs": records}, out, indent=1,
                                  default=_plain))
    def write_csv(out):
        writer = csv.DictWriter(out, fieldnames=CSV_FIELDS, extrasaction="ignore")
        writer.writeheader()
        for r in records:
            row = dict(r)
            row["path"] = json.dumps(r.get("path", []))
            writer.writerow({k: _cell(row.get(k)) for k in CSV_FIELDS})
    _atomic(os.path.join(folder, "results.csv"), write_csv)


def _atomic(path, fill):
    folder = os.path.dirname(path)
    handle, temporary = tempfile.mkstemp(dir=folder, prefix=".results-")
    with os.fdopen(handle, "w", newline="") as out:
        fill(out)
    os.replace(temporary, path)


def _cell(value):
    if isinstance(value, float):
        return "%.6g" % value if math.isfinite(value) else ""
    return "" if value is None else value


def _plain(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    raise TypeError("not JSON: %r" % (value,))


def deterministic_view(record):
    """The record without its machine-dependent fields."""
    return {k: v for k, v in record.items() if k not in MACHINE_FIELDS}


def _distribution(values, unit, spec="%.2f"):
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return "n/a"
    q = np.percentile(values, [0, 25, 50, 75, 100])
    return ("min " + spec + "  p25 " + spec + "  median " + spec + "  p75 " + spec
            + "  max " + spec + " %s") % (*q, unit)


def summary_table(records, title=""):
    """The batch's summary: success rate overall, per world and per seed, the failure
    reasons, and the distributions of the metrics."""
    runs = list(records)
    lines = [title] if title else []
    if not runs:
        return "\n".join(lines + ["no runs"])
    done = sum(1 for r in runs if r.get("success"))
    lines.append("runs %d, success %d (%.0f %%), failed %d" % (
        len(runs), done, 100.0 * done / len(runs), len(runs) - done))
    for key in ("world", "seed", "task"):
        groups = sorted({r.get(key) for r in runs}, key=str)
        if len(groups) > 1:
            for g in groups:
                sub = [r for r in runs if r.get(key) == g]
                ok = sum(1 for r in sub if r.get("success"))
                lines.append("  %s %-12s %3d/%-3d succeeded (%.0f %%)" % (
                    key, g, ok, len(sub), 100.0 * ok / len(sub)))
    reasons = {}
    for r in runs:
        if not r.get("success"):
            reason = _reason_kind(r.get("reason", ""))
            reasons[reason] = reasons.get(reason, 0) + 1
    for reason, count in sorted(reasons.items(), key=lambda kv: -kv[1]):
        lines.append("  failed: %3d x %s" % (count, reason))
    rows = [("distance", "distance_m", "m"), ("min clearance", "min_clearance_m", "m"),
            ("contact events", "contact_events", ""), ("time in contact", "time_in_contact_s", "s"),
            ("time stuck", "time_stuck_s", "s"), ("time to goal", "time_to_goal_s", "s"),
            ("wall time", "wall_time_s", "s"), ("real-time factor", "real_time_factor", "x")]
    for label, key, unit in rows:
        values = [r.get(key) for r in runs if r.get(key) is not None]
        if values:
            lines.append("  %-17s %s" % (label, _distribution(values, unit)))
    return "\n".join(lines)


def _reason_kind(reason):
    """The reason without its specifics (numbers, paths), so that alike failures group."""
    head = reason.split(";")[0].split(" at ")[0].split("(")[0].strip()
    return head or "unknown"
