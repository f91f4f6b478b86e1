#!/usr/bin/env bash
# Benchmark of the stand-in (see m2wr_tools.bench.cli, scripts/m2wr_tools/bench/cli.py, or --help):
#   scripts/bench.sh [--seconds 15] [--soak MINUTES] [--clock-hz 20] [--output output/]
#   scripts/bench.sh --listeners-only ROUNDS [--seconds 15] [--watch-rate HZ]
#     only the lockstep loop without and with listeners, in turn (ratio per round, median)
#   scripts/bench.sh --web-only ROUNDS [--pages 1] [--seconds 15]
#     only the lockstep loop without and with the live web page (web:=true) watched by
#     --pages pages, in turn (ratio per round, median; target >= 90 %)
#   scripts/bench.sh --loop-program-only [ROUNDS] [--seconds 15]
#     obstacle_avoidance.py and the same rules on a rospy.Rate loop, in lockstep, in turn
#     ROUNDS times (default 3) at /clock 20 and 100 Hz: their ratio per round, median
#   scripts/bench.sh --bug [--worlds world02 world03] [--output output/]
#     the series' bug-2 runs in lockstep (m2wr_tools.bench.bug): x real time, lockstep
#     time-outs, contact events
#   scripts/bench.sh --grade [--students 30] [--workers N] [--rounds 2] [--output output/]
#     a class of N students graded with the default spec (m2wr_tools.bench.grade): wall
#     time, runs a minute, the grader's overhead a run beside the batch runner's
# Prints the figures side by side and writes them to output/bench.json. Runs
# scripts/setup.sh first unless the project is already set up, and sources scripts/env.sh.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/ensure_ready.sh" bench
if [ "${1:-}" = "--bug" ]; then
  shift
  exec python -m m2wr_tools.bench.bug "$@"
fi
if [ "${1:-}" = "--grade" ]; then
  shift
  exec python -m m2wr_tools.bench.grade "$@"
fi
exec python -m m2wr_tools.bench.cli "$@"
