#!/usr/bin/env bash
# Benchmark of the stand-in (see m2wr_tools.bench, scripts/m2wr_tools/bench.py, or --help):
#   scripts/bench.sh [--seconds 15] [--soak MINUTES] [--clock-hz 20] [--output output/]
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
exec python -m m2wr_tools.bench "$@"
