#!/usr/bin/env bash
# Benchmark of the stand-in (see m2wr_tools.bench, scripts/m2wr_tools/bench.py, or --help):
#   scripts/bench.sh [--seconds 15] [--soak MINUTES] [--clock-hz 20] [--output output/]
#   scripts/bench.sh --listeners-only ROUNDS [--seconds 15] [--watch-rate HZ]
#     only the lockstep loop without and with listeners, in turn (ratio per round, median)
#   scripts/bench.sh --loop-program-only [--seconds 15]
#     obstacle_avoidance.py and the same rules on a rospy.Rate loop, in lockstep: their ratio
#   scripts/bench.sh --bug [--worlds world02 world03] [--output output/]
#     the series' bug-2 runs in lockstep (m2wr_tools.bench_bug): x real time, lockstep
#     time-outs, contact events
# Prints the figures side by side and writes them to output/bench.json. Needs the project
# set up (scripts/setup.sh); sources scripts/env.sh itself.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ ! -f "$ROOT/catkin_ws/devel/setup.bash" ] || [ ! -x "$ROOT/.venv/bin/python" ] \
   || ! (cd / && "$ROOT/.venv/bin/python" -c "import m2wr_tools" 2>/dev/null); then
  echo "bench: the project is not set up; run scripts/setup.sh first" >&2
  exit 1
fi
set +u
source "$ROOT/scripts/env.sh"
set -u
if [ "${1:-}" = "--bug" ]; then
  shift
  exec python -m m2wr_tools.bench_bug "$@"
fi
exec python -m m2wr_tools.bench "$@"
