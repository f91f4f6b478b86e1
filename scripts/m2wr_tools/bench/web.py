"""`scripts/bench.sh --web-only ROUNDS [--pages N] [--seconds 15]`: what watching the live
page costs the lockstep loop (target: at most 10 %, as for the rviz-like listeners).

Each round measures the lockstep loop of the whole bench (world02, m2wr, obstacle_avoidance.py,
real_time_factor 0; loop.measure_loop) twice in turn: without the page, then with
web:=true and N pages watching (m2wr_tools.bench.web_watch: WebSockets that read and decode every
frame as a browser does, without drawing; a browser's drawing is its own process's cost,
whatever the simulator sends). Printed per round: x real time without and with, the ratio,
the simulator's CPU per sim second, frames the pages got per wall second; and the median."""
import json
import os
import signal
import statistics
import subprocess
import sys

from ..running import processes
from .loop import measure_loop, say
from .arithmetic import fmt


def web_rounds(session, listener, args):
    rounds = []
    for index in range(args.web_only):
        say("round %d of %d" % (index + 1, args.web_only))
        without = measure_loop(session, listener, "lockstep", True, args.clock_hz,
                               args.seconds, args.check_seconds)
        port = processes.free_port()
        watcher = subprocess.Popen(
            [sys.executable, "-m", "m2wr_tools.bench.web_watch", "ws://127.0.0.1:%d/ws" % port,
             "--pages", str(args.pages)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            text=True, start_new_session=True)
        try:
            watched = measure_loop(session, listener, "lockstep + web page", True,
                                   args.clock_hz, args.seconds, args.check_seconds,
                                   extra=("web:=true", "web_port:=%d" % port))
        finally:
            watcher.send_signal(signal.SIGTERM)
            out, _ = watcher.communicate(timeout=20)
        pages = json.loads(out.strip().splitlines()[-1]) if out.strip() else {}
        rounds.append({"without": without, "with": watched, "pages": pages,
                       "load": "%.2f" % os.getloadavg()[0]})
    return rounds


def web_report(figures):
    lines = ["", "lockstep loop with the web page watched / without, round by round (load "
             "before %s):" % figures["machine"]["load_before"]]
    ratios = []
    for index, pair in enumerate(figures["web_rounds"]):
        without, watched, pages = pair["without"], pair["with"], pair["pages"]
        ratio = 100.0 * watched["x_real_time"] / without["x_real_time"] \
            if without["x_real_time"] and watched["x_real_time"] else None
        if ratio is not None:
            ratios.append(ratio)
        rate = pages["frames"] / pages["seconds"] / max(pages["pages"], 1) \
            if pages.get("seconds") else None
        lines.append("  round %d: %sx -> %sx = %s %%; simulator CPU per sim s [ms] %s -> %s; "
                     "%s page(s), %s frames per wall s each; load %s" % (
                         index + 1, fmt(without["x_real_time"]), fmt(watched["x_real_time"]),
                         fmt(ratio, "%.0f"),
                         fmt(without["cpu_ms_per_sim_s"]["simulator"], "%.1f"),
                         fmt(watched["cpu_ms_per_sim_s"]["simulator"], "%.1f"),
                         pages.get("pages", "?"), fmt(rate, "%.1f"), pair["load"]))
    if ratios:
        lines.append("  median: %.0f %% (target >= 90 %%)" % statistics.median(ratios))
    return "\n".join(lines)
